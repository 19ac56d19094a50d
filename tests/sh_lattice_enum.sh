#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# scripts/lattice_enum.c, the enumeration of Minkowski's configurations
# (Betke & Henk's method) that docs/lattices.md uses for the snub cube,
# must find the densest lattices known exactly: the truncated tetrahedron's
# 207/304 (Betke & Henk 2000) and the cuboctahedron's 45/49, not more and
# not less, with every linear program solved; and a missing or malformed
# input is one line and exit 1. (The snub cube itself takes about ten
# minutes on both cores: docs/lattices.md gives its command.)
set -euo pipefail
: "${VP_SRC:?}"
PY=/usr/bin/python3
CC=${VP_CC:-cc}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }

"$CC" -O2 -std=c11 -o lattice_enum "$VP_SRC/scripts/lattice_enum.c" -lm || die "compile"

enum_is() { # NAME EXPECTED ARGS...: the best fraction equals EXPECTED to 1e-9
  local name=$1 want=$2; shift 2
  "$PY" "$VP_SRC/scripts/archimedean_lattices.py" --diff-body "$name" >"$name.txt" || die "$name: --diff-body"
  ./lattice_enum "$name.txt" "$@" >"$name.out" 2>"$name.err" || die "$name: exit $?: $(cat "$name.out" "$name.err")"
  "$PY" - "$name.out" "$want" <<'PY' || die "$name: $(cat "$name.out")"
import re, sys
out = open(sys.argv[1]).read()
best = float(re.search(r"best fraction ([0-9.]+)", out).group(1))
want = eval(sys.argv[2])
assert abs(best - want) < 1e-9, (best, want)
m = re.search(r"\((\d+) retried, (\d+) by the tableau, (\d+) unresolved\)", out)
assert m and m.group(3) == "0", out
n = re.search(r"pattern chain: (\d+) assignments, (\d+) feasible, (\d+) with an admissible", out)
assert n and int(n.group(3)) > 100, out
print("  ok: %s: %.12f = %s; chain assignments %s, %s admissible" % (
    sys.argv[1].split(".")[0], best, sys.argv[2], n.group(1), n.group(3)))
PY
}

echo "=== the enumeration finds the known densest lattices"
enum_is truncated-tetrahedron 207/304
enum_is cuboctahedron 45/49 --pattern chain --starts 8

echo "=== bad input: one line, exit 1"
for bad in missing.txt empty.txt short.txt; do
  case $bad in
  empty.txt) : >empty.txt ;;
  short.txt) printf '7 2.5\n1 0 0\n' >short.txt ;;
  esac
  set +e
  ./lattice_enum "$bad" >out.txt 2>err.txt
  rc=$?
  set -e
  [ $rc = 1 ] || die "$bad: exit $rc"
  [ "$(wc -l <err.txt)" = 1 ] && [ ! -s out.txt ] || die "$bad: $(cat err.txt out.txt)"
  echo "  ok: $bad: $(cat err.txt)"
done

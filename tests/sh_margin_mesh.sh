#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# --margin with a mesh container, for the lattice (spheres, cubes) and rsa:
# `vdbpack check` reads the margin from the file and loads the container's
# level set deep enough to test it (the level set's narrow band reaches the
# radius and the margin), so the packing passes, and a larger --margin on
# check fails it. A gap between solids on a lattice is refused.
set -euo pipefail
: "${VDBPACK:?}"
VP_SRC=${VP_SRC:-$(cd "$(dirname "$0")/.." && pwd)}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
P=$VP_SRC/vdb_samples/peanut.obj
for job in "lattice:--radius 0.04" "lattice-cubes:--radius 0.05 --shape cube" \
           "rsa:--method rsa --radius 0.04 --count 400" "lattice-gap:--radius 0.04 --gap 0.02"; do
  name=${job%%:*}; args=${job#*:}
  # shellcheck disable=SC2086
  "$VDBPACK" pack "$P" $args --margin 0.05 -o "$name.vdb" -q
  "$VDBPACK" check "$name.vdb" --container "$P" --json >"$name.json" ||
    die "$name: check failed: $(cat "$name.json")"
  /usr/bin/python3 -c "
import json; j = json.load(open('$name.json'))
assert j['margin'] == 0.05 and j['outside'] == 0 and j['overlapping_pairs'] == 0, j
print('  ok: $name: %d particles keep the margin 0.05' % j['count'])"
  set +e; "$VDBPACK" check "$name.vdb" --container "$P" --margin 0.08 >more.txt 2>&1; rc=$?; set -e
  [ "$rc" != 0 ] || die "$name: check --margin 0.08 passed: $(cat more.txt)"
  grep -q "outside the container: [1-9]" more.txt || die "$name: $(cat more.txt)"
done
set +e; "$VDBPACK" pack "$P" --radius 0.05 --shape cube --gap 0.01 -o bad.vdb 2>err.txt; rc=$?; set -e
[ "$rc" = 2 ] && [ ! -e bad.vdb ] && [ "$(wc -l <err.txt)" = 1 ] || die "lattice gap of cubes: $rc $(cat err.txt)"
echo "  ok: $(cat err.txt)"
echo PASS

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 31 through the command line: one meaning per option (getopt_long
# spellings, --count N for every method, messages naming the methods an
# option goes with), shortfalls visible (exit status 4, one warning line,
# requested/placed/short in --json and in the file's metadata, read back
# with OpenVDB's vdb_print; --allow-short), count=max with a law of
# radii, --margin and --gap (measured with numpy, and by check) and their
# bad values, and progress: none on a non-terminal, --progress one line per
# stage in order with a fraction that never decreases (the terminal's bar
# is drawn on a timer, so no test here asserts it). Particle data is read back from CSV with numpy, not from the
# summary.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
PY=""
for p in /usr/bin/python3 python3; do
  if command -v "$p" >/dev/null && "$p" -c 'import numpy' 2>/dev/null; then PY=$p; break; fi
done
[ -n "$PY" ] || { echo "SKIP: no python3 with numpy"; exit 77; }
command -v vdb_print >/dev/null || { echo "SKIP: vdb_print not installed"; exit 77; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
P="$VP_SRC/vdb_samples/peanut.obj"

bad() { # EXPECTED_STATUS WORDS args...: one line, the status, no output file
  local want=$1 word=$2; shift 2
  rm -f bad.csv
  set +e; "$VDBPACK" pack "$@" >bad.out 2>bad.err; local st=$?; set -e
  [ "$st" = "$want" ] || die "'$*' exited $st, expected $want: $(cat bad.err)"
  [ "$(wc -l <bad.err)" = 1 ] || die "'$*' printed $(wc -l <bad.err) lines on stderr: $(cat bad.err)"
  grep -qF -- "$word" bad.err || die "'$*': message lacks '$word': $(cat bad.err)"
  [ ! -e bad.csv ] || die "'$*' left an output file"
  echo "  ok ($st): $(cat bad.err)"
}

echo "=== spellings: --opt value, --opt=value, abbreviations, --, clusters"
"$VDBPACK" pack box:1,1,1 --radius 0.05 -o a.csv -q
"$VDBPACK" pack box:1,1,1 --radius=0.05 --output=b.csv -q
"$VDBPACK" pack --rad 0.05 -qo c.csv box:1,1,1
cp "$P" ./-peanut.obj
"$VDBPACK" pack --radius 0.1 -o d.csv -q -- -peanut.obj
"$VDBPACK" pack "$P" --radius 0.1 -o e.csv -q
cmp -s a.csv b.csv && cmp -s a.csv c.csv || die "--radius 0.05, --radius=0.05 and --rad 0.05 differ"
cmp -s d.csv e.csv || die "a container after -- differs from the same mesh given plainly"
echo "  ok: one packing for --radius 0.05, --radius=0.05, --rad 0.05 (-qo), and after --"
# captured whole: head closing the pipe early would kill the writer (pipefail)
he=$("$VDBPACK" pack box:1,1,1 --he) || die "--he failed"
printf '%s\n' "$he" | sed -n 1p | grep -q "^Usage: vdbpack pack" || die "--he is not --help"
bad 2 "is ambiguous (--radius, --retries, --rotate, --rotations, --radius-field, --radius-field-mode)" box:1,1,1 --r 0.05 -o bad.csv
bad 2 "unknown option '--frobnicate'" box:1,1,1 --radius 0.05 -o bad.csv --frobnicate
bad 2 "--grow takes no value" box:1,1,1 --method rsa --radius 0.05 --count 10 --grow=1 -o bad.csv
bad 2 "--radius needs a value" box:1,1,1 -o bad.csv --radius
bad 2 "--output is given twice" box:1,1,1 --radius 0.05 -o bad.csv --out=bad.csv

echo "=== options given to the wrong method name the methods that take them"
bad 2 "--grow goes with --method rsa, not lattice" box:1,1,1 --radius 0.05 --grow -o bad.csv
bad 2 "--tolerance goes with --method relax and jam, not rsa" box:1,1,1 --method rsa --radius 0.05 --count 10 --tolerance 0.01 -o bad.csv
bad 2 "--lattice goes with --method lattice, not jam" box:1,1,1 --method jam --count 100 --lattice fcc -o bad.csv
bad 2 "--target-fraction goes with --method rsa, relax and jam, not lattice" box:1,1,1 --radius 0.05 --target-fraction 0.3 -o bad.csv
bad 2 "distributions of radii go with --method rsa, relax and jam" box:1,1,1 --radius uniform:0.01:0.03 -o bad.csv
bad 2 "--count max goes with --method rsa, not relax" box:1,1,1 --method relax --radius 0.05 --count max -o bad.csv
bad 2 "--count max needs --radius" box:1,1,1 --method rsa --count max -o bad.csv
bad 2 "not both" box:1,1,1 --method rsa --count 100 --radius 0.05 --target-fraction 0.2 -o bad.csv

echo "=== rsa --count N alone: N spheres of the radius at which they fill --target-fraction"
for f in default 0.2; do
  extra=(); [ "$f" = default ] || extra=(--target-fraction "$f")
  "$VDBPACK" pack box:1,2,1 --method rsa --count 3000 "${extra[@]}" -o n.csv --json >n.json
  "$PY" - n.csv n.json "$f" <<'PY' || exit 1
import json, sys
import numpy as np
a = np.genfromtxt(sys.argv[1], delimiter=",", names=True)
d = json.load(open(sys.argv[2]))
f = 0.3 if sys.argv[3] == "default" else float(sys.argv[3])
want = np.float32((f * 2.0 / (3000 * 4.0 / 3.0 * np.pi)) ** (1.0 / 3.0))
assert len(a) == 3000, len(a)
assert np.all(a["pscale"].astype(np.float32) == want), (a["pscale"].min(), a["pscale"].max(), want)
vol = (4.0 / 3.0 * np.pi * a["pscale"] ** 3).sum() / 2.0
assert abs(vol - f) < 1e-5, vol
assert d["short"] is False and d["target_fraction"] == f, d
print("  ok: target %.2f: 3000 spheres in the file, every radius %.7g, fraction %.6f" % (f, want, vol))
PY
done

echo "=== a shortfall: exit 4, one warning line, JSON and metadata"
set +e; "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.2 --count 20 --retries 200 -o s.vdb --json >s.json 2>s.err; st=$?; set -e
[ "$st" = 4 ] || die "a short run exited $st, not 4: $(cat s.err)"
[ "$(wc -l <s.err)" = 1 ] && grep -q "^vdbpack: warning: packed, but short: placed [0-9]* of the 20 particles" s.err ||
  die "warning: $(cat s.err)"
[ -s s.vdb ] || die "a short run left no file"
vdb_print -m s.vdb >s.meta
"$PY" - s.json s.meta <<'PY' || exit 1
import json, sys
d = json.load(open(sys.argv[1]))
meta = dict(l.split(": ", 1) for l in open(sys.argv[2]).read().splitlines() if ": " in l and not l.startswith(" "))
p = d["passes"][0]
assert d["short"] is True and p["short"] is True and p["requested"] == 20 and 0 < p["placed"] < 20, p
assert meta["requested"] == "20" and meta["placed"] == str(p["placed"]) and meta["short"] == "1", meta
assert int(meta["particle_count"]) == p["placed"] == d["count"], meta
print("  ok: exit 4; JSON and metadata (vdb_print): requested 20, placed %d, short" % p["placed"])
PY
set +e; "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.2 --count 20 --retries 200 -o s2.vdb --allow-short -q 2>s2.err; st=$?; set -e
[ "$st" = 0 ] && [ ! -s s2.err ] || die "--allow-short -q: exit $st, $(cat s2.err)"
"$VDBPACK" convert s.vdb s.csv && "$VDBPACK" convert s2.vdb s2.csv && cmp -s s.csv s2.csv ||
  die "--allow-short changed the packing"
echo "  ok: --allow-short: exit 0, the same particles"
# two passes, the second maximal: requested "100,max"; a maximal pass is
# never short, so the run is short by its first pass only
set +e; "$VDBPACK" pack "$P" --method rsa --pass count=100,radius=0.12 --pass count=max,radius=0.05 -o t.vdb -q; st=$?; set -e
vdb_print -m t.vdb >t.meta
grep -q "^requested: 100,max$" t.meta || die "two passes: $(grep requested t.meta)"
placed1=$(sed -n 's/^placed: \([0-9]*\),.*/\1/p' t.meta)
if [ "$placed1" -lt 100 ]; then [ "$st" = 4 ] || die "short first pass, exit $st"; else [ "$st" = 0 ] || die "exit $st"; fi
echo "  ok: two passes: $(grep -E '^(requested|placed|short):' t.meta | tr '\n' ' ')exit $st"
for r in 0.05 uniform:0.03:0.06; do
  "$VDBPACK" pack box:1,1,1 --method rsa --radius "$r" --count max -o m.vdb --json >m.json ||
    die "a maximal pass exited $?"
  "$PY" -c "
import json; d = json.load(open('m.json')); p = d['passes'][0]
assert d['short'] is False and p['short'] is False and p['stop'] == 'maximal', p
print('  ok: maximal, radius $r: %d placed, not short, exit 0' % p['placed'])"
  "$VDBPACK" check m.vdb --container box:1,1,1 -q || die "check: maximal $r"
done
echo "=== --margin and --gap: kept (numpy from the CSV), honoured by check"
"$VDBPACK" pack box:1,1,1 --method rsa --radius uniform:0.03:0.05 --count 300 --grow --margin 0.05 --gap=0.01 \
  -o g.vdb --json >g.json
"$VDBPACK" convert g.vdb g.csv -q
"$PY" - g.csv g.json <<'PY' || exit 1
import json, sys
import numpy as np
a = np.genfromtxt(sys.argv[1], delimiter=",", names=True)
P = np.stack([a["x"], a["y"], a["z"]], 1); r = a["pscale"]
d = np.sqrt(((P[:, None, :] - P[None, :, :]) ** 2).sum(-1)) - r[:, None] - r[None, :]
np.fill_diagonal(d, np.inf)
wall = (0.5 - np.abs(P)).min(1) - r
j = json.load(open(sys.argv[2]))
assert j["margin"] == 0.05 and j["gap"] == 0.01, j
assert d.min() >= 0.01 - 1e-7 and d.min() <= 0.01 * 1.001, d.min()
assert wall.min() >= 0.05 - 1e-7, wall.min()
print("  ok: 300 grown spheres: smallest gap %.7f (0.01), smallest wall distance %.7f (0.05)"
      % (d.min(), wall.min()))
PY
"$VDBPACK" check g.vdb --container box:1,1,1 -q || die "check with the file's margin and gap"
set +e; "$VDBPACK" check g.vdb --container box:1,1,1 --gap 0.0101 -q 2>/dev/null; st1=$?
"$VDBPACK" check g.vdb --container box:1,1,1 --margin 0.0505 -q 2>/dev/null; st2=$?; set -e
[ "$st1" = 3 ] && [ "$st2" = 3 ] || die "check with 1 % more gap, margin: exit $st1, $st2 (want 3)"
echo "  ok: check passes with the file's margin and gap, exit 3 with 1 % more of either"

echo "=== bad margins and gaps: one line, non-zero exit, no output"
bad 2 "--gap 0.05 must be smaller than the smallest radius" box:1,1,1 --method rsa --radius uniform:0.05:0.08 --count 10 --gap 0.05 -o bad.csv
bad 2 "--gap 0.05 must be smaller than the radius" box:1,1,1 --method rsa --count 100000 --gap 0.05 -o bad.csv
bad 2 "--margin must be a distance >= 0" box:1,1,1 --method rsa --radius 0.05 --count 10 --margin -0.1 -o bad.csv
bad 2 "--margin must be a distance >= 0" box:1,1,1 --method rsa --radius 0.05 --count 10 --margin nan -o bad.csv
bad 2 "and the smallest radius leave no room in box:1,1,1, whose inradius is 0.5" box:1,1,1 --method rsa --radius 0.05 --count 10 --margin 0.46 -o bad.csv
bad 2 "--margin 0.5 leaves no room in sphere:0.5, whose inradius is 0.5" sphere:0.5 --method rsa --radius 0.05 --count 10 --margin 0.5 --fit center -o bad.csv
bad 1 "margin" "$P" --method rsa --radius 0.05 --count 10 --margin 0.8 -o bad.csv
bad 2 "--gap spaces a lattice of spheres in this version" box:1,1,1 --shape cube --radius 0.05 --gap 0.01 -o bad.csv
bad 2 "not mesh shapes (--margin is)" box:1,1,1 --method rsa --shape "$P" --radius 0.05 --count 10 --gap 0.01 -o bad.csv
bad 2 "not with --overlap bbox" box:1,1,1 --method rsa --shape cube --overlap bbox --radius 0.05 --count 10 --gap 0.01 -o bad.csv
echo "=== a value that looks like an abbreviated option stays as typed"
# (-o --d: the output '--d'; the abbreviation rewrite of '--d' was freed
# while the output name still pointed into it: fuzz_options found it)
bad 2 "the format of '--d'" box:1,1,1 --radius 0.2 -o --d
"$VDBPACK" pack box:1,1,1 --radius 0.2 --out=--d.csv -q || die "--out=--d.csv failed"
[ -s ./--d.csv ] || die "--out=--d.csv did not write './--d.csv'"
echo "  ok: --out=--d.csv wrote ./--d.csv"
echo "=== progress: nothing on a non-terminal; --progress: one line per stage"
"$VDBPACK" pack "$P" --method rsa --radius 0.03 --count 500 -o q.vdb >/dev/null 2>q.err
[ ! -s q.err ] || die "a non-terminal got progress output: $(cat q.err)"
"$VDBPACK" pack "$P" --method rsa --radius 0.03 --count 500 -o q.vdb --progress >/dev/null 2>q.err
"$PY" - q.err <<'PY' || exit 1
import sys
lines = open(sys.argv[1]).read().splitlines()
assert lines and all(l.startswith("progress: ") for l in lines), lines
rows = [l.split()[1:] for l in lines]
stages = [r[0] for r in rows]
fr = [float(r[1]) for r in rows]
secs = [float(r[2]) for r in rows]
assert len(set(stages)) == len(stages), stages            # one line per stage
assert stages[0] == "loading" and stages[-1] == "done", stages
for want in ("loading/voxelizing", "packing/rsa", "writing"):
    assert want in stages, (want, stages)
assert stages.index("loading") < stages.index("packing/rsa") < stages.index("writing")
assert fr == sorted(fr) and fr[-1] == 1.0 and 0 <= fr[0], fr   # monotone, ends at 1
assert secs == sorted(secs), secs
print("  ok: --progress: %d stages in order (%s), fractions %s" % (len(stages), " ".join(stages),
      " ".join("%.3f" % f for f in fr)))
PY
echo "=== progress on a terminal (script(1) gives one): the bar counts rsa's particles"
if command -v script >/dev/null 2>&1; then
  script -q -c "'$VDBPACK' pack box:1,1,1 --method rsa --pass count=300000,radius=0.008 --threads 1 -o t.vdb" \
    /dev/null >bar.txt 2>&1 </dev/null || die "the run under script failed: $(tail -c 300 bar.txt)"
  "$PY" - bar.txt <<'PY' || exit 1
import re, sys
text = open(sys.argv[1], errors="replace").read().replace("\r", "\n")
got = [(int(a), int(b)) for a, b in re.findall(r"rsa (\d+) of (\d+)", text)]
assert len(got) >= 2, text[-400:]
assert all(t == 300000 for _, t in got), got
done = [d for d, _ in got]
assert done == sorted(done) and 0 < done[0] < 300000, done
print("  ok: the bar counts %d states, %d .. %d of 300000" % (len(got), done[0], done[-1]))
PY
else
  echo "  (no script(1): the terminal bar is not tested)"
fi
echo "PASS: sh_options"

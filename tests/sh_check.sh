#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `vdbpack check`: every packer's output passes it (lattice spheres and each
# solid, 16-bit fixed-point and float P, analytic and mesh containers), and
# violations made by OpenVDB's own vdb_ax (not vdbpack) are caught: pscale
# scaled up (overlaps), one point moved out of the container (outside),
# positions stored too coarsely for their radii (imprecise), with exit
# status 3, one line on stderr under -q, and the JSON figures.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
command -v vdb_ax >/dev/null || { echo "SKIP: vdb_ax not installed"; exit 77; }
PY=/usr/bin/python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
AX=(env OPENVDB_DISABLE_DELAYED_LOAD=1 vdb_ax)
jget() { "$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }
S="$VP_SRC/vdb_samples"

passes() { # NAME CONTAINER pack-args...
  local name=$1 cont=$2; shift 2
  "$VDBPACK" pack "$cont" -o "$name.vdb" -q "$@" 2>"$name.err" || die "$name: pack: $(cat "$name.err")"
  "$VDBPACK" check "$name.vdb" --container "$cont" --json >"$name.json" 2>"$name.err" ||
    die "$name: check exited $?: $(cat "$name.err") $(cat "$name.json")"
  [ "$(jget "$name.json" overlapping_pairs)" = 0 ] && [ "$(jget "$name.json" outside)" = 0 ] ||
    die "$name: $(cat "$name.json")"
  echo "  ok: $name: $(jget "$name.json" count) $(jget "$name.json" shape)s, no violation," \
       "fraction $(jget "$name.json" packing_fraction), mean contacts $(jget "$name.json" mean_contacts)"
}
echo "=== every packer's output passes"
passes fcc box:1,1,1 --radius 0.05
passes hcp_center sphere:1 --lattice hcp --fit center --radius 0.07
for s in tetrahedron cube octahedron dodecahedron icosahedron; do
  passes "$s" sphere:1 --shape "$s" --radius 0.12
done
passes peanut "$S/peanut.obj" --radius 0.05
passes rsa_peanut "$S/peanut.obj" --method rsa --pass count=50,radius=0.1,grow --pass count=2000,radius=0.03
passes relax_torus "$S/torus_ls.vdb" --method relax --radius 0.04 --count 800 --target-fraction 0.45
# lattice contacts: FCC has 12 neighbours inside; the mean is a bit lower for the border
"$PY" -c "
import json; d = json.load(open('fcc.json'))
assert 6 < d['mean_contacts'] <= 12, d['mean_contacts']
assert d['position_error'] > 0, 'fixed16 P should report its position error'
print('  ok: FCC mean contacts %.2f (12 in the bulk); fixed16 position error %.3g' % (d['mean_contacts'], d['position_error']))" ||
  die "fcc contacts"

# Lattice placements at the edge of what fits (found by an acceptance
# audit): spheres that touch both walls of a box (simple cubic, radius 0.05
# in a unit box: 1000 fit; rounding refused the touching ones and the
# search never tried the aligned offset: 729), and check accepts them;
# --rotate never ends below the search without it (it tried fewer offsets
# per orientation: 2399 against 2400 in the peanut); and --count 5 gives 5
# (it gave 4).
passes sc_touching box:1,1,1 --lattice sc --radius 0.05
passes sc_touching_full box:1,1,1 --lattice sc --radius 0.05 --precision full
passes sc_touching_234 box:2,3,4 --lattice sc --radius 0.25
passes sc_center box:1,1,1 --lattice sc --radius 0.05 --fit center
for n in sc_touching:1000 sc_touching_full:1000 sc_touching_234:192 sc_center:1331; do
  [ "$(jget "${n%%:*}.json" count)" = "${n##*:}" ] || die "${n%%:*}: $(jget "${n%%:*}.json" count) spheres, ${n##*:} fit"
done
passes peanut_rotate "$S/peanut.obj" --radius 0.05 --rotate
[ "$(jget peanut_rotate.json count)" -ge "$(jget peanut.json count)" ] ||
  die "--rotate placed $(jget peanut_rotate.json count), fewer than $(jget peanut.json count) without it"
echo "  ok: --rotate $(jget peanut_rotate.json count) >= $(jget peanut.json count) without"
for n in 1 2 3 5 7; do
  passes "peanut_count$n" "$S/peanut.obj" --count "$n"
  [ "$(jget "peanut_count$n.json" count)" = "$n" ] || die "--count $n gave $(jget "peanut_count$n.json" count)"
done

echo "=== violations made with vdb_ax are caught"
viol() { # NAME SRC FIELD SNIPPET (vdb_ax)
  local name=$1 src=$2 field=$3 code=$4
  "${AX[@]}" -i "$src.vdb" -s "$code" -o "$name.vdb" >ax.out 2>&1 || die "vdb_ax: $(cat ax.out)"
  set +e; "$VDBPACK" check "$name.vdb" --container "$5" --json >"$name.json" 2>"$name.err"; local st=$?; set -e
  [ "$st" = 3 ] || die "$name: check exited $st, expected 3: $(cat "$name.err")"
  [ "$(wc -l <"$name.err")" = 1 ] || die "$name: expected one line on stderr: $(cat "$name.err")"
  [ "$(jget "$name.json" "$field")" != 0 ] || die "$name: $field is 0: $(cat "$name.json")"
  echo "  ok: $name: exit 3, $field = $(jget "$name.json" "$field"): $(cat "$name.err")"
}
viol fcc_fat fcc overlapping_pairs '@pscale *= 1.01f;' box:1,1,1
viol rsa_fat rsa_peanut overlapping_pairs 'if (i@id == 7) @pscale *= 3.0f;' "$S/peanut.obj"
viol fcc_out fcc outside 'if (i@id == 0) @P.x += 2.0f;' box:1,1,1
viol cube_out cube outside 'if (i@id == 3) @P.y += 1.5f;' sphere:1
# the same overlap below the tolerance passes; above, the text report says VIOLATION
"${AX[@]}" -i fcc.vdb -s '@pscale *= 1.0000001f;' -o tiny.vdb >/dev/null 2>&1
"$VDBPACK" check tiny.vdb --container box:1,1,1 -q || die "an overlap of 1e-7 (below 1e-6) was flagged"
set +e; "$VDBPACK" check fcc_fat.vdb --container box:1,1,1 >fat.txt 2>&1; st=$?; set -e
[ "$st" = 3 ] && grep -q VIOLATION fat.txt || die "text report: exit $st: $(cat fat.txt)"
"$VDBPACK" check fcc_fat.vdb --container box:1,1,1 --overlap-tolerance 0.02 -q ||
  die "--overlap-tolerance 0.02 should accept a 1% overlap"
echo "  ok: tolerance respected both ways"

echo "=== tiny packings: positions stored precisely enough, or a violation"
# (audit) 16-bit fixed point in OpenVDB's smallest voxel (1.44e-5) rounds
# positions by up to 3.8e-10: 2 % of a radius of 2e-8, and check passed such
# a file (max_overlap 0.004) by widening its tolerances by that error. pack
# must write float P there, and check must flag a file that has the error.
"$VDBPACK" pack sphere:1e-7 --radius 2e-8 -o tiny.vdb >tiny_pack.txt 2>tiny_pack.err ||
  die "tiny pack: $(cat tiny_pack.err)"
grep -q "P stored as 32-bit float" tiny_pack.txt || die "tiny pack: no precision line: $(cat tiny_pack.txt)"
"$VDBPACK" check tiny.vdb --container sphere:1e-7 --json >tiny.json 2>tiny.err ||
  die "tiny: check exited $?: $(cat tiny.err) $(cat tiny.json)"
"$PY" -c "
import json; d = json.load(open('tiny.json'))
assert d['count'] == 55, d['count']
assert d['position_error'] <= 1e-3 * 2e-8, 'position error %g of radius 2e-8' % d['position_error']
assert d['max_overlap'] <= 1e-3, 'max_overlap %g' % d['max_overlap']
assert d['imprecise'] is False and d['ok'] is True, d
print('  ok: 55 spheres of radius 2e-8: position error %.3g, max_overlap %.3g' % (d['position_error'], d['max_overlap']))" ||
  die "tiny: $(cat tiny.json)"
# one sphere of radius 1e-6: its voxel (2 r) was below OpenVDB's smallest
# scale ("ArithmeticError: Non-zero scale values required")
printf 'id,x,y,z,pscale,group\n0,1e-7,0,-2e-7,1e-6,pass1\n' >one.csv
"$VDBPACK" convert one.csv one.vdb -q 2>one.err || die "one small sphere: convert: $(cat one.err)"
"$VDBPACK" check one.vdb --container sphere:1e-5 -q || die "one small sphere: check failed"
echo "  ok: one sphere of radius 1e-6 written and checked"
# the same 55 spheres written as 16-bit fixed point by OpenVDB's own tools
# (vdb_tool, pscale added by vdb_ax): a violation, exit 3, one line
if command -v vdb_tool >/dev/null; then
  "$VDBPACK" pack sphere:1e-7 --radius 2e-8 -o tiny.ply -q
  vdb_tool -read tiny.ply -points2vdb bits=16 -write tiny16_nopscale.vdb >vt.out 2>&1 || die "vdb_tool: $(cat vt.out)"
  "${AX[@]}" -i tiny16_nopscale.vdb -s 'f@pscale = 2e-8f;' -o tiny16.vdb >ax.out 2>&1 || die "vdb_ax: $(cat ax.out)"
  "$VDBPACK" info tiny16.vdb | grep -q 'P: vec3s \[fxpt16\]' || die "tiny16.vdb: P is not fixed16"
  set +e; "$VDBPACK" check tiny16.vdb --container sphere:1e-7 --json >tiny16.json 2>tiny16.err; st=$?; set -e
  [ "$st" = 3 ] || die "tiny16: check exited $st, expected 3: $(cat tiny16.err) $(cat tiny16.json)"
  [ "$(wc -l <tiny16.err)" = 1 ] && grep -q "too coarse" tiny16.err || die "tiny16: stderr: $(cat tiny16.err)"
  [ "$(jget tiny16.json imprecise)" = True ] || die "tiny16: $(cat tiny16.json)"
  set +e; "$VDBPACK" check tiny16.vdb --container sphere:1e-7 >tiny16.txt 2>&1; st=$?; set -e
  [ "$st" = 3 ] && grep -q VIOLATION tiny16.txt || die "tiny16 text report: exit $st: $(cat tiny16.txt)"
  echo "  ok: fixed16 P at radius 2e-8 (vdb_tool): exit 3: $(cat tiny16.err)"
else
  echo "  skipped: fixed16 file from vdb_tool (not installed)"
fi

echo "=== bad input"
bad() { # STATUS WORD args...
  local want=$1 word=$2; shift 2
  set +e; "$VDBPACK" check "$@" >bad.out 2>bad.err; local st=$?; set -e
  [ "$st" = "$want" ] || die "check $*: exit $st, expected $want: $(cat bad.err)"
  [ "$(wc -l <bad.err)" = 1 ] || die "check $*: $(wc -l <bad.err) lines on stderr"
  grep -qi -- "$word" bad.err || die "check $*: message lacks '$word': $(cat bad.err)"
  echo "  ok: $(cat bad.err)"
}
bad 2 "container" fcc.vdb
bad 2 "no file" --container box:1,1,1
bad 1 "no such file" missing.vdb --container box:1,1,1
bad 1 "point data" "$S/sphere_ls.vdb" --container box:1,1,1
bad 2 "malformed" fcc.vdb --container box:1,-1,1
bad 2 "overlap-tolerance" fcc.vdb --container box:1,1,1 --overlap-tolerance -1
bad 2 "unknown option" fcc.vdb --container box:1,1,1 --frobnicate
echo "PASS: sh_check"

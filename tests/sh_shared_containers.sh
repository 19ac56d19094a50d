#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# vdbpack on the shared third-party containers (../shared/containers):
# clean closed meshes pack to about --count N with a sane packing fraction and
# a level-set volume close to the mesh's own (computed here in numpy); open
# meshes with --inside closed, and fog volumes without --iso, are refused with
# one line; level sets from .vdb work; every file packs and checks or is refused.
set -euo pipefail

VDBPACK=${VDBPACK:-vdbpack}
VP_SRC=${VP_SRC:-$(cd "$(dirname "$0")/.." && pwd)}
VP_SHARED=${VP_SHARED:-$VP_SRC/../shared/containers}
[ -d "$VP_SHARED" ] || { echo "SKIP: $VP_SHARED absent"; exit 77; }
PY=""
for p in python3 /usr/bin/python3; do
    if command -v "$p" >/dev/null && "$p" -c 'import numpy' 2>/dev/null; then PY=$p; break; fi
done
[ -n "$PY" ] || { echo "SKIP: no python3 with numpy"; exit 77; }
CHECK="$VP_SRC/tests/py/vp_check.py"

W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$W"
NFAIL=0
fail() { echo "FAIL: $*"; NFAIL=$((NFAIL + 1)); }
jget() { "$PY" "$CHECK" json "$1" "$2"; }
# between LO HI X: LO < X < HI
between() { awk -v lo="$1" -v hi="$2" -v x="$3" 'BEGIN { exit !(x > lo && x < hi) }'; }

# --- clean closed meshes ------------------------------------------------------
pack_mesh() { # FILE COUNT
    local m=$1 n=$2 f=$VP_SHARED/$1
    [ -f "$f" ] || { echo "--- $m: absent, skipped"; return; }
    echo "--- $m: pack --count $n"
    local rc=0 t0 t1
    t0=$(date +%s)
    "$VDBPACK" pack "$f" --count "$n" -o out.vdb --json >s.json 2>err.txt || rc=$?
    t1=$(date +%s)
    if [ "$rc" != 0 ]; then fail "$m: exit $rc: $(cat err.txt)"; return; fi
    local c pf cv mv
    c=$(jget s.json count)
    pf=$(jget s.json packing_fraction)
    cv=$(jget s.json container_volume)
    mv=$("$PY" "$VP_SRC/tests/py/mesh_volume.py" "$f")
    echo "    count $c, packing fraction $pf, level-set volume $cv, mesh volume $mv," \
        "voxel $(jget s.json voxel_size), $((t1 - t0)) s"
    between "$(awk -v n="$n" 'BEGIN{print n*0.98}')" "$(awk -v n="$n" 'BEGIN{print n*1.02}')" "$c" ||
        fail "$m: count $c not within 2% of $n"
    between 0.3 0.75 "$pf" || fail "$m: packing fraction $pf outside (0.3, 0.75)"
    between 0.95 1.05 "$(awk -v a="$cv" -v b="$mv" 'BEGIN{print a/b}')" ||
        fail "$m: level-set volume $cv not within 5% of the mesh volume $mv"
    # the file holds what the summary says (counted by OpenVDB's vdb_tool)
    if command -v vdb_tool >/dev/null; then
        vdb_tool -quiet -read out.vdb grids=points -vdb2points -write out.ply >/dev/null 2>&1 ||
            { fail "$m: vdb_tool cannot read the output"; return; }
        local k
        k=$("$PY" "$CHECK" plycount out.ply)
        [ "$k" = "$c" ] || fail "$m: vdb_tool extracts $k points, summary says $c"
    fi
}
pack_mesh spot_control_mesh.obj 2000
pack_mesh spot.obj 2000
pack_mesh fandisk.obj 2000
pack_mesh skull.obj 2000
pack_mesh boot.obj 2000
pack_mesh sword.obj 2000

# --- open meshes: refused with --inside closed, one line naming edge counts
# (by default they pack inside their winding number: tests/sh_inside.sh, and
# the loop over every file below)
refuse() { # FILE REGEX [pack options]
    local m=$1 re=$2 f=$VP_SHARED/$1
    shift 2
    [ -f "$f" ] || { echo "--- $m: absent, skipped"; return; }
    echo "--- $m $*: must be refused"
    rm -f out.vdb
    local rc=0
    "$VDBPACK" pack "$f" --count 2000 -o out.vdb "$@" >/dev/null 2>err.txt || rc=$?
    [ "$rc" != 0 ] || { fail "$m was packed"; return; }
    [ "$(wc -l <err.txt)" = 1 ] || fail "$m: $(wc -l <err.txt) lines on stderr: $(cat err.txt)"
    grep -Eq -- "$re" err.txt || fail "$m: message does not match /$re/: $(cat err.txt)"
    [ ! -e out.vdb ] || fail "$m: out.vdb left behind"
    echo "    exit $rc: $(cat err.txt)"
}
EDGES='[0-9]+ boundary edges|[0-9]+ non-manifold edges'
refuse suzanne.obj "$EDGES" --inside closed
refuse teapot.obj "$EDGES" --inside closed
refuse stanford-bunny.obj "$EDGES" --inside closed
refuse 3dfier_testarea.obj "$EDGES" --inside closed
refuse gaffer_smoke_fog.vdb "density"

# --- level sets from .vdb --------------------------------------------------------
if [ -f "$VP_SHARED/gaffer_ls_sphere.vdb" ]; then
    echo "--- gaffer_ls_sphere.vdb: --radius 0.2"
    if "$VDBPACK" pack "$VP_SHARED/gaffer_ls_sphere.vdb" --radius 0.2 -o ls.vdb --json >s.json 2>err.txt; then
        cv=$(jget s.json container_volume)
        want=$(awk 'BEGIN{printf "%.10g", 4/3*atan2(0,-1)*27}')
        echo "    count $(jget s.json count), packing fraction $(jget s.json packing_fraction)," \
            "volume $cv (sphere of radius 3: $want)"
        between 0.97 1.03 "$(awk -v a="$cv" -v b="$want" 'BEGIN{print a/b}')" ||
            fail "gaffer_ls_sphere: volume $cv not within 3% of $want"
        between 0.3 0.75 "$(jget s.json packing_fraction)" || fail "gaffer_ls_sphere: packing fraction"
    else
        fail "gaffer_ls_sphere.vdb: $(cat err.txt)"
    fi
fi
if [ -f "$VP_SHARED/zeno_res.vdb" ]; then
    echo "--- zeno_res.vdb (unnamed grid): --count 500 --fit center"
    rc=0
    "$VDBPACK" pack "$VP_SHARED/zeno_res.vdb" --count 500 --fit center -o z.vdb --json >s.json 2>err.txt || rc=$?
    if [ "$rc" = 0 ]; then
        c=$(jget s.json count)
        echo "    packed: count $c, packing fraction $(jget s.json packing_fraction), volume $(jget s.json container_volume)"
        between 490 510 "$c" || fail "zeno_res: count $c not within 2% of 500"
    else
        [ "$(wc -l <err.txt)" = 1 ] || fail "zeno_res: refused with $(wc -l <err.txt) lines: $(cat err.txt)"
        [ ! -e z.vdb ] || fail "zeno_res: z.vdb left behind"
        echo "    refused (accepted): $(cat err.txt)"
    fi
fi

# --- every file: packs and passes `vdbpack check`, or is refused ------------
echo "=== every file in $VP_SHARED"
for f in "$VP_SHARED"/*; do
    m=$(basename "$f")
    case $m in *.md|*.txt) continue ;; esac
    rm -f every.vdb
    rc=0
    "$VDBPACK" pack "$f" --count 1000 -o every.vdb -q 2>err.txt || rc=$?
    if [ "$rc" = 0 ]; then
        crc=0
        "$VDBPACK" check every.vdb --container "$f" >check.txt 2>&1 || crc=$?
        if [ "$crc" = 0 ]; then
            echo "  $m: packed, check passed: $(grep -Eo 'max_overlap[^,]*|outside[^,]*' check.txt | head -2 | tr '\n' ' ')"
        else
            fail "$m: packed but vdbpack check exits $crc: $(tail -3 check.txt)"
        fi
    else
        if [ "$rc" -gt 2 ] || [ "$(wc -l <err.txt)" != 1 ] || ! grep -q "$m" err.txt || [ -e every.vdb ]; then
            fail "$m: refused badly (exit $rc, $(wc -l <err.txt) lines, output left: $([ -e every.vdb ] && echo yes || echo no)): $(cat err.txt)"
        else
            echo "  $m: refused: $(cat err.txt)"
        fi
    fi
done

if [ "$NFAIL" -gt 0 ]; then
    echo "FAILED: $NFAIL check(s)"
    exit 1
fi
echo "PASS: sh_shared_containers"

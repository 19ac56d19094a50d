#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# vdbpack output read back ONLY with OpenVDB's own tools (vdb_print, vdb_ax,
# vdb_tool) and Python/numpy (tests/py/vp_check.py); expected values are
# computed independently (geometry, literature lattice fractions).
set -euo pipefail

VDBPACK=${VDBPACK:-vdbpack}
VP_SRC=${VP_SRC:-$(cd "$(dirname "$0")/.." && pwd)}
CHECK="$VP_SRC/tests/py/vp_check.py"

for t in vdb_print vdb_ax vdb_tool; do
    command -v "$t" >/dev/null || { echo "SKIP: $t not installed"; exit 77; }
done
PY=""
for p in python3 /usr/bin/python3; do
    if command -v "$p" >/dev/null && "$p" -c 'import numpy' 2>/dev/null; then PY=$p; break; fi
done
[ -n "$PY" ] || { echo "SKIP: no python3 with numpy"; exit 77; }

W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$W"

die() { echo "FAIL: $*"; exit 1; }
jget() { "$PY" "$CHECK" json "$1" "$2"; }

# vdb_ax (OpenVDB 10, assertions on) aborts on "uniform" attribute arrays read
# with delayed loading + blosc (an OpenVDB issue, reproducible with a file
# written by plain OpenVDB API).  vdbpack writes pscale uniform, so we note
# the abort and load everything eagerly for the real checks.
AXENV=(env OPENVDB_DISABLE_DELAYED_LOAD=1)

plycount() { # VDB -> number of points as seen by vdb_tool
    vdb_tool -quiet -read "$1" grids=points -vdb2points -write "$2" >/dev/null 2>vt.err ||
        die "vdb_tool could not read $1: $(cat vt.err)"
    "$PY" "$CHECK" plycount "$2"
}

ax_keep_all() { # VDB CODE EXPECTED_COUNT WHAT
    local in=$1 code=$2 want=$3 what=$4
    rm -f ax.vdb
    "${AXENV[@]}" vdb_ax -i "$in" -s "$code" -o ax.vdb >ax.out 2>&1 ||
        die "vdb_ax failed ($what): $(cat ax.out)"
    local got
    got=$(plycount ax.vdb ax.ply)
    [ "$got" = "$want" ] || die "$what: vdb_ax deletepoint() left $got of $3 points (code: $code)"
    echo "  ok: $what (vdb_ax kept $got points)"
}

run_case() { # NAME CONTAINER SHAPE LATTICE FIT RADIUS [extra pack args]
    local name=$1 cont=$2 shape=$3 lat=$4 fit=$5 r=$6
    shift 6
    echo "=== $name: pack $cont --shape $shape --lattice $lat --fit $fit --radius $r $*"
    local out=$name.vdb
    "$VDBPACK" pack "$cont" --shape "$shape" --lattice "$lat" --fit "$fit" --radius "$r" \
        -o "$out" --json "$@" >"$name.json" 2>"$name.err" || die "pack failed: $(cat "$name.err")"
    [ ! -s "$name.err" ] || die "pack wrote to stderr: $(cat "$name.err")"
    local n
    n=$(jget "$name.json" count)
    [ "$n" -gt 0 ] || die "packed no particles"
    echo "  JSON: count $n, packing_fraction $(jget "$name.json" packing_fraction)"

    # (a) vdb_print
    vdb_print -l -m "$out" >vp.txt 2>&1 || true
    grep -q "^Name: points$" vp.txt || die "vdb_print -l does not list a grid named points: $(head -5 vp.txt)"
    grep -q "Type: Tree_ptdataidx32_5_4_3" vp.txt || die "vdb_print: grid points is not ptdataidx32"
    vdb_print "$out" 2>&1 | grep -Eq "^points +ptdataidx32 " || die "vdb_print short listing lacks 'points ptdataidx32'"
    grep -Eq "particle_count: $n\$" vp.txt || die "vdb_print metadata particle_count != $n: $(grep particle_count vp.txt)"
    echo "  ok: vdb_print lists grid points of type ptdataidx32, metadata particle_count $n"
    # vdb_print 10.0 does not print a point count; count with vdb_tool instead
    local m
    m=$(plycount "$out" all.ply)
    [ "$m" = "$n" ] || die "vdb_tool -vdb2points gives $m points, JSON count $n"
    echo "  ok: vdb_tool -vdb2points extracts $m points == JSON count"

    # (b) vdb_ax: every point satisfies the properties (none deleted) ...
    local rf
    rf=$(jget "$name.json" radius)
    local ptest
    if [ "$fit" = inside ] && [ "$shape" = sphere ]; then
        case $cont in
        sphere:*) ptest="length(@P) > ${cont#sphere:} - $rf + 1e-3 * $rf" ;;
        box:*)
            IFS=, read -r bx by bz <<<"${cont#box:}"
            ptest="abs(@P.x) > $bx/2 - $rf + 1e-3*$rf || abs(@P.y) > $by/2 - $rf + 1e-3*$rf || abs(@P.z) > $bz/2 - $rf + 1e-3*$rf" ;;
        esac
    else
        case $cont in
        sphere:*) ptest="length(@P) > ${cont#sphere:} + 1e-3 * $rf" ;;
        box:*)
            IFS=, read -r bx by bz <<<"${cont#box:}"
            ptest="abs(@P.x) > $bx/2 + 1e-3*$rf || abs(@P.y) > $by/2 + 1e-3*$rf || abs(@P.z) > $bz/2 + 1e-3*$rf" ;;
        esac
    fi
    ax_keep_all "$out" "if (i@id < 0 || i@id >= $n) deletepoint();" "$n" "every id in [0,$n)"
    ax_keep_all "$out" "if (abs(f@pscale - float($rf)) > 1e-6f * float($rf)) deletepoint();" "$n" \
        "every pscale == radius $rf (float precision)"
    ax_keep_all "$out" "if ($ptest) deletepoint();" "$n" "every P inside $cont (fit $fit)"
    ax_keep_all "$out" 'if (!ingroup("pass1")) deletepoint();' "$n" "every point in group pass1"
    # ... and the same mechanism does delete when the property is violated
    ax_keep_all "$out" "if (i@id < $((n / 2))) deletepoint();" "$((n - n / 2))" \
        "negative control: deleting id < $((n / 2))"
    # ids unique: move every point to (id, pscale, 0), extract with vdb_tool
    rm -f ids.vdb
    "${AXENV[@]}" vdb_ax -i "$out" -s '@P = {float(i@id), f@pscale, 0.0f};' -o ids.vdb >ax.out 2>&1 ||
        die "vdb_ax id->P failed: $(cat ax.out)"
    vdb_tool -quiet -read ids.vdb -vdb2points -write ids.ply >/dev/null 2>&1 || die "vdb_tool on ids.vdb"
    "$PY" "$CHECK" ids --ply ids.ply --n "$n" --radius "$rf"

    # orient: quats for solids, absent for spheres (type check by vdb_ax itself)
    "${AXENV[@]}" vdb_ax -i "$out" -s 'vec4f q = vec4f@orient; if (q[0] > 2.0f) deletepoint();' \
        >orient.txt 2>&1 || true
    if [ "$shape" = sphere ]; then
        grep -q 'orient.*exists of type' orient.txt && die "a sphere packing carries orient: $(cat orient.txt)"
        echo "  ok: no orient attribute on spheres"
    else
        grep -q 'Attribute "orient" on grid "points" exists of type "quats"' orient.txt ||
            die "vdb_ax does not see orient as quats: $(cat orient.txt)"
        echo "  ok: vdb_ax reports orient of type quats (not vec4)"
        # unit quaternions: the ax kernel over orient cannot read quats, so
        # the raw check is in vdbpack info --json type only (below)
    fi

    # (c) geometry of the extracted positions
    "$PY" "$CHECK" geom --ply all.ply --summary "$name.json" --container "$cont" \
        --shape "$shape" --lattice "$lat" --fit "$fit" --radius "$rf"
    case $cont in sphere:* | box:*)
        "$PY" "$CHECK" fraction --summary "$name.json" --container "$cont" --shape "$shape" \
            --lattice "$lat" ;;
    esac
    # vdbpack info --json: metadata equals the summary
    "$VDBPACK" info "$out" --json >info.json 2>info.err || die "vdbpack info failed: $(cat info.err)"
    "$PY" "$CHECK" info --info info.json --summary "$name.json"
}

# note the vdb_ax delayed-loading abort once (not a failure of vdbpack)
"$VDBPACK" pack sphere:3 --radius 1 -o probe.vdb -q
if vdb_ax -i probe.vdb -s 'f@pscale += 0.0f;' -o probe2.vdb >probe.txt 2>&1; then
    echo "note: vdb_ax reads pscale with delayed loading fine"
else
    echo "NOTE: vdb_ax aborts on pscale with delayed loading (uniform attribute array + blosc):"
    grep -m1 -o "Assertion.*" probe.txt || true
    echo "      continuing with OPENVDB_DISABLE_DELAYED_LOAD=1"
fi

run_case sc sphere:10 sphere sc inside 1
run_case bcc sphere:10 sphere bcc inside 1
run_case fcc sphere:10 sphere fcc inside 1
run_case hcp sphere:10 sphere hcp inside 1
run_case fccbox box:12,10,8 sphere fcc inside 0.5
run_case fcccenter sphere:8 sphere fcc center 1
run_case fccfull sphere:10 sphere fcc inside 1 --precision full
run_case cube sphere:10 cube densest inside 1
run_case octa sphere:10 octahedron densest inside 1
run_case tetra box:8,8,8 tetrahedron densest inside 1
echo "PASS: sh_vdb_tools"

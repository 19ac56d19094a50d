#!/usr/bin/env bash
# Bad input to the vdbpack CLI: non-zero exit, exactly one line on stderr
# that names the problem, and no output (nor hidden temporary) file left.
set -euo pipefail

VDBPACK=${VDBPACK:-vdbpack}
VP_SRC=${VP_SRC:-$(cd "$(dirname "$0")/.." && pwd)}
VP_SHARED=${VP_SHARED:-$VP_SRC/../shared/containers}

W=$(mktemp -d)
trap 'chmod -R u+w "$W" 2>/dev/null; rm -rf "$W"' EXIT
cd "$W"
mkdir run
NFAIL=0
fail() { echo "FAIL: $*"; NFAIL=$((NFAIL + 1)); }

# expect_error NAME REGEX [MAX_SECONDS] -- vdbpack args...
# runs in ./run (inputs are referenced as ../x), checks status, stderr, files
expect_error() {
    local name=$1 re=$2 maxs=$3
    shift 4
    echo "--- $name: vdbpack $*"
    rm -rf run && mkdir run
    local t0 t1 rc=0
    t0=$(date +%s.%N)
    (cd run && "$VDBPACK" "$@" >../out.txt 2>../err.txt) || rc=$?
    t1=$(date +%s.%N)
    local lines
    lines=$(wc -l <err.txt)
    if [ "$rc" = 0 ]; then
        fail "$name: exit status 0 (stdout: $(head -c 300 out.txt))"
        return
    fi
    if [ "$rc" -gt 2 ]; then fail "$name: exit status $rc (crash? expected 1 or 2)"; fi
    if [ "$lines" != 1 ] || [ "$(tail -c 1 err.txt | od -An -c | tr -d ' ')" != '\n' ]; then
        fail "$name: expected exactly one line on stderr, got $lines: $(head -c 600 err.txt)"
    fi
    if ! grep -Eqi -- "$re" err.txt; then
        fail "$name: stderr does not match /$re/: $(cat err.txt)"
    fi
    local left
    left=$(cd run && find . -mindepth 1 -maxdepth 2 ! -name 'in_*' | sort | tr '\n' ' ')
    if [ -n "$left" ]; then fail "$name: files left behind: $left"; fi
    left=$(find . -maxdepth 2 -name '.*.tmp*' | tr '\n' ' ')
    if [ -n "$left" ]; then fail "$name: temporary files left behind: $left"; fi
    if [ -n "$maxs" ]; then
        if awk -v a="$t0" -v b="$t1" -v m="$maxs" 'BEGIN { exit !(b - a > m) }'; then
            fail "$name: took $(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.2f", b-a}') s (> $maxs s)"
        fi
    fi
    echo "    exit $rc: $(cat err.txt)"
}

# --- inputs ----------------------------------------------------------------
: >empty.obj
head -c 4096 /dev/urandom >random.obj
cube_obj() { # closed unit cube, 8 vertices, 12 triangles; $1 = first vertex x
    cat <<EOF
v $1 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
EOF
}
cube_obj 0 >cube.obj
cube_obj nan >nan.obj
cube_obj 0 | grep -v -e '^f 5 6 7$' -e '^f 5 7 8$' >open.obj # top face missing

# the closed cube itself packs (so the failures below are about the input)
"$VDBPACK" pack cube.obj --radius 0.1 -o good.vdb -q || fail "closed cube.obj does not pack"
rm -f good.vdb

# a float level set, written by OpenVDB's own tool
LS=""
if command -v vdb_tool >/dev/null; then
    vdb_tool -quiet -sphere r=1 voxel=0.05 name=ball -write ls.vdb >/dev/null 2>&1 && LS=ls.vdb
fi
if [ -z "$LS" ] && [ -f "$VP_SRC/vdb_samples/sphere.obj" ]; then
    "$VDBPACK" pack "$VP_SRC/vdb_samples/sphere.obj" --radius 0.1 -o x.vdb -q --save-container ls.vdb && LS=ls.vdb
    rm -f x.vdb
fi

# --- cases -------------------------------------------------------------------
expect_error "missing container" "nothere\.obj|no such|not found|cannot open|does not exist" "" -- pack ../nothere.obj --radius 1 -o out.vdb
expect_error "empty obj" "empty\.obj" "" -- pack ../empty.obj --radius 1 -o out.vdb
expect_error "random bytes obj" "random\.obj" "" -- pack ../random.obj --radius 1 -o out.vdb
expect_error "NaN vertex" "nan|not finite|non-finite|invalid" "" -- pack ../nan.obj --radius 0.1 -o out.vdb
expect_error "open mesh" "boundary edge" "" -- pack ../open.obj --radius 0.1 -o out.vdb
if [ -f "$VP_SHARED/gaffer_smoke_fog.vdb" ]; then
    expect_error "fog volume" "density" "" -- pack "$VP_SHARED/gaffer_smoke_fog.vdb" --radius 0.1 -o out.vdb
else
    echo "--- fog volume: skipped ($VP_SHARED absent)"
fi
if [ -n "$LS" ]; then
    expect_error "unknown --grid" "nope" "" -- pack ../$LS --grid nope --radius 0.1 -o out.vdb
else
    echo "--- unknown --grid: skipped (no vdb_tool, no vdb_samples/sphere.obj)"
fi
for r in 0 -1 nan abc inf 1e999; do
    expect_error "--radius $r" "radius" "" -- pack sphere:1 --radius "$r" -o out.vdb
done
expect_error "radius too large" "radius|too large|no particle|fit|0 particles|none" "" -- pack sphere:1 --radius 5 -o out.vdb
expect_error "--count 0" "count" "" -- pack sphere:1 --count 0 -o out.vdb
expect_error "--count -5" "count" "" -- pack sphere:1 --count -5 -o out.vdb
expect_error "no size" "radius|count" "" -- pack sphere:1 -o out.vdb
expect_error "radius and count" "radius|count" "" -- pack sphere:1 --radius 0.1 --count 10 -o out.vdb
expect_error "no -o" "output|-o" "" -- pack sphere:1 --radius 0.1
expect_error "malformed sphere:" "sphere:-1|malformed" "" -- pack sphere:-1 --radius 0.1 -o out.vdb
expect_error "malformed box:" "box:1,2|malformed" "" -- pack box:1,2 --radius 0.1 -o out.vdb
expect_error "unwritable dir" "nonexistent-dir" "" -- pack sphere:1 --radius 0.1 -o /nonexistent-dir/out.vdb
mkdir adir
expect_error "output is a directory" "adir|directory" "" -- pack sphere:1 --radius 0.1 -o ../adir
[ -d adir ] || fail "output directory was removed"
expect_error "memory refused" "memory|too many|too large" 5 -- pack sphere:1000 --radius 0.0001 -o out.vdb
expect_error "--max-memory refused" "memory" 5 -- pack sphere:10 --radius 0.001 --max-memory 10M -o out.vdb
expect_error "unknown option" "--frobnicate" "" -- pack sphere:1 --radius 0.1 -o out.vdb --frobnicate
expect_error "unknown --shape" "blob" "" -- pack sphere:1 --radius 0.1 --shape blob -o out.vdb
expect_error "fcc with cube" "fcc|lattice" "" -- pack sphere:1 --radius 0.1 --shape cube --lattice fcc -o out.vdb
expect_error "unknown --lattice" "zz" "" -- pack sphere:1 --radius 0.1 --lattice zz -o out.vdb
expect_error "--voxel-size on analytic" "voxel" "" -- pack sphere:1 --radius 0.1 --voxel-size 0.1 -o out.vdb
expect_error "unknown command" "frob" "" -- frob
expect_error "info missing file" "nothere\.vdb" "" -- info ../nothere.vdb
expect_error "info on random bytes" "random\.obj" "" -- info ../random.obj

# a failed pack must not clobber an existing output file
echo "--- existing output survives a failure"
echo keep >keep.vdb
"$VDBPACK" pack sphere:1 --radius 5 -o keep.vdb >/dev/null 2>&1 && fail "radius 5 in sphere:1 succeeded"
[ "$(cat keep.vdb)" = keep ] || fail "a failed pack changed the existing keep.vdb"
ls -a | grep -q '\.keep\.vdb\.tmp' && fail "hidden temp file left beside keep.vdb"

# --- help and version ------------------------------------------------------------
for args in "--help" "pack --help" "info --help" "--version"; do
    echo "--- vdbpack $args"
    rc=0
    # shellcheck disable=SC2086
    "$VDBPACK" $args >out.txt 2>err.txt || rc=$?
    [ "$rc" = 0 ] || fail "vdbpack $args: exit $rc"
    [ -s err.txt ] && fail "vdbpack $args wrote to stderr: $(head -3 err.txt)"
    case $args in
    --version) grep -Eq '^vdbpack [0-9]+\.[0-9]+' out.txt || fail "--version: $(cat out.txt)" ;;
    *) grep -q 'Usage' out.txt || fail "vdbpack $args: no usage text" ;;
    esac
    case $args in "pack --help")
        for o in --radius --count --shape --lattice --fit --offsets --rotate --precision \
            --save-container --shape-out --threads --max-memory --voxel-size --allow-open --grid --json; do
            grep -q -- "$o" out.txt || fail "pack --help does not mention $o"
        done ;;
    esac
done

if [ "$NFAIL" -gt 0 ]; then
    echo "FAILED: $NFAIL check(s)"
    exit 1
fi
echo "PASS: sh_cli_bad_input"

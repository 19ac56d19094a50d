#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 27, defects 2 and 7: file names.
# - two outputs, or an output and an input, that are one file spelled
#   differently (./x.vdb, a/../x.vdb, a link to the directory, a dangling
#   link, a hard link) are refused before any work (exit 2, one line,
#   nothing written), in pack, render and convert; different files that
#   look alike are not;
# - a legal 250-byte file name and paths up to PATH_MAX - 1 (4095 bytes)
#   are written by every command and output kind (the temporary name added
#   16 bytes to the target's: "File name too long"), and leave no
#   temporary;
# - a path one byte too long fails with one line that keeps its reason
#   (the line was cut at about 1 KB).
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
N=0
ok() { N=$((N + 1)); echo "  ok: $*"; }
S="$VP_SRC/vdb_samples"
cp "$S/box.obj" cube.obj
"$VDBPACK" pack box:1,1,1 --radius 0.2 -o pts.vdb -q

# exit 2, one line matching REGEX, and the directory as it was
same() { # NAME REGEX ARGS...
  local name=$1 re=$2; shift 2
  local before; before=$(find . -mindepth 1 | sort | md5sum)
  local st=0
  "$VDBPACK" "$@" >run.out 2>run.err || st=$?
  [ "$st" = 2 ] || die "$name: exit status $st: $(cat run.err)"
  [ "$(wc -l <run.err)" = 1 ] || die "$name: stderr: $(cat run.err)"
  grep -Eq -- "$re" run.err || die "$name: stderr does not match /$re/: $(cat run.err)"
  local msg; msg=$(cat run.err)
  rm -f run.out run.err
  [ "$(find . -mindepth 1 | sort | md5sum)" = "$before" ] || die "$name: the directory changed"
  ok "$name: exit 2: $msg"
}

echo "=== one file spelled two ways"
mkdir real sub
ln -s real ln
ln -s nowhere.vdb dangling.vdb
same "-o x.vdb --save-container ./x.vdb (the issue's case)" "-o and --save-container name the same file" \
  pack cube.obj --radius 0.2 -o x.vdb --save-container ./x.vdb
same "-o ln/x.png --format vdb --preview real/x.png (the issue's case)" "-o and --preview name the same file" \
  pack cube.obj --radius 0.2 -o ln/x.png --format vdb --preview real/x.png
same "sub/../x.vdb and x.vdb" "name the same file" pack cube.obj --radius 0.2 -o sub/../x.vdb --save-container x.vdb
same "$W/x.vdb (absolute) and x.vdb" "name the same file" pack cube.obj --radius 0.2 -o "$W/x.vdb" --save-container x.vdb
same "a dangling link and the file it names" "name the same file" \
  pack cube.obj --radius 0.2 -o dangling.vdb --save-container nowhere.vdb
same "--shape-out through a link to the directory" "-o and --shape-out name the same file" \
  pack cube.obj --radius 0.2 -o ln/s.obj --format vdb --shape-out real/s.obj
same "-o is the container, spelled ./cube.obj" "is the container itself" \
  pack cube.obj --radius 0.2 -o ./cube.obj --format vdb
ln cube.obj hard.obj
same "-o is a hard link to the container" "is the container itself" \
  pack cube.obj --radius 0.2 -o hard.obj --format vdb
same "--shape-out is the --shape mesh via a link" "is the --shape mesh itself" \
  pack box:2,2,2 --method rsa --shape cube.obj --radius 0.2 --count 3 -o p.vdb --shape-out "$(ln -s cube.obj shape_link.obj; echo shape_link.obj)"
same "convert: the output through a link to the directory" "the output is the input" \
  convert real/../pts.vdb ./pts.vdb
ln -s pts.vdb pts_link.csv
same "convert: the output a link to the input" "the output is the input" convert pts.vdb pts_link.csv
ln -s pts.vdb pts_image.png
same "render: -o a link to the packing" "is the packing it renders itself" render pts.vdb -o pts_image.png
same "render: -o the packing, spelled differently" "is the packing it renders itself" \
  render pts.vdb -o "$(ln -s ../pts.vdb real/p.png; echo ln/p.png)"
# different files that look alike still work
"$VDBPACK" pack cube.obj --radius 0.2 -o real/x.vdb --save-container x.vdb -q ||
  die "real/x.vdb and x.vdb were refused"
"$VDBPACK" pack cube.obj --radius 0.2 -o sub/x.vdb --save-container ln/y.vdb -q ||
  die "sub/x.vdb and ln/y.vdb were refused"
[ -f real/y.vdb ] && [ -f sub/x.vdb ] || die "outputs missing"
ok "two different files of one name in two directories are written"

echo "=== long names"
name250=$(printf 'n%.0s' $(seq 246)).vdb
[ ${#name250} = 250 ] || die "name of ${#name250} bytes"
base250=${name250%.vdb}
"$VDBPACK" pack cube.obj --radius 0.2 -o "$name250" --save-container "${base250:0:246}.l.vdb" \
  --shape-out "${base250:0:246}.obj" --preview "${base250:0:246}.png" -q ||
  die "pack with 250-byte names failed"
"$VDBPACK" convert "$name250" "${base250:0:246}.csv" -q || die "convert into a 250-byte name"
"$VDBPACK" convert "$name250" "${base250:0:246}.ply" -q || die "convert into a 250-byte .ply"
"$VDBPACK" render "$name250" -o "${base250:0:246}.exr" --size 16x16 -q || die "render into a 250-byte name"
"$VDBPACK" check "$name250" --container cube.obj -q || die "check of a 250-byte name"
"$VDBPACK" info "$name250" >/dev/null || die "info of a 250-byte name"
[ "$(ls | grep -c '^nnnn')" = 7 ] || die "expected 7 files with 250-byte names: $(ls | grep -c '^nnnn')"
[ -z "$(ls -A | grep '^\.vp-' || true)" ] || die "temporaries left: $(ls -A | grep '^\.vp-')"
ok "250-byte names: pack (4 outputs), convert (.csv, .ply), render (.exr), check, info"

# a directory chain making paths of any length up to 4095 bytes
deep=""
while [ $((${#deep} + 251)) -lt 3800 ]; do deep="$deep$(printf 'd%.0s' $(seq 250))/"; done
mkdir -p "$deep"
at_len() { # DIR-FILL-CHAR TOTAL NAME: a path of TOTAL bytes ending in /NAME
  local fill=$1 total=$2 name=$3
  local left=$((total - ${#deep} - ${#name} - 1)) d=$deep
  while [ "$left" -gt 200 ]; do # components of at most 200 bytes (NAME_MAX 255)
    d="$d$(printf "$fill%.0s" $(seq 150))/"
    left=$((left - 151))
  done
  d="$d$(printf "$fill%.0s" $(seq "$left"))"
  mkdir -p "$d"
  echo "$d/$name"
}
for total in 4090 4095; do
  for name in a.vdb "$(printf 'q%.0s' $(seq 60)).vdb"; do
    p=$(at_len e "$total" "$name")
    [ ${#p} = "$total" ] || die "path of ${#p} bytes, not $total"
    d=${p%/*}
    "$VDBPACK" pack cube.obj --radius 0.2 -o "$p" -q || die "pack -o a $total-byte path (${#name}-byte name)"
    "$VDBPACK" check "$p" --container cube.obj -q || die "check of a $total-byte path"
    "$VDBPACK" info "$p" >/dev/null || die "info of a $total-byte path"
    c=$(at_len f "$total" "${name%.vdb}.csv")
    "$VDBPACK" convert "$p" "$c" -q || die "convert into a $total-byte path"
    r=$(at_len g "$total" "${name%.vdb}.png")
    "$VDBPACK" render "$p" -o "$r" --size 16x16 -q || die "render into a $total-byte path"
    [ -f "$p" ] && [ -f "$c" ] && [ -f "$r" ] || die "$total-byte outputs missing"
    for dd in "$d" "${c%/*}" "${r%/*}"; do
      [ -z "$(ls -A "$dd" | grep '^\.vp-' || true)" ] || die "temporary left in a $total-byte path's directory"
    done
    ok "$total-byte paths (name of ${#name} bytes): pack, check, info, convert, render"
  done
done
# the other outputs of pack at 4095 bytes
o=$(at_len h 4095 m.vdb); l=$(at_len h 4095 l.vdb); s=$(at_len h 4095 s.obj); v=$(at_len h 4095 v.png)
"$VDBPACK" pack cube.obj --radius 0.2 -o "$o" --save-container "$l" --shape-out "$s" --preview "$v" -q ||
  die "pack with four 4095-byte outputs"
[ "$(ls -A "${o%/*}" | wc -l)" = 4 ] || die "expected 4 files: $(ls -A "${o%/*}")"
ok "pack -o, --save-container, --shape-out and --preview at 4095 bytes each"

echo "=== a path too long keeps its reason"
too=$(at_len e 4090 "")
too="${too%/}/$(printf 'z%.0s' $(seq 20)).vdb"
[ ${#too} -ge 4096 ] || die "not too long: ${#too}"
st=0; "$VDBPACK" pack cube.obj --radius 0.2 -o "$too" 2>run.err || st=$?
[ "$st" = 1 ] && [ "$(wc -l <run.err)" = 1 ] || die "too long: status $st: $(tail -c 200 run.err)"
grep -q '(File name too long)$' run.err || die "the reason was lost: $(tail -c 200 run.err)"
grep -q '\.\.\.' run.err || die "no '...' in the shortened line"
[ "$(wc -c <run.err)" -le 1100 ] || die "the line is $(wc -c <run.err) bytes"
ok "a ${#too}-byte -o: one line of $(wc -c <run.err) bytes ending '$(tail -c 60 run.err | tr -d '\n')'"
# a missing directory at depth: the reason survives too
miss=$(at_len e 4000 "")
miss="${miss%/}/no/such/dir/x.vdb"
st=0; "$VDBPACK" pack cube.obj --radius 0.2 -o "$miss" 2>run.err || st=$?
[ "$st" = 1 ] && grep -q 'does not exist$' run.err || die "missing directory: $st $(tail -c 200 run.err)"
ok "a missing directory in a 4000-byte path: '$(tail -c 60 run.err | tr -d '\n')'"
st=0; "$VDBPACK" info "$too" 2>run.err || st=$?
[ "$st" = 1 ] && [ "$(wc -l <run.err)" = 1 ] && grep -q 'File name too long)' run.err ||
  die "info of a too-long path: $st $(tail -c 200 run.err)"
ok "info of a ${#too}-byte path: one line ending '$(tail -c 40 run.err | tr -d '\n')'"
echo "PASS: sh_hostile_paths ($N cases)"

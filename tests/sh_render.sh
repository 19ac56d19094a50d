#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `vdbpack render` and `vdbpack pack --preview` end to end. PNGs are read
# back by a small independent reader (Python: zlib + struct, chunk CRCs
# checked, filters undone); EXR contents are checked by test_render_exr
# (OpenEXR's C++ API), here only that 1 and 2 threads give the same bytes.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$W"
fail=0
bad() { echo "FAIL: $*"; fail=1; }

png_py="$VP_SRC/tests/py/png_read.py"

"$VDBPACK" pack box:1,1,1 --radius 0.1 -o box.vdb -q --preview prev.png
[ -s box.vdb ] || bad "pack --preview: no box.vdb"
out=$(python3 "$png_py" prev.png </dev/null) || bad "pack --preview: unreadable PNG"
[ "$out" = "960 540" ] || bad "pack --preview: size '$out', expected the default 960x540"

# front view, 320x200: the corners are background, the centre is a particle
"$VDBPACK" render box.vdb -o front.png --size 320x200 --view front -q
out=$(printf '0 0\n319 0\n0 199\n319 199\n160 100\n' | python3 "$png_py" front.png)
echo "front.png: $(echo "$out" | tr '\n' '|')"
[ "$(echo "$out" | sed -n 1p)" = "320 200" ] || bad "front.png: size $(echo "$out" | sed -n 1p)"
for k in 2 3 4 5; do
  [ "$(echo "$out" | sed -n ${k}p | awk '{print $4}')" = 0 ] || bad "front.png: corner $k not background"
done
centre=$(echo "$out" | sed -n 6p)
[ "$(echo "$centre" | awk '{print $4}')" = 255 ] || bad "front.png: centre not covered ($centre)"
[ "$(echo "$centre" | awk '{print ($1 + $2 + $3 > 30)}')" = 1 ] || bad "front.png: centre is black ($centre)"

# the cut: a camera on the plane x = 0 sees everything with x <= 0 left of
# the centre column; without the cut, the right half is covered too
"$VDBPACK" render box.vdb -o nocut.png --size 200x200 --camera 0,0,4:0,0,0 -q
"$VDBPACK" render box.vdb -o cut.png --size 200x200 --camera 0,0,4:0,0,0 --cut x:0 -q
right() { python3 "$png_py" "$1" columns </dev/null | sed -n 2p | awk '{s = 0; for (i = 102; i <= NF; i++) s += $i; print s}'; }
left() { python3 "$png_py" "$1" columns </dev/null | sed -n 2p | awk '{s = 0; for (i = 1; i <= 99; i++) s += $i; print s}'; }
echo "covered pixels right of the centre: no cut $(right nocut.png), cut x:0 $(right cut.png); left: $(left nocut.png) / $(left cut.png)"
[ "$(right nocut.png)" -gt 1000 ] || bad "nocut.png: right half empty"
[ "$(right cut.png)" = 0 ] || bad "cut.png: particles beyond the cut plane are drawn"
[ "$(left cut.png)" -gt 1000 ] || bad "cut.png: left half empty"

# same bytes for 1 and 2 threads (EXR, random octahedra with orientations)
"$VDBPACK" pack sphere:1 --method rsa --shape octahedron --radius 0.1 --count 300 -o oct.vdb -q
"$VDBPACK" render oct.vdb -o t1.exr --size 300x200 --colour size --threads 1 -q
"$VDBPACK" render oct.vdb -o t2.exr --size 300x200 --colour size --threads 2 -q
cmp t1.exr t2.exr || bad "render: 1 and 2 threads give different EXR files"
[ "$(head -c 4 t1.exr | od -An -tx1 | tr -d ' ')" = 762f3101 ] || bad "t1.exr: not an OpenEXR file"

# no temporary left behind
left=$(find . -name '.*.tmp*')
[ -z "$left" ] || bad "temporary files left: $left"
[ $fail -eq 0 ] && echo "render CLI checks passed"
exit $fail

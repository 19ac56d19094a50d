#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `cmake --install` into a temporary prefix, then everything from that
# prefix alone, moved elsewhere first (so that nothing may point back into
# the build tree or the first prefix):
#  - the layout: bin/vdbpack, the library with its soname, the public
#    headers, lib/pkgconfig/vdbpack.pc, lib/cmake/vdbpack/*.cmake, the
#    Python module;
#  - the library exports exactly the functions the headers declare with
#    VP_API (and __assert_fail, see cmake/vdbpack.map);
#  - every public header compiles alone as strict C99 and as C++;
#  - a C program built through pkg-config and a C++ program built through
#    find_package(vdbpack) run: they pack, write and read back;
#  - the installed command-line tool works;
#  - the installed Python module loads the prefix's library, packs, and
#    runs the examples of docs/python.md.
set -euo pipefail
: "${VP_SRC:?}" "${VP_BUILD:?}" "${VP_CC:?}" "${VP_CXX:?}"
if [ "${VP_SHARED_LIB:-1}" != 1 ]; then echo "skip: static build"; exit 77; fi
# a sanitized library links only into sanitized programs: the consumers
# built here are plain ones
if [ "${VP_SANITIZED:-0}" = 1 ]; then echo "skip: sanitizer build"; exit 77; fi
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fail=0
die() { echo "FAIL: $*"; exit 1; }

cmake --install "$VP_BUILD" --prefix "$T/first" >/dev/null
mv "$T/first" "$T/p"
P=$T/p
libdir=
for d in lib lib64 lib/*; do
  if [ -z "$libdir" ] && [ -e "$P/$d/pkgconfig/vdbpack.pc" ]; then libdir=$d; fi
done
[ -n "$libdir" ] || die "no lib*/pkgconfig/vdbpack.pc under the prefix"

# --- layout
for f in bin/vdbpack include/vdbpack/vdbpack.h include/vdbpack/version.h include/vdbpack/rsa.h \
         "$libdir/pkgconfig/vdbpack.pc" "$libdir/cmake/vdbpack/vdbpackConfig.cmake" \
         "$libdir/cmake/vdbpack/vdbpackConfigVersion.cmake" "$libdir/cmake/vdbpack/vdbpackTargets.cmake"; do
  [ -e "$P/$f" ] || die "$f is not installed"
done
so=$(find "$P/$libdir" -maxdepth 1 -name "libvdbpack.so.*.*.*" | sort | sed -n 1p)
[ -n "$so" ] || die "no libvdbpack.so.X.Y.Z installed"
soname=$(readelf -d "$so" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[ -e "$P/$libdir/$soname" ] && [ -e "$P/$libdir/libvdbpack.so" ] ||
  die "soname link $soname or libvdbpack.so missing"
echo "ok: installed layout; library $(basename "$so"), soname $soname"
version=$(sed -n 's/#define VP_VERSION_STRING "\(.*\)"/\1/p' "$P/include/vdbpack/version.h")
[ -n "$version" ] || die "version.h has no VP_VERSION_STRING"

# --- exports against declarations
sed -n 's/.*VP_API[^(]*[ *]\(vp_[a-z0-9_]*\)(.*/\1/p' "$P"/include/vdbpack/*.h | sort -u > "$T/declared"
{ cat "$T/declared"; echo __assert_fail; } | sort -u > "$T/allowed"
nm -D --defined-only "$so" | awk '{print $3}' | sed 's/@.*//' | sort -u > "$T/exported"
extra=$(comm -13 "$T/allowed" "$T/exported" | tr '\n' ' ')
missing=$(comm -23 "$T/allowed" "$T/exported" | tr '\n' ' ')
[ -z "${extra// /}" ] || { echo "FAIL: exported but not declared with VP_API: $extra"; fail=1; }
[ -z "${missing// /}" ] || { echo "FAIL: declared with VP_API but not exported: $missing"; fail=1; }
echo "ok: $(wc -l < "$T/exported") exported symbols = $(wc -l < "$T/declared") VP_API declarations + __assert_fail"

# --- each public header alone, strict C99 and C++
for h in "$P"/include/vdbpack/*.h; do
  n=$(basename "$h")
  printf '#include <vdbpack/%s>\nint vp_header_probe;\n' "$n" > "$T/h.c"
  "$VP_CC" -std=c99 -pedantic -Werror -Wall -Wextra -fsyntax-only -I"$P/include" "$T/h.c" ||
    { echo "FAIL: $n does not compile alone as strict C99"; fail=1; }
  cp "$T/h.c" "$T/h.cpp"
  "$VP_CXX" -std=c++11 -pedantic -Werror -Wall -Wextra -fsyntax-only -I"$P/include" "$T/h.cpp" ||
    { echo "FAIL: $n does not compile alone as C++11"; fail=1; }
done
echo "ok: $(ls "$P"/include/vdbpack/*.h | wc -l) headers compile alone as C99 and C++11 (-pedantic -Werror)"

# --- C through pkg-config
export PKG_CONFIG_PATH="$P/$libdir/pkgconfig"
pkg-config --exact-version="$version" vdbpack || die "pkg-config: vdbpack is not version $version"
cflags=$(pkg-config --cflags vdbpack); libs=$(pkg-config --libs vdbpack)
case "$cflags $libs" in *"$VP_BUILD"*) die "vdbpack.pc points into the build tree";; esac
# shellcheck disable=SC2086
"$VP_CC" -std=c99 -Wall -Werror "$VP_SRC/tests/consumers/c/consumer.c" -o "$T/consumer_c" $cflags $libs -lm
LD_LIBRARY_PATH="$P/$libdir" "$T/consumer_c" "$T/c.vdb" "$T/c.csv" || die "the C consumer failed"
[ -s "$T/c.vdb" ] && [ -s "$T/c.csv" ] || die "the C consumer wrote no files"
if LD_LIBRARY_PATH="$P/$libdir" ldd "$T/consumer_c" | grep -q "$VP_BUILD"; then
  die "the C consumer loads vdbpack from the build tree"
fi

# --- C++ through find_package
cmake -S "$VP_SRC/tests/consumers/cpp" -B "$T/cppb" -G Ninja -DCMAKE_PREFIX_PATH="$P" \
  -DCMAKE_CXX_COMPILER="$VP_CXX" -DCMAKE_BUILD_TYPE=Release >"$T/cpp.log" 2>&1 ||
  { cat "$T/cpp.log"; die "find_package(vdbpack) failed"; }
cmake --build "$T/cppb" >>"$T/cpp.log" 2>&1 || { cat "$T/cpp.log"; die "the C++ consumer did not build"; }
grep -q "$P" "$T/cppb/CMakeCache.txt" || die "the C++ consumer did not find vdbpack under the prefix"
# the imported target carries the runtime path of the library (CMake's build RPATH)
"$T/cppb/consumer_cpp" "$VP_SRC/vdb_samples/peanut.obj" "$T/cpp.vdb" || die "the C++ consumer failed"

# --- the installed tool and the Python module
out=$("$P/bin/vdbpack" --version | head -n 1)
[ "$out" = "vdbpack $version" ] || die "installed vdbpack --version printed '$out'"
ldd "$P/bin/vdbpack" | grep libvdbpack | grep -q "$P/" || die "installed vdbpack does not load the installed library"
"$P/bin/vdbpack" pack box:1,1,1 --radius 0.2 -q -o "$T/t.vdb" || die "installed vdbpack pack failed"
echo "ok: installed vdbpack $version packs, with its library from the prefix"

# --- the Python module, from the prefix alone (the build tree's copy off
# PYTHONPATH, no VDBPACK_LIBRARY): it loads the prefix's library through its
# relative _libpath.py, packs, and the examples of docs/python.md run
PY=/usr/bin/python3
pydir=$(find "$P" -path "*/lib/python3*/dist-packages" -type d | sort | sed -n 1p)
[ -n "$pydir" ] && [ -f "$pydir/vdbpack/__init__.py" ] && [ -f "$pydir/vdbpack/_libpath.py" ] ||
  die "no lib/python3*/dist-packages/vdbpack (with _libpath.py) under the prefix"
if ! "$PY" -c 'import numpy' 2>/dev/null; then
  echo "skip: the Python module's checks ($PY has no numpy)"
  exit $fail
fi
out=$(cd "$T" && env -u VDBPACK_LIBRARY PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 "$PY" - "$P" "$version" <<'PYEOF'
import os, sys
import vdbpack
prefix, version = os.path.realpath(sys.argv[1]), sys.argv[2]
def under(path):
    return os.path.realpath(path).startswith(prefix + os.sep)
assert under(vdbpack.__file__), "vdbpack.__file__ %s is not under %s" % (vdbpack.__file__, prefix)
assert under(vdbpack.library_path()), "the library %s is not under %s" % (
    vdbpack.library_path(), prefix)
assert vdbpack.version() == version == vdbpack.__version__, (vdbpack.version(), version)
p = vdbpack.pack("box:1,1,1", method="rsa", radius=0.1, count=50)
assert len(p) == 50 and p.check("box:1,1,1").ok
p.write("py.vdb")
print("%s %d" % (os.path.realpath(vdbpack.library_path()), len(vdbpack.read("py.vdb"))))
PYEOF
) || die "the installed Python module failed"
echo "ok: installed Python module $version loads ${out% *} and packs"
examples=$(env -u VDBPACK_LIBRARY PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 VDBPACK_PREFIX="$P" \
  "$PY" "$VP_SRC/tests/python/doc_examples.py" "$VP_SRC/docs/python.md" "$VP_SRC/vdb_samples" \
  "$T/docs" 2>&1) || { echo "$examples"; die "the examples of docs/python.md failed from the prefix"; }
echo "${examples##*$'\n'} (from the prefix)"
exit $fail

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The build's layer rules (docs/design.md, "Layers") hold and can catch a
# breach:
#  1. src/core compiles with src/core/layer_core.h force-included, and with
#     it an include of OpenVDB, Assimp, libpng, OpenEXR or an upper layer's
#     internal header fails to compile, while the core's own headers and the
#     public API compile;
#  2. the core's and os layer's objects link alone, with nothing undefined,
#     against libm and threads (the build's vdbpack_core_link_check), and
#     the same link fails once an object calls into an upper layer.
set -euo pipefail
: "${VP_SRC:?}" "${VP_BUILD:?}" "${VP_CC:?}"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
flags=(-std=c11 -D_XOPEN_SOURCE=700 -DVP_LAYER_CORE=1 -include "$VP_SRC/src/core/layer_core.h"
       -I"$VP_SRC/include" -I"$VP_BUILD/include" -I"$VP_SRC/src" -fsyntax-only)
fail=0
probe() { # EXPECT(ok|fail) INCLUDE
  printf '#include %s\nint vp_probe_unused;\n' "$2" > "$T/probe.c"
  if "$VP_CC" "${flags[@]}" "$T/probe.c" 2>"$T/err"; then got=ok; else got=fail; fi
  if [ "$got" != "$1" ]; then
    echo "FAIL: core including $2: expected the compile to $1"; sed -n 1,5p "$T/err"; fail=1
  else
    why=$(grep -Eo 'poisoned "[A-Za-z_]+"|[a-z]+: No such file|src/core is C11' "$T/err" | head -n 1 || true)
    echo "ok: core including $2: $got${why:+ ($why)}"
  fi
}
for h in '<openvdb/openvdb.h>' '<assimp/cimport.h>' '<assimp/scene.h>' '<png.h>' \
         '<OpenEXR/openexr.h>' '"vdb/vdb_bridge.h"' '"mesh/mesh.h"' '"api/probe.h"' \
         '"io/io_internal.h"'; do
  probe fail "$h"
done
for h in '"vdbpack/vdbpack.h"' '"core/container.h"' '"core/rsa_top.h"' '"os/bigmem.h"' '<math.h>'; do
  probe ok "$h"
done
# the poison is what stops them, not a missing header: the same includes
# compile without the layer header
printf '#include <png.h>\n#include <assimp/cimport.h>\nint x;\n' > "$T/plain.c"
"$VP_CC" -std=c11 -fsyntax-only "$T/plain.c" ||
  { echo "FAIL: <png.h> and <assimp/cimport.h> do not compile even without the layer header"; fail=1; }

if [ "${VP_SANITIZED:-0}" = 1 ] || [ "${VP_SANITIZED:-}" = "ON" ] || [ "${VP_SANITIZED:-}" = "TRUE" ]; then
  echo "skip: link check (sanitizer build: the objects need the sanitizer runtime)"
else
  objs=("$VP_BUILD"/CMakeFiles/vdbpack_core.dir/src/core/*.o "$VP_BUILD"/CMakeFiles/vdbpack_os.dir/src/os/*.o)
  [ -e "${objs[0]}" ] || { echo "FAIL: no core objects under $VP_BUILD/CMakeFiles"; exit 1; }
  [ -f "$VP_BUILD/libvdbpack_core_link_check.so" ] ||
    { echo "FAIL: the build made no libvdbpack_core_link_check.so"; exit 1; }
  "$VP_CC" -shared -o "$T/core.so" "${objs[@]}" -Wl,--no-undefined -lm -lpthread ||
    { echo "FAIL: core + os do not link alone"; fail=1; }
  echo "ok: core + os (${#objs[@]} objects) link with nothing undefined against libm and threads"
  # a core object that calls the OpenVDB bridge and the mesh importer
  printf 'int vpv_init(void);\nint vp_probe_call(void) { return vpv_init(); }\n' > "$T/call.c"
  "$VP_CC" -fPIC -c "$T/call.c" -o "$T/call.o"
  if "$VP_CC" -shared -o "$T/bad.so" "${objs[@]}" "$T/call.o" -Wl,--no-undefined -lm -lpthread 2>"$T/lerr"; then
    echo "FAIL: a core calling vpv_init linked alone"; fail=1
  else
    echo "ok: a call into the OpenVDB bridge fails the link ($(grep -o 'undefined reference to .vpv_init.' "$T/lerr" | head -n 1))"
  fi
fi
exit $fail

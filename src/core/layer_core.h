/* SPDX-License-Identifier: Apache-2.0 */
/* Force-included (-include) in every compile of src/core by the build
 * (CMakeLists.txt): the core is plain C11 over libc, libm, threads and the
 * operating-system helpers of src/os. A name from each library it must not
 * use is poisoned, so that including that library's headers fails to
 * compile ("attempt to use poisoned ..."), whatever the include path; the
 * core's link check (vdbpack_core_link_check) catches calls. Test:
 * tests/sh_layers.sh. */
#ifndef VDBPACK_CORE_LAYER_CORE_H
#define VDBPACK_CORE_LAYER_CORE_H

#ifdef __cplusplus
#error "src/core is C11: C++ belongs in src/vdb"
#endif

/* OpenVDB (and its C++ namespace), Assimp, libpng, OpenEXR Core */
#pragma GCC poison openvdb aiScene aiImportFile png_struct_def png_create_read_struct
#pragma GCC poison exr_context_t
/* vdbpack's own upper layers: the OpenVDB bridge, the mesh importer, the
 * API's probes and the export formats' internals */
#pragma GCC poison vpv_init vp_mesh_load vp_probe_read vpio_open

#endif

/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: mesh loading. The first byte picks the format Assimp is
 * told to expect (mostly OBJ; PLY, STL, OFF), the rest is the file. The mesh
 * is read in-process (VP_FUZZING: no child process, so the sanitizers see
 * welding and the topology counts), its invariants are checked, and a closed
 * mesh is voxelized coarsely with OpenVDB, as `vdbpack pack` would. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "mesh/mesh.h"
#include "vdb/vdb_bridge.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size < 2 || size > 65536) return 0;
    static const char *hints[8] = {"obj", "obj", "obj", "obj", "obj", "ply", "stl", "off"};
    const char *hint = hints[data[0] & 7];
    vp_mesh *m = NULL;
    char err[1024];
    vp_result r = vp_mesh_load_memory(data + 1, size - 1, hint, &m, err, sizeof err);
    if (r != VP_OK) {
        if (m || !err[0]) __builtin_trap(); /* an error has a message and no mesh */
        return 0;
    }
    /* invariants of a loaded mesh */
    if (!m || m->ntris == 0 || m->nverts == 0 || m->nverts > m->nverts_raw) __builtin_trap();
    for (size_t i = 0; i < 3 * m->nverts; i++)
        if (!isfinite(m->verts[i])) __builtin_trap();
    for (size_t i = 0; i < 3 * m->ntris; i++)
        if (m->tris[i] >= m->nverts) __builtin_trap();
    double diag = 0;
    for (int k = 0; k < 3; k++) {
        if (m->bmin[k] > m->bmax[k]) __builtin_trap();
        diag += (m->bmax[k] - m->bmin[k]) * (m->bmax[k] - m->bmin[k]);
    }
    diag = sqrt(diag);
    if (!m->boundary_edges && !m->nonmanifold_edges && m->ntris <= 4096 && diag > 0 &&
        isfinite(diag)) {
        vpv_levelset *ls = NULL;
        int rc = vpv_levelset_from_mesh(m->verts, m->nverts, m->tris, m->ntris, diag / 12, 3, 3, 0,
                                        NULL, NULL, &ls, err, sizeof err);
        if (rc == VP_OK) vpv_levelset_destroy(ls);
    }
    vp_mesh_destroy(m);
    return 0;
}

/* SPDX-License-Identifier: Apache-2.0 */
/* See mesh_wire.h. */
#include "mesh/mesh_wire.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Fixed-size header the child sends first; arrays follow. */
typedef struct wire_header {
    int32_t result;
    uint32_t errlen;
    uint64_t nverts, nverts_raw, ntris, boundary, nonmanifold, zero_area, components;
    double signed_volume, bmin[3], bmax[3];
} wire_header;

int vp_mesh_wire_write(int fd, vp_result r, const char *err, const vp_mesh *m)
{
    wire_header h;
    memset(&h, 0, sizeof h);
    h.result = (int32_t)r;
    h.errlen = (uint32_t)strlen(err);
    if (r == VP_OK && m) {
        h.nverts = m->nverts;
        h.nverts_raw = m->nverts_raw;
        h.ntris = m->ntris;
        h.boundary = m->boundary_edges;
        h.nonmanifold = m->nonmanifold_edges;
        h.zero_area = m->zero_area_tris;
        h.components = m->components;
        h.signed_volume = m->signed_volume;
        memcpy(h.bmin, m->bmin, sizeof h.bmin);
        memcpy(h.bmax, m->bmax, sizeof h.bmax);
    }
    int bad = vp_subproc_write_all(fd, &h, sizeof h) || vp_subproc_write_all(fd, err, h.errlen);
    if (!bad && r == VP_OK && m)
        bad = vp_subproc_write_all(fd, m->verts, 3 * m->nverts * sizeof *m->verts) ||
              vp_subproc_write_all(fd, m->tris, 3 * m->ntris * sizeof *m->tris);
    return bad ? -1 : 0;
}

int vp_mesh_wire_read(int fd, vp_subproc_watch *w, const char *name, vp_result *res, vp_mesh **out,
                      char *err, size_t errlen)
{
    *res = VP_OK;
    *out = NULL;
    vp_mesh *m = NULL;
    wire_header h;
    int rr = vp_subproc_read_all(fd, &h, sizeof h, w);
    if (rr == 0) {
        char msg[512];
        size_t el = h.errlen < sizeof msg ? h.errlen : sizeof msg - 1;
        rr = vp_subproc_read_all(fd, msg, el, w);
        msg[rr == 0 ? el : 0] = '\0';
        if (rr == 0 && h.result != VP_OK) {
            *res = (vp_result)h.result;
            snprintf(err, errlen, "%s", msg);
        } else if (rr == 0) {
            m = calloc(1, sizeof *m);
            if (m && h.nverts <= SIZE_MAX / 24 && h.ntris <= SIZE_MAX / 12) {
                m->verts = malloc(3 * h.nverts * sizeof *m->verts + 1);
                m->tris = malloc(3 * h.ntris * sizeof *m->tris + 1);
            }
            if (!m || !m->verts || !m->tris) {
                *res = VP_ERR_OUT_OF_MEMORY;
                snprintf(err, errlen, "%s: out of memory", name);
            } else {
                m->nverts = h.nverts;
                m->nverts_raw = h.nverts_raw;
                m->ntris = h.ntris;
                m->boundary_edges = h.boundary;
                m->nonmanifold_edges = h.nonmanifold;
                m->zero_area_tris = h.zero_area;
                m->components = h.components;
                m->signed_volume = h.signed_volume;
                memcpy(m->bmin, h.bmin, sizeof h.bmin);
                memcpy(m->bmax, h.bmax, sizeof h.bmax);
                rr = vp_subproc_read_all(fd, m->verts, 3 * h.nverts * sizeof *m->verts, w);
                if (rr == 0)
                    rr = vp_subproc_read_all(fd, m->tris, 3 * h.ntris * sizeof *m->tris, w);
            }
        }
    }
    if (rr != 0 || *res != VP_OK) {
        vp_mesh_destroy(m);
        m = NULL;
    }
    *out = m;
    return rr;
}

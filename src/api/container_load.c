/* SPDX-License-Identifier: Apache-2.0 */
/* Loading containers: meshes (through Assimp) voxelized by OpenVDB, and
 * level sets read from .vdb files. Both end up as a vp_container whose
 * distance is a trilinear sample of the level set. */
#include "api/atomic.h"
#include "api/probe.h"
#include "core/container.h"
#include "core/context.h"
#include "core/winding.h"
#include "mesh/mesh.h"
#include "os/input.h"
#include "os/subproc.h"
#include "vdb/vdb_bridge.h"
#include "vdb/vdb_field.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void vp_container_params_init(vp_container_params *p) {
    if (p) memset(p, 0, sizeof *p);
}

static double ls_distance(void *user, const double p[3]) { return vpv_levelset_sample(user, p); }
static void ls_gradient(void *user, const double p[3], double g[3]) {
    vpv_levelset_gradient(user, p, g);
}
static void ls_destroy(void *user) { vpv_levelset_destroy(user); }

/* The coarse depth map (core/depth_map.h) of a level-set container. Capped
 * at 64M blocks (256 MB; a container that large holds billions of
 * particles, and without the map the packer is only slower). */
static int ls_depth_map(const vp_container *c, vp_depth_map *out) {
    memset(out, 0, sizeof *out);
    vpv_blocks b;
    char err[256];
    if (vpv_levelset_blocks(c->levelset, (size_t)1 << 26, &b, err, sizeof err) != VP_OK) return -1;
    return vp_depth_map_build(out, b.origin, b.block, b.voxel, b.dims, b.value,
                              c->info.interior_band, b.background);
}

/* The box of the level set's inside (fields must cover it). */
static int ls_inside_box(const vp_container *c, double lo[3], double hi[3]) {
    return vpv_levelset_inside_box(c->levelset, lo, hi);
}

/* True when the file starts with OpenVDB's magic number or ends in .vdb. */
static int looks_like_vdb(const char *path) {
    size_t n = strlen(path);
    if (n >= 4) {
        const char *e = path + n - 4;
        if (e[0] == '.' && tolower((unsigned char)e[1]) == 'v' &&
            tolower((unsigned char)e[2]) == 'd' && tolower((unsigned char)e[3]) == 'b')
            return 1;
    }
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    unsigned char m[4] = {0};
    size_t got = fread(m, 1, 4, f);
    fclose(f);
    return got == 4 && m[0] == 0x20 && m[1] == 0x42 && m[2] == 0x44 && m[3] == 0x56;
}

/* The sanity checks of a level set: VP_OK, or the failure (ls is then
 * destroyed). */
static vp_result check_levelset(vp_context *ctx, const char *path, vpv_levelset *ls,
                                const vpv_levelset_info *li, vp_container_kind kind) {
    if (li->leaked) {
        vpv_levelset_destroy(ls);
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER,
                       "%s: the inside of the level set reaches its bounding box (it leaks: "
                       "the surface is probably open), refusing to pack it",
                       vp_path_base(path));
    }
    if (li->inside_voxels == 0 || !(li->volume > 0)) {
        vpv_levelset_destroy(ls);
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER,
                       "%s: the level set has an empty inside (no voxel below zero%s)",
                       vp_path_base(path),
                       kind == VP_CONTAINER_MESH ? "; is the mesh thinner than a voxel? "
                                                   "try a smaller --voxel-size"
                                                 : "");
    }
    return VP_OK;
}

/* Wraps a level set into a container after the sanity checks. */
static vp_result finish_levelset(vp_context *ctx, const char *path, vpv_levelset *ls,
                                 vp_container_info *info, vp_container **out) {
    vpv_levelset_info li;
    vpv_levelset_get_info(ls, &li);
    vp_result bad = check_levelset(ctx, path, ls, &li, info->kind);
    if (bad != VP_OK) return bad;
    memcpy(info->bmin, li.bmin, sizeof info->bmin);
    memcpy(info->bmax, li.bmax, sizeof info->bmax);
    info->volume = li.volume;
    info->voxel_size = li.voxel_size;
    info->interior_band = li.interior_band;
    info->active_voxels = li.active_voxels;
    snprintf(info->grid_name, sizeof info->grid_name, "%s", li.name);
    static const vp_container_ops ops = {ls_distance, ls_gradient, ls_destroy};
    vp_result r = vp_container_wrap(ctx, &ops, ls, info, out);
    if (r != VP_OK) {
        vpv_levelset_destroy(ls);
        return r;
    }
    (*out)->levelset = ls;
    (*out)->depth_map = ls_depth_map;
    (*out)->inside_box = ls_inside_box;
    return VP_OK;
}

/* Radius that gives about particle_count particles in volume vol. */
static double estimate_radius(double vol, const vp_container_params *pp) {
    double space = pp->space_per_particle > 0 ? pp->space_per_particle
                                              : 4.18879020478639 / 0.74048; /* FCC spheres */
    return cbrt(vol / ((double)pp->particle_count * space));
}

/* Polled by OpenVDB while it voxelizes (serialized by the bridge). */
static int keep_going(void *ctx) {
    return vp_report_progress((vp_context *)ctx, 0.5, "voxelizing");
}

/* Memory a particle needs at the least: below every packer's own estimate
 * (lattice 80, RSA 64 bytes), so the loaders' early refusal (before
 * voxelizing or widening a band) never refuses what would fit. */
#define MIN_BYTES_PER_PARTICLE 48.0

/* Particles a request will make (0 when unknown): the count, or the
 * container's volume over the space one particle of that radius takes. */
static double estimate_particles(double vol, double radius, const vp_container_params *pp) {
    if (pp->particle_count > 0) return (double)pp->particle_count;
    if (radius > 0 && pp->space_per_particle > 0)
        return vol / (pp->space_per_particle * radius * radius * radius);
    return 0;
}

static double mesh_area(const vp_mesh *m) {
    double a = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p0 = m->verts + 3 * m->tris[3 * t], *p1 = m->verts + 3 * m->tris[3 * t + 1],
                     *p2 = m->verts + 3 * m->tris[3 * t + 2];
        double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        a += 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    }
    return a;
}

const char *vp_inside_name(vp_inside_mode m) {
    switch (m) {
    case VP_INSIDE_AUTO: return "auto";
    case VP_INSIDE_CLOSED: return "closed";
    case VP_INSIDE_WINDING: return "winding";
    }
    return NULL;
}

int vp_inside_parse(const char *name, vp_inside_mode *out) {
    static const vp_inside_mode all[] = {VP_INSIDE_AUTO, VP_INSIDE_CLOSED, VP_INSIDE_WINDING};
    for (size_t i = 0; name && i < sizeof all / sizeof all[0]; i++)
        if (!strcmp(name, vp_inside_name(all[i]))) {
            if (out) *out = all[i];
            return 0;
        }
    return -1;
}

/* The winding numbers for the voxelizer (vpv_winding_ops): a tree built
 * once, read by every thread. */
static void winding_points(void *user, const double *pts, size_t n, double *w) {
    vp_winding_batch((const vp_winding *)user, pts, n, w);
}
static void winding_block(void *user, const double lo[3], double h, double *w) {
    vp_winding_block((const vp_winding *)user, lo, h, w);
}

/* The volume where the winding number is at least 0.5, from WINDING_SAMPLES^3
 * samples at the centres of a regular grid over the mesh's bounding box
 * (the midpoint rule), grown by a tenth of its size each way for an open
 * mesh, whose inside may reach past it (below an open sheet); evaluated
 * 8^3 at a time (vp_winding_block). Its error is well under 1 % of the
 * inside's volume for the meshes of the tests. */
#define WINDING_SAMPLES 64
static double winding_volume(const vp_winding *w, const vp_mesh *m) {
    double ext[3], lo[3], cell[3], box = 1;
    double grow = m->boundary_edges ? 0.1 : 0.0;
    for (int k = 0; k < 3; k++) {
        ext[k] = (m->bmax[k] - m->bmin[k]) * (1 + 2 * grow);
        lo[k] = m->bmin[k] - grow * (m->bmax[k] - m->bmin[k]);
        cell[k] = ext[k] / WINDING_SAMPLES;
        box *= ext[k];
    }
    if (!(box > 0)) return 0;
    /* the blocks want one spacing: the grid's cells are cubes of the
     * largest side, fewer along the shorter axes; cells of centre q count
     * h^3 each, those past the box too (they hold no inside) */
    double h = fmax(cell[0], fmax(cell[1], cell[2]));
    size_t inside = 0;
    double out[512];
    for (double bz = lo[2] + 0.5 * h; bz < lo[2] + ext[2]; bz += 8 * h)
        for (double by = lo[1] + 0.5 * h; by < lo[1] + ext[1]; by += 8 * h)
            for (double bx = lo[0] + 0.5 * h; bx < lo[0] + ext[0]; bx += 8 * h) {
                double b[3] = {bx, by, bz};
                vp_winding_block(w, b, h, out);
                for (int i = 0; i < 512; i++) inside += out[i] >= 0.5;
            }
    return (double)inside * h * h * h;
}

/* The voxel size of a mesh container, and why (info->voxel_reason): the
 * user's, half the particle radius, or 1/200 of the bounding box's
 * diagonal, whichever is smallest of the last two. */
static double choose_voxel(const vp_container_params *pp, double radius, double diag,
                           vp_container_info *info) {
    if (pp->voxel_size > 0) {
        snprintf(info->voxel_reason, sizeof info->voxel_reason, "set by --voxel-size");
        return pp->voxel_size;
    }
    if (radius > 0 && radius / 2 < diag / 200) {
        snprintf(info->voxel_reason, sizeof info->voxel_reason,
                 "half the particle radius %g, so the wall is resolved at the particle scale",
                 radius);
        return radius / 2;
    }
    snprintf(info->voxel_reason, sizeof info->voxel_reason,
             "1/200 of the mesh's bounding-box diagonal %g, to resolve the mesh (particles "
             "are larger than that)",
             diag);
    return diag / 200;
}

/* The refusals of VP_INSIDE_CLOSED: an open, non-manifold or inconsistently
 * oriented mesh. VP_OK when the mesh may go on. */
static vp_result check_closed(vp_context *ctx, const char *name, const vp_mesh *m,
                              const vp_container_params *pp, int from_memory) {
    if (pp->inside != VP_INSIDE_CLOSED) return VP_OK;
    const char *other = from_memory ? "set inside to VP_INSIDE_AUTO or VP_INSIDE_WINDING"
                                    : "use --inside auto or winding";
    if (m->boundary_edges || m->nonmanifold_edges)
        return vp_fail(ctx, VP_ERR_OPEN_MESH,
                       "%s: the mesh is not closed: %zu boundary edges and %zu non-manifold edges "
                       "(after welding %zu vertices into %zu); fix it or %s to take its inside "
                       "by winding number",
                       name, m->boundary_edges, m->nonmanifold_edges, m->nverts_raw, m->nverts,
                       other);
    if (m->inconsistent_edges)
        return vp_fail(ctx, VP_ERR_OPEN_MESH,
                       "%s: the mesh is closed but not consistently oriented (%zu edges where "
                       "both triangles run the same way); fix it or %s",
                       name, m->inconsistent_edges, other);
    return VP_OK;
}

/* A welded mesh (owned: destroyed here) into a level-set container, in
 * named steps: the inside mode's refusals; the mesh readied for its inside
 * (mesh_inside.c); the route (OpenVDB's closed-surface sign, or the
 * winding number's) and an independent estimate of the inside's volume;
 * the voxel size; the memory guard; the voxelization; the level set's
 * checks; the estimate against the level set's volume. name names it in
 * messages; from_memory: hints name the parameter rather than the
 * command-line option. */
static vp_result voxelize_mesh(vp_context *ctx, const char *name, vp_mesh *m,
                               const vp_container_params *pp, int from_memory, vp_container **out) {
    char err[1024];
    vp_result r = check_closed(ctx, name, m, pp, from_memory);
    if (r != VP_OK) {
        vp_mesh_destroy(m);
        return r;
    }
    vp_container_info info;
    memset(&info, 0, sizeof info);
    info.kind = VP_CONTAINER_MESH;
    info.mesh_vertices = m->nverts;
    info.mesh_vertices_raw = m->nverts_raw;
    info.boundary_edges = m->boundary_edges;
    info.nonmanifold_edges = m->nonmanifold_edges;
    info.inconsistent_edges = m->inconsistent_edges;
    info.mesh_volume = fabs(m->signed_volume);
    int closed = !m->boundary_edges && !m->nonmanifold_edges;
    int consistent = !m->inconsistent_edges;

    vp_mesh_repair rep;
    if (vp_mesh_prepare_winding(m, &rep) != VP_OK) {
        vp_mesh_destroy(m);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    info.mesh_triangles = m->ntris;
    info.mesh_pieces = rep.pieces;
    int winding = pp->inside == VP_INSIDE_WINDING || !closed || !consistent || rep.pieces_overlap ||
                  m->ntris == 0;
    info.inside = winding ? VP_INSIDE_WINDING : VP_INSIDE_CLOSED;
    if (winding) {
        info.duplicate_triangles = rep.duplicate_triangles;
        info.opposite_triangles = rep.opposite_triangles;
        info.reoriented_triangles = rep.reoriented_triangles;
        info.turned_pieces = rep.turned_pieces;
        info.cavities = rep.cavities;
    }

    double ext[3], diag = 0, bvol = 1;
    for (int i = 0; i < 3; i++) {
        ext[i] = m->bmax[i] - m->bmin[i];
        diag += ext[i] * ext[i];
        bvol *= ext[i];
    }
    diag = sqrt(diag);
    /* the estimate: the signed volume where it is exact (closed pieces
     * that do not overlap, turned the right way out), else the winding
     * number's */
    vp_winding *w = NULL;
    if (m->ntris && (winding || !closed || rep.pieces_overlap)) {
        uint8_t *rim = vp_mesh_rim_triangles(m);
        w = rim ? vp_winding_build(m->verts, m->nverts, m->tris, m->ntris, rim) : NULL;
        free(rim);
        if (!w) {
            vp_mesh_destroy(m);
            return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
        }
    }
    if (closed && !rep.pieces_overlap && m->ntris) {
        info.volume_estimate_kind = VP_ESTIMATE_MESH_VOLUME;
        info.volume_estimate = fabs(m->signed_volume);
    } else if (w) {
        info.volume_estimate_kind = VP_ESTIMATE_WINDING;
        info.volume_estimate = winding_volume(w, m);
    }
    double vol = info.volume_estimate;
    if (!(vol > 1e-9 * (bvol > 0 ? bvol : diag * diag * diag))) {
        vp_winding_destroy(w);
        vp_mesh_destroy(m);
        if (info.volume_estimate_kind == VP_ESTIMATE_WINDING)
            return vp_fail(ctx, VP_ERR_BAD_CONTAINER,
                           "%s: the mesh has no inside: its winding number is below 0.5 "
                           "everywhere (a single open surface, such as a plane or a bowl, "
                           "encloses nothing)",
                           name);
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER,
                       "%s: the mesh encloses no volume (it is flat or degenerate)", name);
    }

    double radius = pp->particle_radius;
    if (!(radius > 0) && pp->particle_count > 0) radius = estimate_radius(vol, pp);
    double voxel = choose_voxel(pp, radius, diag, &info);
    if (!(voxel > 0) || !isfinite(voxel)) {
        vp_winding_destroy(w);
        vp_mesh_destroy(m);
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: cannot choose a voxel size", name);
    }
    double extra = pp->extra_depth;
    double in_band = radius > 0 ? (pp->narrow_band ? ceil((1.02 * radius + extra) / voxel + 0.9)
                                                   : ceil((1.25 * radius + extra) / voxel) + 2)
                                : ceil(extra / voxel) + 3;
    if (in_band < 3) in_band = 3;
    double ex_band = 3;
    /* memory guard: narrow-band voxels ~ area / voxel^2 * band width, at
     * about 4 bytes each plus tree overhead (x3); the winding route's band
     * is as wide outside as in */
    double voxels =
        mesh_area(m) / (voxel * voxel) * (winding ? 2 * fmax(in_band, ex_band) : in_band + ex_band);
    double bytes = voxels * 12.0;
    /* the particles come after the level set: a request too large for
     * memory is refused now, not after minutes of voxelizing */
    double particles = estimate_particles(vol, radius, pp);
    bytes += particles * MIN_BYTES_PER_PARTICLE;
    uint64_t limit = vp_memory_limit(ctx);
    if (bytes > (double)limit || ext[0] / voxel > 1e6 || ext[1] / voxel > 1e6 ||
        ext[2] / voxel > 1e6) {
        char a[32], b[32], c[64] = "";
        vp_format_bytes(bytes, a, sizeof a);
        vp_format_bytes((double)limit, b, sizeof b);
        if (particles >= 1) snprintf(c, sizeof c, " and about %.3g particles", particles);
        vp_winding_destroy(w);
        vp_mesh_destroy(m);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "%s: voxelizing at voxel size %g%s need an estimated %s of memory, more "
                       "than the limit of %s; use a larger --voxel-size or fewer, larger particles",
                       name, voxel, c, a, b);
    }
    if (!vp_report_progress(ctx, 0.0, "voxelizing")) {
        vp_winding_destroy(w);
        vp_mesh_destroy(m);
        return vp_fail(ctx, VP_ERR_CANCELLED, "cancelled");
    }
    vpv_levelset *ls = NULL;
    double *holes = NULL;
    size_t nholes = 0;
    if (winding && vp_mesh_hole_boxes(m, &holes, &nholes) != VP_OK) {
        vp_winding_destroy(w);
        vp_mesh_destroy(m);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    vpv_winding_ops wops = {w, winding_points, winding_block};
    int rc = winding
                 ? vpv_levelset_from_mesh_winding(m->verts, m->nverts, m->tris, m->ntris, voxel,
                                                  ex_band, in_band, &wops, holes, nholes,
                                                  keep_going, ctx, &ls, err, sizeof err)
                 : vpv_levelset_from_mesh(m->verts, m->nverts, m->tris, m->ntris, voxel, ex_band,
                                          in_band, 0, keep_going, ctx, &ls, err, sizeof err);
    free(holes);
    vp_winding_destroy(w);
    vp_mesh_destroy(m);
    if (rc != VP_OK) return vp_fail(ctx, (vp_result)rc, "%s", err);
    r = finish_levelset(ctx, name, ls, &info, out);
    if (r != VP_OK) {
        if (r == VP_ERR_BAD_CONTAINER && winding && strstr(vp_context_message(ctx), "empty inside"))
            return vp_fail(ctx, r,
                           "%s: the mesh has no inside at voxel size %g: where its winding number "
                           "is at least 0.5 is thinner than a voxel (try a smaller --voxel-size)",
                           name, voxel);
        return r;
    }
    (*out)->info.volume_mismatch = fabs((*out)->info.volume - vol) > 0.05 * vol;
    return VP_OK;
}

static vp_result load_mesh(vp_context *ctx, const char *path, const vp_container_params *pp,
                           vp_container **out) {
    char err[1024];
    vp_mesh *m = NULL;
    vp_subproc_guard guard; /* cancel and --max-memory reach the reader */
    vp_context_child_guard(ctx, &guard);
    vp_result r = vp_mesh_load_guarded(path, &guard, &m, err, sizeof err);
    if (r != VP_OK) return vp_fail(ctx, r, "%s", err);
    return voxelize_mesh(ctx, vp_path_base(path), m, pp, 0, out);
}

typedef struct probe_ls_arg {
    const char *path, *grid;
    const double *iso; /* a fog grid's iso value, or NULL: a level set */
} probe_ls_arg;

/* The level set of a .vdb, or its fog grid's at the iso value. */
static int read_levelset(const probe_ls_arg *a, vpv_levelset **ls, char *err, size_t errlen) {
    return a->iso ? vpv_levelset_read_fog(a->path, a->grid, *a->iso, ls, err, errlen)
                  : vpv_levelset_read(a->path, a->grid, ls, err, errlen);
}

static int probe_levelset(const void *arg, char *err, size_t errlen) {
    vpv_levelset *ls = NULL;
    int rc = read_levelset(arg, &ls, err, errlen);
    vpv_levelset_destroy(ls);
    return rc;
}

static vp_result load_vdb(vp_context *ctx, const char *path, const vp_container_params *pp,
                          vp_container **out) {
    probe_ls_arg pa = {path, pp->grid_name, pp->has_iso ? &pp->iso : NULL};
    vp_result pr = vp_probe_read(ctx, path, probe_levelset, &pa);
    if (pr != VP_OK) return pr;
    char err[1024];
    vpv_levelset *ls = NULL;
    int rc = read_levelset(&pa, &ls, err, sizeof err);
    if (rc != VP_OK) return vp_fail(ctx, (vp_result)rc, "%s", err);
    vp_container_info info;
    memset(&info, 0, sizeof info);
    info.kind = VP_CONTAINER_LEVEL_SET;
    if (pp->has_iso) {
        info.iso = pp->iso;
        snprintf(info.voxel_reason, sizeof info.voxel_reason,
                 "the fog grid's in the file, inside where it is at least %g", pp->iso);
    } else {
        snprintf(info.voxel_reason, sizeof info.voxel_reason, "from the level set in the file");
    }
    vpv_levelset_info li;
    vpv_levelset_get_info(ls, &li);
    /* before widening the band: the rebuild of a leaking level set can
     * voxelize the faces of a huge inside tile (a corrupt file took 10 GB) */
    vp_result bad = check_levelset(ctx, path, ls, &li, info.kind);
    if (bad != VP_OK) return bad;
    double radius = pp->particle_radius;
    if (!(radius > 0) && pp->particle_count > 0 && li.volume > 0)
        radius = estimate_radius(li.volume, pp);
    double particles = estimate_particles(li.volume, radius, pp);
    double bytes = particles * MIN_BYTES_PER_PARTICLE;
    uint64_t limit = vp_memory_limit(ctx);
    if (bytes > (double)limit) {
        char a[32], b[32];
        vp_format_bytes(bytes, a, sizeof a);
        vp_format_bytes((double)limit, b, sizeof b);
        vpv_levelset_destroy(ls);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "%s: about %.3g particles need an estimated %s of memory, more than the "
                       "limit of %s; use fewer, larger particles",
                       vp_path_base(path), particles, a, b);
    }
    if (radius > 0 || pp->extra_depth > 0) {
        double depth = (pp->narrow_band ? 1.02 * radius + 0.9 * li.voxel_size
                                        : 1.25 * radius + li.voxel_size) +
                       pp->extra_depth;
        /* the rebuild that widens the band, at 12 bytes a voxel as for a
         * mesh: a tile of 4096^3 voxels meeting the outside (a hand-made or
         * corrupt file) made it run for minutes in 10 GB */
        double v = li.voxel_size;
        double voxels = vpv_levelset_rebuild_voxels(ls, depth, li.volume / (v * v * v));
        if (voxels * 12.0 + bytes > (double)limit) {
            char a[32], b[32];
            vp_format_bytes(voxels * 12.0 + bytes, a, sizeof a);
            vp_format_bytes((double)limit, b, sizeof b);
            vpv_levelset_destroy(ls);
            return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                           "%s: widening the level set's interior band to %g for particles of "
                           "radius %g needs an estimated %s of memory, more than the limit "
                           "of %s; use smaller particles",
                           vp_path_base(path), depth, radius, a, b);
        }
        rc = vpv_levelset_ensure_interior(ls, depth, err, sizeof err);
        if (rc != VP_OK) {
            vpv_levelset_destroy(ls);
            return vp_fail(ctx, (vp_result)rc, "%s", err);
        }
    }
    return finish_levelset(ctx, path, ls, &info, out);
}

/* The sizes of params: VP_OK, or the failure. */
static vp_result check_params(vp_context *ctx, const vp_container_params *params) {
    if (params->voxel_size < 0 || !isfinite(params->voxel_size) || params->particle_radius < 0 ||
        !isfinite(params->particle_radius) || params->space_per_particle < 0 ||
        !isfinite(params->space_per_particle) || !(params->extra_depth >= 0) ||
        !isfinite(params->extra_depth))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "the voxel size and particle radius must be positive finite numbers");
    return VP_OK;
}

vp_result vp_container_from_mesh(vp_context *ctx, const double *vertices, size_t vertex_count,
                                 const uint32_t *triangles, size_t triangle_count,
                                 const vp_container_params *params, vp_container **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "container: out is NULL");
    *out = NULL;
    vp_container_params def;
    if (!params) {
        vp_container_params_init(&def);
        params = &def;
    }
    vp_result r = check_params(ctx, params);
    if (r != VP_OK) return r;
    const char *name = params->name && *params->name ? params->name : "mesh";
    char err[1024];
    vp_mesh *m = NULL;
    r = vp_mesh_from_arrays(vertices, vertex_count, triangles, triangle_count, name, &m, err,
                            sizeof err);
    if (r != VP_OK) return vp_fail(ctx, r, "%s", err);
    vpv_init();
    return voxelize_mesh(ctx, name, m, params, 1, out);
}

vp_result vp_container_load(vp_context *ctx, const char *path, const vp_container_params *params,
                            vp_container **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "container: out is NULL");
    *out = NULL;
    if (!path || !*path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no container file given");
    vp_container_params def;
    if (!params) {
        vp_container_params_init(&def);
        params = &def;
    }
    vp_result pr = check_params(ctx, params);
    if (pr != VP_OK) return pr;
    /* a FIFO or a device would block the readers: one line at once */
    char msg[1024];
    if (vp_os_check_input(path, msg, sizeof msg) != 0) return vp_fail(ctx, VP_ERR_IO, "%s", msg);
    vpv_init();
    if (!looks_like_vdb(path) && params->has_iso)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: --iso is for a fog or density grid in a .vdb, not a mesh",
                       vp_path_base(path));
    return looks_like_vdb(path) ? load_vdb(ctx, path, params, out)
                                : load_mesh(ctx, path, params, out);
}

vp_result vp_container_save(vp_context *ctx, const vp_container *c, const char *path) {
    if (!c || !c->levelset)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "only a mesh or level-set container can be saved as a level set");
    vp_atomic a;
    vp_result r = vp_atomic_begin(ctx, path, &a);
    if (r != VP_OK) return r;
    char err[1024];
    vp_meta meta[1] = {{"creator", VP_META_STRING, "vdbpack " VP_VERSION_STRING, 0, 0}};
    int rc = vpv_levelset_write(c->levelset, a.tmp_path, meta, 1, err, sizeof err);
    if (rc != VP_OK) {
        vp_atomic_abort(&a);
        return vp_fail(ctx, (vp_result)rc, "%s: %s", path, err);
    }
    return vp_atomic_commit(ctx, &a);
}

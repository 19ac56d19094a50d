/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack pack`: the job as a list of named steps (the shapes, the
 * container, the checks that need it, the packer, the outputs, the
 * report), with the progress bar; options in pack_options.c, the report in
 * pack_report.c. */
#include "vdbpack/vdbpack.h"

#include <float.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/pack_internal.h"

static void container_params(const pack_opts *o, vp_container_params *cp);

typedef struct progress {
    const vp_context *ctx; /* for the stage's counts */
    double start;
    int shown;
    int bar;             /* draw a bar (stderr is a terminal) */
    int lines;           /* --progress: one line per stage, no bar */
    double last;         /* when the bar was last drawn (at most 10 times a second) */
    const char *phase;   /* the run's phase ("packing") */
    double base, weight; /* the phase spans [base, base + weight] of the bar */
    double local;        /* the phase's largest fraction so far */
    double done;         /* the bar's fraction: never decreases */
    char stage[48];      /* the last stage printed by --progress */
} progress;

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One --progress line, when the stage changes. */
static void progress_line(progress *p, const char *stage, double t) {
    char name[48];
    snprintf(name, sizeof name, "%s%s%s", p->phase, stage && *stage ? "/" : "", stage ? stage : "");
    if (!strcmp(name, p->stage)) return;
    snprintf(p->stage, sizeof p->stage, "%s", name);
    fprintf(stderr, "progress: %s %.3f %.2f\n", name, p->done, t - p->start);
    fflush(stderr);
}

/* The next phase of the run and its share of the bar (the shares of the
 * phases left are scaled to what remains). */
static void progress_phase(progress *p, const char *phase, double weight) {
    p->base = p->done;
    p->weight = weight * (1.0 - p->done);
    p->local = 0.0;
    p->phase = phase;
    if (p->lines) progress_line(p, NULL, now());
}

static int on_progress(void *user, double fraction, const char *stage) {
    progress *p = user;
    if (vp_cli_interrupted()) return 0; /* SIGINT/SIGTERM: cancel */
    if (!p->bar && !p->lines) return 1;
    if (fraction > p->local && fraction <= 1.0) p->local = fraction;
    double f = p->base + p->weight * p->local;
    if (f > p->done) p->done = f;
    double t = now();
    if (p->lines) {
        progress_line(p, stage, t);
        return 1;
    }
    if (t - p->start < 0.5 || t - p->last < 0.1) return 1;
    p->last = t;
    int w = 30, filled = (int)(p->done * w + 0.5);
    if (filled > w) filled = w;
    if (filled < 0) filled = 0;
    double el = t - p->start;
    char left[32] = "", counts[48] = "";
    if (p->done >= 0.02) snprintf(left, sizeof left, ", %.0f s left", el * (1 - p->done) / p->done);
    uint64_t cd = 0, ct = 0;
    if (vp_context_progress_counts(p->ctx, &cd, &ct)) {
        if (ct)
            snprintf(counts, sizeof counts, " %llu of %llu", (unsigned long long)cd,
                     (unsigned long long)ct);
        else snprintf(counts, sizeof counts, " %llu placed", (unsigned long long)cd);
    }
    char mid[64];
    snprintf(mid, sizeof mid, "%s%s", stage ? stage : "", counts);
    fprintf(stderr, "\r[%.*s%*s] %3d%% %s: %-26.26s %.0f s%-14s", filled,
            "##############################", w - filled, "", (int)(p->done * 100 + 0.5), p->phase,
            mid, el, left);
    fflush(stderr);
    p->shown = 1;
    return 1;
}

/* The end of a run that succeeded: the last --progress line. */
static void progress_end(progress *p) {
    if (!p->lines) return;
    p->done = 1.0;
    p->phase = "done";
    progress_line(p, NULL, now());
}

/* A library call failed: one line, or the interruption's line when a signal
 * made it stop. */
static int lib_error(vp_context *ctx) {
    if (vp_cli_interrupted()) return vp_cli_interrupted_exit();
    return vp_cli_die(1, "%s", vp_context_message(ctx));
}

/* --- option parsing -------------------------------------------------------- */

/* The --pass shape=FILE meshes (after --shape's, whose mesh a pass naming
 * the same file shares): each file read once. 0, or the exit status after
 * one line. */
static int load_pass_shapes(vp_context *ctx, pack_opts *o) {
    for (int i = 0; i < o->npasses; i++) {
        const char *file = o->pass_mesh_file[i];
        if (!file[0]) continue;
        const vp_mesh_shape *m = NULL;
        if (o->shape_file && !strcmp(o->shape_file, file)) m = o->mesh;
        for (int k = 0; k < i && !m; k++)
            if (!strcmp(o->pass_mesh_file[k], file)) m = o->passes[k].shape.mesh;
        if (!m) {
            struct stat st;
            if (stat(file, &st) != 0)
                return vp_cli_die(2,
                                  "pack: --pass %d: shape '%s' is no shape name (sphere, a "
                                  "platonic or Archimedean solid, superball:P) and no file",
                                  i + 1, file);
            if (vp_mesh_shape_load(ctx, file, &o->pass_mesh[i]) != VP_OK)
                return vp_cli_die(1, "pack: --pass %d: %s", i + 1, vp_context_message(ctx));
            m = o->pass_mesh[i];
        }
        o->passes[i].shape.mesh = m;
    }
    return 0;
}

/* The command line for the file's metadata, shell-quoted. --threads N is
 * left out: the thread count never changes the result, and the file must be
 * byte-identical for any thread count. */
static void join_args(int argc, char **argv, char *out, size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (int i = 0; i < argc && at + 8 < outlen; i++) {
        const char *a = argv[i];
        if (i >= 2 && !strcmp(a, "--threads")) {
            i++;
            continue;
        }
        int quote = strpbrk(a, " \t'\"$\\`*?[]{}()<>|&;#~!") != NULL || !*a;
        if (i && at + 1 < outlen) out[at++] = ' ';
        if (quote && at + 1 < outlen) out[at++] = '\'';
        for (const char *c = a; *c && at + 6 < outlen; c++) {
            if (quote && *c == '\'') { /* 'it'\''s' */
                memcpy(out + at, "'\\''", 4);
                at += 4;
            } else {
                out[at++] = *c;
            }
        }
        if (quote && at + 1 < outlen) out[at++] = '\'';
        out[at] = 0;
    }
}

/* Volume of one particle of bounding radius 1 (o->mesh loaded first). */
static double unit_volume(const pack_opts *o) {
    return o->mesh ? vp_mesh_shape_volume(o->mesh)
                   : vp_shape_unit_volume_param(o->shape, o->shape_param);
}

/* rsa --count N without --radius: the radius at which N particles fill
 * target_fraction of the container. */
static double rsa_count_radius(const pack_opts *o, const vp_container_info *ci) {
    return cbrt(o->target_fraction * ci->volume / ((double)o->count * unit_volume(o)));
}

static double smallest_radius(const pack_opts *o, const vp_container_info *ci);

/* A margin that leaves no centre: analytic containers know their inradius
 * (others: the packer finds no room, and says so). */
static int margin_check(const pack_opts *o, const vp_container_info *ci) {
    if (!(o->margin > 0) || ci->kind != VP_CONTAINER_ANALYTIC) return 0;
    double in = HUGE_VAL;
    for (int k = 0; k < 3; k++) in = fmin(in, 0.5 * (ci->bmax[k] - ci->bmin[k]));
    double r = o->fit == VP_FIT_INSIDE ? smallest_radius(o, ci) : 0.0;
    if (o->margin + r < in) return 0;
    return vp_cli_die(2, "pack: --margin %g%s leave%s no room in %s, whose inradius is %g",
                      o->margin, r > 0 ? " and the smallest radius" : "", r > 0 ? "" : "s",
                      o->container, in);
}

/* Lattice --count: the radius the packer starts from (the infinite
 * lattice's, which fills the container's volume with count particles); the
 * radius it ends with is about this or smaller. */
static double lattice_count_radius(const pack_opts *o, const vp_container_info *ci) {
    double f = vp_lattice_fraction_param(o->shape, o->shape_param, o->lattice);
    return cbrt(ci->volume * f /
                ((double)o->count * vp_shape_unit_volume_param(o->shape, o->shape_param)));
}

/* The smallest radius the method will produce, as far as the options tell
 * before packing (0 when they do not: relax with --target-fraction). */
static double smallest_radius(const pack_opts *o, const vp_container_info *ci) {
    if (!strcmp(o->method, "lattice"))
        return o->radius > 0 ? o->radius : lattice_count_radius(o, ci);
    if (!strcmp(o->method, "rsa")) {
        double m = HUGE_VAL;
        for (int i = 0; i < o->npasses; i++) m = fmin(m, vp_size_dist_min(&o->passes[i].radius));
        if (o->fields.radius_field && o->fields.rmin > 0) /* (check_fields ran) */
            m = o->fields.mode == VP_FIELD_ABSOLUTE ? o->fields.rmin : m * o->fields.rmin;
        return isfinite(m) ? m : 0.0;
    }
    if (!strcmp(o->method, "jam")) return 0.0; /* the jamming point's */
    return o->target_fraction > 0 ? 0.0 : vp_size_dist_min(&o->sizes);
}

/* jam with --count N and --radius: N spheres of these radii must fit at
 * all (the jamming point then scales them; without --radius any N does). */
static int jam_count_check(const pack_opts *o, const vp_container_info *ci) {
    if (strcmp(o->method, "jam") != 0 || !o->count || !o->radius_text) return 0;
    double v = (double)o->count * 4.0 / 3.0 * M_PI * vp_size_dist_mean_cube(&o->sizes);
    int equal = vp_size_dist_min(&o->sizes) == vp_size_dist_max(&o->sizes);
    double most = equal ? 0.7405 : 1.0;
    if (v <= most * ci->volume) return 0;
    return vp_cli_die(1,
                      "pack: %llu spheres of radius %s fill %.3g times the container's volume, "
                      "more than %s; use fewer or smaller spheres (or leave out --radius: jam "
                      "then finds the radius)",
                      (unsigned long long)o->count, o->radius_text, v / ci->volume,
                      equal ? "equal spheres can fill (0.7405)" : "it has");
}

/* A radius that a .vdb cannot hold (positions to within VP_POSITION_ERROR_LIMIT
 * of it): one line naming the radius, before the packing's work. */
static int vdb_radius_check(const pack_opts *o, const vp_container_info *ci, double r) {
    if (o->out_format != VP_FORMAT_VDB || !(r > 0)) return 0;
    double m = 0;
    for (int k = 0; k < 3; k++) m = fmax(m, fmax(fabs(ci->bmin[k]), fabs(ci->bmax[k])));
    double least = vp_points_min_radius(m);
    if (r >= least) return 0;
    return vp_cli_die(2,
                      "pack: radius %g is too small for a .vdb: OpenVDB's points grid stores "
                      "positions%s only to within %.3g, more than %g of it (radii from %.3g "
                      "fit); write .csv or .ply instead, or scale the scene up",
                      r, m > 536870912.0 * VP_POINTS_MIN_VOXEL ? " this far from the origin" : "",
                      least * VP_POSITION_ERROR_LIMIT, VP_POSITION_ERROR_LIMIT, least);
}

/* --- fields and masks: options, loading, checks (docs/fields.md) ---------- */

/* Reads the radius and density fields (before the container: the radius
 * field's largest value sizes its level set). */
static int load_fields(vp_context *ctx, pack_opts *o) {
    pack_fields *f = &o->fields;
    if (f->radius.text) {
        if (vp_field_load(ctx, f->radius.path, f->radius.grid, &f->radius_field) != VP_OK)
            return lib_error(ctx);
        if (f->mode == VP_FIELD_ABSOLUTE) {
            vp_field_info fi;
            vp_field_get_info(f->radius_field, &fi);
            if (!(fi.max > 0))
                return vp_cli_die(1,
                                  "%s: the radius field has no positive value (largest %g); "
                                  "radii must be positive",
                                  f->radius.path, fi.max);
            for (int i = 0; i < o->npasses; i++)
                vp_size_dist_constant(&o->passes[i].radius, fi.max);
            vp_size_dist_constant(&o->sizes, fi.max); /* relax, jam: replaced by the field */
        }
    }
    if (f->density.text &&
        vp_field_load(ctx, f->density.path, f->density.grid, &f->density_field) != VP_OK)
        return lib_error(ctx);
    return 0;
}

/* --mask: the container less the mask's inside. *c becomes the masked
 * container; o->fields.base keeps the old one (for --save-container) and
 * mask_c the mask, both freed after *c. */
static int apply_mask(vp_context *ctx, pack_opts *o, vp_container **c) {
    pack_fields *f = &o->fields;
    if (!f->mask.text) return 0;
    vp_container *m = NULL;
    int an = vp_cli_analytic_container(ctx, f->mask.text, &m);
    if (an == -2) return vp_cli_die(2, "pack: --mask: %s", vp_context_message(ctx));
    if (an < 0)
        return vp_cli_die(2,
                          "pack: malformed analytic --mask '%s' (sphere:R or box:X,Y,Z with "
                          "positive sizes)",
                          f->mask.text);
    vp_container_info ci;
    vp_container_get_info(*c, &ci);
    /* the distances a packer needs outside the mask: the largest radius
     * (fit inside) and the margin */
    double need = o->margin;
    vp_container_params cp;
    container_params(o, &cp);
    double r = cp.particle_radius; /* else, from the count (relax, jam: at the start) */
    if (!(r > 0) && cp.particle_count && cp.space_per_particle > 0)
        r = cbrt(ci.volume / ((double)cp.particle_count * cp.space_per_particle));
    if (o->fit == VP_FIT_INSIDE) need += r;
    if (an == 0) {
        cp.grid_name = f->mask.grid;
        cp.has_iso = 0;
        /* the container's voxel, coarsened where the band of 3 voxels
         * outside the mask would not reach `need` */
        if (ci.voxel_size > 0) cp.voxel_size = ci.voxel_size;
        if (cp.voxel_size == 0 && need > 0) /* (automatic: half the radius or less) */
            cp.voxel_size = 1.05 * need / 3.0;
        if (cp.voxel_size > 0 && 3.0 * cp.voxel_size < 1.05 * need)
            cp.voxel_size = 1.05 * need / 3.0;
        if (vp_container_load(ctx, f->mask.path, &cp, &m) != VP_OK) return lib_error(ctx);
    }
    vp_container_info mki;
    vp_container_get_info(m, &mki);
    f->mask_voxel = mki.voxel_size;
    f->mask_c = m;
    vp_container *cm = NULL;
    if (vp_container_subtract(ctx, *c, m, &cm) != VP_OK)
        return vp_cli_die(1, "pack: --mask %s: %s", f->mask.text, vp_context_message(ctx));
    f->base = *c;
    *c = cm;
    vp_container_info mi;
    vp_container_get_info(cm, &mi);
    if (need > 0 && mi.interior_band < need)
        return vp_cli_die(1,
                          "pack: --mask %s: its level set holds distances only %g outside "
                          "it, and the particles need %g (radius and margin); give a mask "
                          "with a wider exterior band",
                          f->mask.text, mi.interior_band, need);
    return 0;
}

/* The fields against the container they drive (its inside covered,
 * radii positive, a density not negative), each named by its file. */
static int check_fields(vp_context *ctx, pack_opts *o, const vp_container *c) {
    pack_fields *f = &o->fields;
    if (f->radius_field && vp_field_check(ctx, f->radius_field, f->radius.text, "radius field", 1,
                                          c, &f->rmin, &f->rmax) != VP_OK)
        return lib_error(ctx);
    if (f->density_field && vp_field_check(ctx, f->density_field, f->density.text, "density field",
                                           0, c, NULL, NULL) != VP_OK)
        return lib_error(ctx);
    return 0;
}

/* relax and jam with a radius field: radii vary by up to the field's
 * largest over its smallest value (capped at 8: a field that is 0 or
 * negative somewhere is refused where it covers the container), so the
 * container's band must reach that much deeper. */
static void field_band(const pack_opts *o, vp_container_params *cp) {
    if (!o->fields.radius_field) return;
    vp_field_info fi;
    vp_field_get_info(o->fields.radius_field, &fi);
    double k = fi.min > 0 ? fi.max / fi.min : 8.0;
    if (!(k >= 1)) k = 1;
    if (k > 8) k = 8;
    if (!strcmp(o->method, "relax") && !(o->target_fraction > 0) && fi.max > 0) {
        /* radii as the field makes them: times it, or it */
        cp->particle_radius =
            o->fields.mode == VP_FIELD_SCALE ? cp->particle_radius * fi.max : fi.max;
        return;
    }
    cp->particle_radius *= k;
    cp->space_per_particle /= k * k * k;
}

/* The library's parameters of the method's job, from the options. */
static void lattice_params(const pack_opts *o, vp_lattice_params *lp) {
    vp_lattice_params_init(lp);
    lp->shape = o->shape;
    lp->shape_param = o->shape_param;
    lp->lattice = o->lattice;
    lp->fit = o->fit;
    lp->radius = o->radius;
    lp->count = (size_t)o->count;
    lp->offsets = (int)o->offsets;
    lp->rotate = o->rotate;
    lp->rotations = (int)o->rotations;
    lp->seed = o->seed;
    lp->margin = o->margin;
    lp->gap = o->gap;
}

static void rsa_params(const pack_opts *o, vp_rsa_params *rp) {
    vp_rsa_params_init(rp);
    rp->fit = o->fit;
    rp->shape = o->shape;
    rp->shape_param = o->shape_param;
    rp->mesh = o->mesh;
    rp->orient = (vp_orient_mode)o->orient;
    rp->overlap = (vp_overlap_mode)o->overlap;
    rp->passes = o->passes;
    rp->npasses = (size_t)o->npasses;
    rp->seed = o->seed;
    rp->margin = o->margin;
    rp->gap = o->gap;
    rp->radius_field = o->fields.radius_field;
    rp->radius_field_mode = o->fields.mode;
    rp->density_field = o->fields.density_field;
}

static void relax_params(const pack_opts *o, vp_relax_params *xp) {
    vp_relax_params_init(xp);
    xp->fit = o->fit;
    xp->radius = o->sizes;
    xp->count = (size_t)o->count;
    xp->target_fraction = o->target_fraction;
    if (o->tolerance > 0) xp->tolerance = o->tolerance;
    xp->seed = o->seed;
    xp->margin = o->margin;
    xp->gap = o->gap;
    xp->radius_field = o->fields.radius_field;
    xp->radius_field_mode = o->fields.mode;
}

static void jam_params(const pack_opts *o, vp_jam_params *jp) {
    vp_jam_params_init(jp);
    jp->fit = o->fit;
    jp->radius = o->sizes;
    jp->count = (size_t)o->count;
    if (o->target_fraction > 0) jp->target_fraction = o->target_fraction;
    if (o->tolerance > 0) jp->tolerance = o->tolerance;
    jp->seed = o->seed;
    jp->margin = o->margin;
    jp->gap = o->gap;
    jp->radius_field = o->fields.radius_field;
    jp->radius_field_mode = o->fields.mode;
}

/* What loading a mesh or .vdb container needs to know of the job. */
static void container_params(const pack_opts *o, vp_container_params *cp) {
    vp_container_params_init(cp);
    cp->voxel_size = o->voxel_size;
    cp->inside = o->inside;
    cp->has_iso = o->has_iso;
    cp->iso = o->iso;
    cp->grid_name = o->grid;
    if (!strcmp(o->method, "lattice")) {
        vp_lattice_params lp;
        lattice_params(o, &lp);
        vp_container_params_for_lattice(cp, &lp);
    } else if (!strcmp(o->method, "rsa")) {
        vp_rsa_params rp;
        rsa_params(o, &rp);
        vp_container_params_for_rsa(cp, &rp);
        if (o->rsa_count_radius) { /* the radius follows from the volume */
            cp->particle_radius = 0;
            cp->particle_count = (size_t)o->count;
            cp->space_per_particle = unit_volume(o) / o->target_fraction;
        }
    } else if (!strcmp(o->method, "jam")) {
        vp_jam_params jp;
        jam_params(o, &jp);
        vp_container_params_for_jam(cp, &jp);
        field_band(o, cp);
    } else {
        vp_relax_params xp;
        relax_params(o, &xp);
        vp_container_params_for_relax(cp, &xp);
        field_band(o, cp);
    }
}

static vp_result run_method(vp_context *ctx, const vp_container *c, pack_opts *o, vp_particles **p,
                            run_result *rr) {
    memset(rr, 0, sizeof *rr);
    vp_result r;
    if (!strcmp(o->method, "lattice")) {
        vp_lattice_params lp;
        lattice_params(o, &lp);
        r = vp_pack_lattice(ctx, c, &lp, p, &rr->lat);
        rr->pack_seconds = rr->lat.seconds;
        rr->max_radius = rr->lat.radius;
    } else if (!strcmp(o->method, "rsa")) {
        vp_rsa_params rp;
        rsa_params(o, &rp);
        r = vp_pack_rsa(ctx, c, &rp, p, &rr->rsa);
        rr->pack_seconds = rr->rsa.seconds;
    } else if (!strcmp(o->method, "jam")) {
        vp_jam_params jp;
        jam_params(o, &jp);
        r = vp_pack_jam(ctx, c, &jp, p, &rr->jam);
        rr->pack_seconds = rr->jam.seconds;
    } else {
        vp_relax_params xp;
        relax_params(o, &xp);
        r = vp_pack_relax(ctx, c, &xp, p, &rr->relax);
        rr->pack_seconds = rr->relax.seconds;
    }
    if (r == VP_OK && *p && !rr->max_radius) {
        const vp_particles *q = *p;
        double m = q->uniform_radius;
        if (q->radii)
            for (size_t i = 0; i < q->count; i++)
                if (q->radii[i] > m) m = q->radii[i];
        rr->max_radius = m;
    }
    return r;
}

/* A lattice --count whose radius (estimated: about "about ") is below
 * float's smallest normal value, which pscale cannot hold: exit 2. */
static int count_radius_too_small(const pack_opts *o, const char *about, double r) {
    return vp_cli_die(2,
                      "pack: --count %llu in %s gives a radius of %s%g, below 1.2e-38 (radii "
                      "are stored as float): ask for fewer particles",
                      (unsigned long long)o->count, o->container, about, r);
}

static int malformed_analytic(const char *spec) {
    return vp_cli_die(2,
                      "pack: malformed analytic container '%s' (sphere:R or box:X,Y,Z with "
                      "positive sizes)",
                      spec);
}

int vp_cli_pack_parse_only(int argc, char **argv) {
    pack_opts o;
    int rc = pack_parse_options(argc, argv, &o);
    if (rc) return rc;
    vp_shape_format(o.shape, o.shape_param, o.shape_text, sizeof o.shape_text);
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    vp_container *c = NULL;
    int an = vp_cli_analytic_container(ctx, o.container, &c);
    vp_container_destroy(c);
    rc = an == -2 ? vp_cli_die(2, "pack: %s", vp_context_message(ctx))
         : an < 0 ? malformed_analytic(o.container)
                  : 0;
    vp_context_destroy(ctx);
    return rc;
}

/* One run of `vdbpack pack`: what its steps share. Owned by vp_cli_pack,
 * which frees it (job_finish). */
typedef struct pack_job {
    pack_opts o;
    int argc;
    char **argv;
    double t0;
    vp_context *ctx;
    progress prog;
    vp_mesh_shape *mesh; /* --shape FILE, loaded */
    vp_container *c;
    vp_container_info ci;
    vp_particles *p;
    run_result rr;
    double fraction;
    vp_write_report wrep;
    const char *created[2]; /* written so far (removed on failure) */
    int ncreated;
    int nshort; /* passes that placed fewer than asked */
    size_t short_asked, short_placed;
} pack_job;

/* The context (threads, memory limit), the progress bar and the signal
 * handlers. */
static int job_start(pack_job *j) {
    pack_opts *o = &j->o;
    vp_shape_format(o->shape, o->shape_param, o->shape_text, sizeof o->shape_text);
    j->t0 = now();
    if (vp_context_create(&j->ctx) != VP_OK) {
        j->ctx = NULL;
        return vp_cli_die(1, "out of memory");
    }
    if (!o->threads && getenv("VDBPACK_THREADS")) {
        const char *e = getenv("VDBPACK_THREADS");
        if (vp_cli_parse_u64(e, &o->threads) != 0 || o->threads == 0 || o->threads > 256)
            return vp_cli_die(2,
                              "pack: VDBPACK_THREADS must be a whole number in 1..256, not "
                              "'%s'",
                              e);
    }
    if (o->threads) vp_context_set_threads(j->ctx, (int)o->threads);
    if (o->max_memory) vp_context_set_max_memory(j->ctx, o->max_memory);
    progress *prog = &j->prog;
    prog->ctx = j->ctx;
    prog->start = now();
    prog->lines = o->progress;
    prog->bar = !o->progress && !o->quiet && !o->json && isatty(2);
    prog->phase = "starting";
    vp_context_set_progress(j->ctx, on_progress, prog);
    vp_cli_signals_install();
    return 0;
}

/* The particle shapes and the fields, before the container: a bad shape
 * file fails before a long voxelization. */
static int job_load_shapes(pack_job *j) {
    pack_opts *o = &j->o;
    if (o->shape == VP_SHAPE_MESH) {
        if (vp_mesh_shape_load(j->ctx, o->shape_file, &j->mesh) != VP_OK) return lib_error(j->ctx);
        o->mesh = j->mesh;
    }
    int status = load_pass_shapes(j->ctx, o);
    if (!status) status = load_fields(j->ctx, o);
    return status;
}

/* The container (analytic, or loaded from its file), less the mask; its
 * info and warnings. */
static int job_load_container(pack_job *j) {
    pack_opts *o = &j->o;
    int an = vp_cli_analytic_container(j->ctx, o->container, &j->c);
    if (an == -2) return vp_cli_die(2, "pack: %s", vp_context_message(j->ctx));
    if (an < 0) return malformed_analytic(o->container);
    if (an == 0) {
        vp_container_params cp;
        container_params(o, &cp);
        progress_phase(&j->prog, "loading", 0.3);
        if (vp_container_load(j->ctx, o->container, &cp, &j->c) != VP_OK) return lib_error(j->ctx);
    } else if (o->voxel_size > 0 || o->grid || o->save_container || o->inside_set || o->has_iso) {
        return vp_cli_die(2,
                          "pack: --voxel-size, --grid, --inside, --iso and --save-container "
                          "need a mesh or .vdb container, not '%s'",
                          o->container);
    }
    int status = apply_mask(j->ctx, o, &j->c);
    if (!status) status = check_fields(j->ctx, o, j->c);
    if (status) return status;
    vp_container_get_info(j->c, &j->ci);
    if (!o->quiet) vp_cli_warn_container(&j->ci);
    return 0;
}

/* The checks that need the container: sizes a file can hold, the radius
 * that --count gives, the margin's room. */
static int job_check_sizes(pack_job *j) {
    pack_opts *o = &j->o;
    const vp_container_info *ci = &j->ci;
    /* a mesh this small packs (voxelized in scaled units), but OpenVDB's
     * transforms cannot hold its level set in a file: said before packing */
    if (o->save_container && ci->voxel_size > 0 && ci->voxel_size < VP_POINTS_MIN_VOXEL)
        return vp_cli_die(2,
                          "pack: --save-container %s: the container's voxel size %g is "
                          "below the smallest a .vdb can hold (%g); give --voxel-size %g "
                          "or more, or scale the mesh up",
                          o->save_container, ci->voxel_size, VP_POINTS_MIN_VOXEL,
                          VP_POINTS_MIN_VOXEL);
    if (o->rsa_count_radius) {
        double r = rsa_count_radius(o, ci);
        if (!(r >= FLT_MIN) || !(r <= FLT_MAX)) return count_radius_too_small(o, "", r);
        vp_size_dist_constant(&o->passes[0].radius, r);
        if (o->gap > 0 && !(o->gap < r))
            return vp_cli_die(2,
                              "pack: --gap %g must be smaller than the radius %g that "
                              "--count %llu gives",
                              o->gap, r, (unsigned long long)o->count);
    }
    int status = margin_check(o, ci);
    if (status) return status;
    if (!strcmp(o->method, "lattice") && o->count && !(lattice_count_radius(o, ci) >= FLT_MIN))
        return count_radius_too_small(o, "about ", lattice_count_radius(o, ci));
    status = vdb_radius_check(o, ci, smallest_radius(o, ci));
    if (!status) status = jam_count_check(o, ci);
    return status;
}

/* The packer; then the shapes the passes made, and the fraction. */
static int job_pack(pack_job *j) {
    pack_opts *o = &j->o;
    progress_phase(&j->prog, "packing", o->preview ? 0.8 : 0.9);
    if (run_method(j->ctx, j->c, o, &j->p, &j->rr) != VP_OK) return lib_error(j->ctx);
    if (!strcmp(o->method, "lattice") && !(j->rr.lat.radius >= FLT_MIN))
        return count_radius_too_small(o, "", j->rr.lat.radius);
    if (o->mesh)
        snprintf(o->default_shape_text, sizeof o->default_shape_text, "mesh:%.280s",
                 vp_mesh_shape_name(o->mesh));
    else snprintf(o->default_shape_text, sizeof o->default_shape_text, "%s", o->shape_text);
    if (o->pass_shapes) { /* the shapes are those the passes made */
        o->mixed = j->p->shape == VP_SHAPE_MIXED;
        o->shape = j->p->shape;
        o->shape_param = j->p->shape_param;
        o->mesh = j->p->mesh;
        if (o->mixed) snprintf(o->shape_text, sizeof o->shape_text, "mixed");
        else vp_shape_format(o->shape, o->shape_param, o->shape_text, sizeof o->shape_text);
    }
    j->fraction = j->ci.volume > 0 ? vp_particles_volume(j->p) / j->ci.volume : 0.0;
    j->nshort = pack_shortfall(o, &j->rr.rsa, &j->short_asked, &j->short_placed);
    return 0;
}

/* --save-container and --shape-out, before the packing's own file. */
static int job_write_extras(pack_job *j) {
    pack_opts *o = &j->o;
    if (o->save_container) {
        if (vp_container_save(j->ctx, o->fields.base ? o->fields.base : j->c, o->save_container) !=
            VP_OK)
            return lib_error(j->ctx);
        j->created[j->ncreated++] = o->save_container;
        vp_cli_signals_track_output(o->save_container);
    }
    if (o->shape_out) {
        if ((o->mixed  ? vp_particles_write_shapes_obj(j->ctx, j->p, o->shape_out)
             : o->mesh ? vp_mesh_shape_write_obj(j->ctx, o->mesh, o->shape_out)
                       : vp_shape_write_obj_param(j->ctx, o->shape, o->shape_param,
                                                  o->shape_out)) != VP_OK)
            return lib_error(j->ctx);
        j->created[j->ncreated++] = o->shape_out;
        vp_cli_signals_track_output(o->shape_out);
    }
    return 0;
}

/* The packing's file with its metadata (what `vdbpack check` reads back). */
static int job_write_packing(pack_job *j) {
    pack_opts *o = &j->o;
    const vp_container_info *ci = &j->ci;
    const run_result *rr = &j->rr;
    char cmdline[4096], method_params[4096] = "";
    char requested_text[VP_MAX_GROUPS * 24] = "", placed_text[VP_MAX_GROUPS * 24] = "";
    join_args(j->argc, j->argv, cmdline, sizeof cmdline);
    const char *cname = strrchr(o->container, '/');
    cname = cname ? cname + 1 : o->container;
    vp_meta meta[40] = {
        {"creator", VP_META_STRING, "vdbpack " VP_VERSION_STRING, 0, 0},
        {"command_line", VP_META_STRING, cmdline, 0, 0},
        {"seed", VP_META_INT, NULL, (int64_t)o->seed, 0},
        {"method", VP_META_STRING, o->method, 0, 0},
        {"shape", VP_META_STRING, o->shape_text, 0, 0},
        {"fit", VP_META_STRING, o->fit == VP_FIT_INSIDE ? "inside" : "center", 0, 0},
        {"container", VP_META_STRING, cname, 0, 0},
        {"particle_count", VP_META_INT, NULL, (int64_t)j->p->count, 0},
        {"max_radius", VP_META_DOUBLE, NULL, 0, rr->max_radius},
        {"container_volume", VP_META_DOUBLE, NULL, 0, ci->volume},
        {"packing_fraction", VP_META_DOUBLE, NULL, 0, j->fraction},
        {"voxel_size", VP_META_DOUBLE, NULL, 0, ci->voxel_size},
    };
    size_t nmeta = 12;
    if (o->mesh)
        meta[nmeta++] = (vp_meta){"shape_file", VP_META_STRING, vp_mesh_shape_name(o->mesh), 0, 0};
    char shape_list[4096];
    if (o->mixed)
        meta[nmeta++] =
            (vp_meta){"shapes", VP_META_STRING,
                      vp_particles_shape_list(j->p, shape_list, sizeof shape_list), 0, 0};
    if (ci->kind == VP_CONTAINER_MESH)
        meta[nmeta++] = (vp_meta){"inside", VP_META_STRING, vp_inside_name(o->inside), 0, 0};
    if (o->has_iso) meta[nmeta++] = (vp_meta){"iso", VP_META_DOUBLE, NULL, 0, o->iso};
    if (o->fields.mask.text)
        meta[nmeta++] = (vp_meta){"mask", VP_META_STRING, o->fields.mask.text, 0, 0};
    if (o->fields.mask_voxel > 0)
        meta[nmeta++] = (vp_meta){"mask_voxel_size", VP_META_DOUBLE, NULL, 0, o->fields.mask_voxel};
    if (o->fields.radius.text) {
        meta[nmeta++] = (vp_meta){"radius_field", VP_META_STRING, o->fields.radius.text, 0, 0};
        meta[nmeta++] = (vp_meta){"radius_field_mode", VP_META_STRING,
                                  vp_field_mode_name(o->fields.mode), 0, 0};
    }
    if (o->fields.density.text)
        meta[nmeta++] = (vp_meta){"density_field", VP_META_STRING, o->fields.density.text, 0, 0};
    if (!strcmp(o->method, "lattice")) {
        meta[nmeta++] = (vp_meta){"lattice", VP_META_STRING, pack_lattice_label(o), 0, 0};
        meta[nmeta++] = (vp_meta){"radius", VP_META_DOUBLE, NULL, 0, rr->lat.radius};
    } else if (!strcmp(o->method, "rsa")) {
        pack_passes_text(o, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"passes", VP_META_STRING, method_params, 0, 0};
        pack_counts_text(o, &rr->rsa, 0, requested_text, sizeof requested_text);
        pack_counts_text(o, &rr->rsa, 1, placed_text, sizeof placed_text);
        meta[nmeta++] = (vp_meta){"requested", VP_META_STRING, requested_text, 0, 0};
        meta[nmeta++] = (vp_meta){"placed", VP_META_STRING, placed_text, 0, 0};
        meta[nmeta++] = (vp_meta){"short", VP_META_INT, NULL, j->nshort > 0, 0};
        if (o->rsa_count_radius)
            meta[nmeta++] =
                (vp_meta){"target_fraction", VP_META_DOUBLE, NULL, 0, o->target_fraction};
        if (o->shape != VP_SHAPE_SPHERE) {
            meta[nmeta++] = (vp_meta){"orient", VP_META_STRING,
                                      o->orient == VP_ORIENT_FIXED ? "fixed" : "random", 0, 0};
            meta[nmeta++] = (vp_meta){"overlap", VP_META_STRING,
                                      o->overlap == VP_OVERLAP_BBOX ? "bbox" : "exact", 0, 0};
        }
    } else if (!strcmp(o->method, "jam")) {
        vp_size_dist_format(&o->sizes, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"radius", VP_META_STRING, method_params, 0, 0};
        meta[nmeta++] = (vp_meta){"radius_scale", VP_META_DOUBLE, NULL, 0, rr->jam.radius_scale};
        meta[nmeta++] = (vp_meta){"max_overlap", VP_META_DOUBLE, NULL, 0, rr->jam.max_overlap};
        meta[nmeta++] = (vp_meta){"mean_contacts", VP_META_DOUBLE, NULL, 0, rr->jam.mean_contacts};
        meta[nmeta++] =
            (vp_meta){"rattler_fraction", VP_META_DOUBLE, NULL, 0, rr->jam.rattler_fraction};
        meta[nmeta++] = (vp_meta){"core_fraction", VP_META_DOUBLE, NULL, 0, rr->jam.core_fraction};
    } else {
        vp_size_dist_format(&o->sizes, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"radius", VP_META_STRING, method_params, 0, 0};
        meta[nmeta++] = (vp_meta){"target_fraction", VP_META_DOUBLE, NULL, 0, o->target_fraction};
        meta[nmeta++] = (vp_meta){"radius_scale", VP_META_DOUBLE, NULL, 0, rr->relax.radius_scale};
        meta[nmeta++] = (vp_meta){"max_overlap", VP_META_DOUBLE, NULL, 0, rr->relax.max_overlap};
    }
    /* what `vdbpack check` then holds the file to by default */
    if (o->margin > 0) meta[nmeta++] = (vp_meta){"margin", VP_META_DOUBLE, NULL, 0, o->margin};
    if (o->gap > 0) meta[nmeta++] = (vp_meta){"gap", VP_META_DOUBLE, NULL, 0, o->gap};
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.full_precision = o->full_precision;
    wp.meta = meta;
    wp.meta_count = nmeta;
    wp.report = &j->wrep;
    progress_phase(&j->prog, "writing", o->preview ? 0.5 : 1.0);
    if (vp_cli_write_particles(j->ctx, o->output, o->out_format, j->p, &wp, o->quiet) != 0)
        return lib_error(j->ctx);
    if (vp_cli_interrupted()) {
        vp_cli_signals_track_output(o->output);
        return vp_cli_interrupted_exit();
    }
    return 0;
}

/* --preview: part of the job, so that if it fails no output stays. */
static int job_preview(pack_job *j) {
    pack_opts *o = &j->o;
    if (!o->preview) return 0;
    vp_cli_signals_track_output(o->output);
    progress_phase(&j->prog, "preview", 1.0);
    if (vp_cli_render_particles(j->ctx, j->p, NULL, o->preview) != 0) {
        vp_remove_output(o->output);
        return lib_error(j->ctx);
    }
    vp_cli_signals_track_output(o->preview);
    if (vp_cli_interrupted()) return vp_cli_interrupted_exit();
    return 0;
}

/* Every output written: kept. The summary or --json, and the exit status:
 * 0, VP_CLI_EXIT_SHORT for a shortfall without --allow-short, or an error
 * when the report asked for is lost (stdout on a full disk), which then
 * leaves no output. */
static int job_report(pack_job *j) {
    pack_opts *o = &j->o;
    vp_cli_signals_done();
    j->ncreated = 0; /* success: keep every output */
    double seconds = now() - j->t0;
    if (j->prog.shown) fprintf(stderr, "\r%*s\r", 96, "");
    progress_end(&j->prog);
    if (o->json)
        pack_print_json(o, &j->ci, j->p, &j->rr, &j->wrep, j->fraction, vp_context_threads(j->ctx),
                        seconds);
    else if (!o->quiet) pack_print_summary(o, &j->ci, j->p, &j->rr, &j->wrep, j->fraction, seconds);
    int status = vp_cli_flush_stdout(0);
    if (status) {
        const char *outs[4] = {o->output, o->save_container, o->shape_out, o->preview};
        for (int i = 0; i < 4; i++)
            if (outs[i]) vp_remove_output(outs[i]);
    } else if (j->nshort) {
        /* packed, but short: the file stays, a script sees it */
        if (!o->quiet)
            fprintf(stderr,
                    "vdbpack: warning: packed, but short: placed %zu of the %zu "
                    "particles asked for in %d %s; %s\n",
                    j->short_placed, j->short_asked, j->nshort, j->nshort == 1 ? "pass" : "passes",
                    o->allow_short ? "exit status 0 (--allow-short)"
                                   : "exit status 4 (--allow-short makes it 0)");
        if (!o->allow_short) status = VP_CLI_EXIT_SHORT;
    }
    return status;
}

/* Frees what the job holds; on failure, removes what it wrote. */
static void job_finish(pack_job *j, int status) {
    for (int i = 0; i < j->ncreated; i++) vp_remove_output(j->created[i]);
    if (j->prog.shown && status) fprintf(stderr, "\r%*s\r", 96, "");
    vp_particles_destroy(j->p);
    vp_mesh_shape_destroy(j->mesh);
    for (int i = 0; i < j->o.npasses; i++) vp_mesh_shape_destroy(j->o.pass_mesh[i]);
    vp_container_destroy(j->c);
    vp_container_destroy(j->o.fields.base); /* (after c, which borrows them) */
    vp_container_destroy(j->o.fields.mask_c);
    vp_field_destroy(j->o.fields.radius_field);
    vp_field_destroy(j->o.fields.density_field);
    vp_context_destroy(j->ctx);
    free(j);
}

int vp_cli_pack(int argc, char **argv) {
    pack_job *j = calloc(1, sizeof *j); /* (the options hold 64 KiB of pass shape names) */
    if (!j) return vp_cli_die(1, "out of memory");
    j->argc = argc;
    j->argv = argv;
    int status = pack_parse_options(argc, argv, &j->o);
    if (status) { /* nothing loaded yet */
        free(j);
        return status;
    }
    status = job_start(j);
    if (!status) status = job_load_shapes(j);
    if (!status) status = job_load_container(j);
    if (!status) status = job_check_sizes(j);
    if (!status) status = job_pack(j);
    if (!status) status = job_write_extras(j);
    if (!status) status = job_write_packing(j);
    if (!status) status = job_preview(j);
    if (!status) status = job_report(j);
    job_finish(j, status);
    return status;
}

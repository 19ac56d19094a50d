/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack pack`: options, container, packer, outputs and the summary. */
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

/* rsa --count N without --radius: the packing fraction the radius is
 * chosen for (random sequential addition of equal spheres saturates near
 * 0.38 in bulk, less near walls; 0.3 leaves room to place all N) */
#define VP_CLI_RSA_FRACTION 0.3
/* exit status of a run that packed fewer particles than asked for */
#define VP_CLI_EXIT_SHORT 4

/* --- fields and masks (docs/fields.md) -------------------------------------
 * --mask FILE[:GRID] (a mesh, a .vdb level set, sphere:R or box:X,Y,Z: its
 * inside is taken out of the container, for every method), --radius-field
 * FILE.vdb[:GRID] with --radius-field-mode scale|absolute and
 * --density-field FILE.vdb[:GRID] (rsa). */
typedef struct field_arg {
    const char *text;       /* as given, or NULL */
    char path[4096];        /* the file (text without :GRID) */
    const char *grid;       /* points into text after ".vdb:", or NULL */
} field_arg;

typedef struct pack_fields {
    field_arg mask, radius, density;
    vp_field_mode mode;
    int mode_set;
    vp_field *radius_field, *density_field; /* loaded; owned by vp_cli_pack */
    double rmin, rmax;      /* the radius field's range over the container */
    double mask_voxel;      /* a mesh or level-set mask's voxel (metadata, for check) */
    vp_container *base, *mask_c; /* with --mask: the container and the mask, which
                                    the masked container borrows (freed after it) */
} pack_fields;

typedef struct pack_opts {
    const char *container;
    const char *output;
    const char *format;     /* --format, or NULL: by the output's extension */
    int out_format;         /* vp_format of the output */
    const char *method;
    vp_shape shape;
    double shape_param;     /* superball: the exponent */
    char shape_text[64];    /* the shape as files record it ("superball:2") */
    const char *shape_file; /* --shape FILE: a mesh (shape == VP_SHAPE_MESH) */
    const vp_mesh_shape *mesh; /* loaded from shape_file before packing */
    int orient;             /* -1 unset, else vp_orient_mode */
    int overlap;            /* -1 unset, else vp_overlap_mode */
    vp_lattice lattice;
    vp_fit fit;
    double radius;          /* lattice: the radius */
    const char *radius_text;
    vp_size_dist sizes;     /* rsa/relax: --radius as a distribution */
    uint64_t count;
    int count_max;          /* rsa: --count max */
    vp_rsa_pass passes[VP_MAX_GROUPS];
    int npasses;
    char pass_mesh_file[VP_MAX_GROUPS][1024]; /* --pass shape=FILE ("" for the others) */
    vp_mesh_shape *pass_mesh[VP_MAX_GROUPS];  /* loaded from them (owned; NULL where a
                                                 pass reuses an earlier one's) */
    int pass_shapes;        /* some --pass has shape= */
    int mixed;              /* the packing holds several shapes (VP_SHAPE_MIXED) */
    char default_shape_text[300]; /* --shape's (a mesh: "mesh:NAME"), the shape of
                                     the passes without their own */
    uint64_t retries;
    int grow;
    double target_fraction;
    double tolerance;
    int precision_set;
    uint64_t offsets;
    int rotate;
    uint64_t rotations;
    uint64_t seed;
    double voxel_size;
    vp_inside_mode inside;  /* --inside (meshes) */
    int inside_set;
    int has_iso;            /* --iso V (fog or density .vdb grids) */
    double iso;
    const char *grid;
    int full_precision;
    const char *save_container;
    const char *shape_out;
    const char *preview;    /* --preview IMAGE.exr|.png */
    uint64_t threads;
    uint64_t max_memory;
    int json;
    int quiet;
    int allow_short;        /* --allow-short: a shortfall exits 0 */
    int progress;           /* --progress: one line per stage on stderr */
    double margin;          /* --margin: distance kept from the wall (rsa) */
    double gap;             /* --gap: distance kept between surfaces (rsa) */
    int rsa_count_radius;   /* rsa --count N without --radius: the radius is
                               the one N fill target_fraction with */
    pack_fields fields;     /* --mask, --radius-field, --density-field */
} pack_opts;

/* --- progress (stderr) ------------------------------------------------------
 * One bar per run, on a terminal only, that never moves back: the run is a
 * list of phases (loading the container, packing, writing, the preview),
 * each with a weight estimated from the job before it starts; within a
 * phase the library's own fraction, which may restart (a lattice search
 * per radius tried, a random packer's passes), counts only where it passes
 * its largest so far. Elapsed and remaining time (remaining: elapsed times
 * what is left over what is done), and the particles placed so far where
 * the stage counts them (vp_context_progress_counts: rsa's passes).
 * --progress on a non-terminal: one line per stage instead ("progress:
 * STAGE FRACTION ELAPSED"), for scripts. */

typedef struct progress {
    const vp_context *ctx; /* for the stage's counts */
    double start;
    int shown;
    int bar;        /* draw a bar (stderr is a terminal) */
    int lines;      /* --progress: one line per stage, no bar */
    double last;    /* when the bar was last drawn (at most 10 times a second) */
    const char *phase;   /* the run's phase ("packing") */
    double base, weight; /* the phase spans [base, base + weight] of the bar */
    double local;   /* the phase's largest fraction so far */
    double done;    /* the bar's fraction: never decreases */
    char stage[48]; /* the last stage printed by --progress */
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
        if (ct) snprintf(counts, sizeof counts, " %llu of %llu", (unsigned long long)cd,
                         (unsigned long long)ct);
        else snprintf(counts, sizeof counts, " %llu placed", (unsigned long long)cd);
    }
    char mid[64];
    snprintf(mid, sizeof mid, "%s%s", stage ? stage : "", counts);
    fprintf(stderr, "\r[%.*s%*s] %3d%% %s: %-26.26s %.0f s%-14s", filled,
            "##############################", w - filled, "", (int)(p->done * 100 + 0.5),
            p->phase, mid, el, left);
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

/* 1 when some particle is not a sphere: --shape, or a --pass shape=. */
static int any_solid(const pack_opts *o) {
    if (o->shape != VP_SHAPE_SPHERE) return 1;
    for (int i = 0; i < o->npasses; i++)
        if (o->passes[i].own_shape && o->passes[i].shape.shape != VP_SHAPE_SPHERE) return 1;
    return 0;
}

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
                return vp_cli_die(2, "pack: --pass %d: shape '%s' is no shape name (sphere, a "
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

/* Which options go with which method, and defaults that depend on it. */
static int check_method_options(pack_opts *o, int have_radius, int have_count) {
    const char *m = o->method;
    int lattice = !strcmp(m, "lattice"), rsa = !strcmp(m, "rsa"), relax = !strcmp(m, "relax");
    int jam = !strcmp(m, "jam");
    /* (options that go with other methods: check_option_methods) */
    if (!rsa && o->count_max)
        return vp_cli_die(2, "pack: --count max goes with --method rsa, not %s", m);
    if (o->shape == VP_SHAPE_MESH && !rsa)
        return vp_cli_die(2, "pack: a mesh --shape (%s) packs with --method rsa in this version",
                          o->shape_file);
    if ((relax || jam) && o->shape != VP_SHAPE_SPHERE)
        return vp_cli_die(2, "pack: --method %s packs spheres in this version (--shape %s "
                             "needs --method lattice or rsa)", m, vp_shape_name(o->shape));
    if ((o->orient >= 0 || o->overlap >= 0) && !(rsa && any_solid(o)))
        return vp_cli_die(2, "pack: --orient and --overlap go with --method rsa and a --shape "
                             "(or a --pass shape=) other than sphere");
    if (o->overlap == VP_OVERLAP_BBOX && o->orient == VP_ORIENT_RANDOM)
        return vp_cli_die(2, "pack: --overlap bbox needs --orient fixed (the axis-aligned box "
                             "of a rotated solid does not bound it)");
    if (o->overlap < 0) o->overlap = VP_OVERLAP_EXACT;
    if (o->orient < 0) o->orient = o->overlap == VP_OVERLAP_BBOX ? VP_ORIENT_FIXED : VP_ORIENT_RANDOM;
    /* Random packings have particles in contact (grow, relax) or nearly so:
     * 16-bit fixed-point positions (1/65536 of a points voxel) would turn
     * contacts into overlaps, so they default to full precision. */
    if (!lattice && !o->precision_set) o->full_precision = 1;
    if (lattice) {
        if (have_radius && have_count)
            return vp_cli_die(2, "pack: give either --radius or --count, not both");
        if (!have_radius && !have_count)
            return vp_cli_die(2, "pack: give the particle size with --radius R or --count N");
        if (have_radius && (vp_cli_parse_double(o->radius_text, &o->radius) != 0 ||
                            !(o->radius > 0)))
            return vp_cli_die(2, "pack: --radius must be a positive number for --method lattice, "
                                 "not '%s'%s", o->radius_text,
                              strchr(o->radius_text, ':')
                                  ? " (distributions of radii go with --method rsa, relax and "
                                    "jam)"
                                  : "");
        /* as for rsa and relax (vp_size_dist_parse): a radius below a
         * normal float would be stored as a denormal or 0 */
        if (have_radius && !(o->radius >= FLT_MIN))
            return vp_cli_die(2, "pack: --radius: size '%s': a radius must be at least 1.2e-38 "
                                 "(radii are stored as float)", o->radius_text);
        if (have_radius && !(o->radius <= FLT_MAX))
            return vp_cli_die(2, "pack: --radius: size '%s': a radius must be at most 3.4e38 "
                                 "(radii are stored as float)", o->radius_text);
        if (o->shape == VP_SHAPE_SPHERE && o->lattice == VP_LATTICE_DENSEST)
            o->lattice = VP_LATTICE_FCC;
        if (o->shape != VP_SHAPE_SPHERE && o->lattice != VP_LATTICE_DEFAULT &&
            o->lattice != VP_LATTICE_DENSEST)
            return vp_cli_die(2, "pack: --lattice %s is for spheres; a %s packs on its densest "
                                 "lattice (--lattice densest)", vp_lattice_name(o->lattice),
                              vp_shape_name(o->shape));
        return 0;
    }
    if (rsa) {
        if (o->npasses && (have_radius || have_count))
            return vp_cli_die(2, "pack: give either --pass options or --radius with --count "
                                 "(one pass), not both");
        if (o->npasses && o->target_fraction > 0)
            return vp_cli_die(2, "pack: --target-fraction with --method rsa chooses the radius "
                                 "for --count N (no --radius); --pass gives its own radii");
        if (!o->npasses) {
            if (!have_count)
                return vp_cli_die(2, "pack: --method rsa needs --count N|max (with --radius R, "
                                     "or alone: the radius that fills --target-fraction) or "
                                     "--pass count=N,radius=R (one or more)");
            if (have_radius && o->target_fraction > 0)
                return vp_cli_die(2, "pack: --method rsa takes --radius R or --target-fraction F "
                                     "(which chooses the radius for --count N), not both");
            if (!have_radius && o->count_max)
                return vp_cli_die(2, "pack: --count max needs --radius R (the radius to fill "
                                     "with)");
            vp_rsa_pass *ps = &o->passes[0];
            vp_rsa_pass_init(ps);
            /* no --radius: one radius, set once the container's volume is
             * known (rsa_count_radius) */
            int rc = have_radius ? vp_cli_parse_sizes("--radius", o->radius_text, &ps->radius) : 0;
            if (rc) return rc;
            if (!have_radius) {
                o->rsa_count_radius = 1;
                if (!(o->target_fraction > 0)) o->target_fraction = VP_CLI_RSA_FRACTION;
            }
            ps->count = (size_t)o->count;
            ps->maximal = o->count_max;
            ps->grow = o->grow;
            o->npasses = 1;
        } else if (o->grow) {
            return vp_cli_die(2, "pack: with --pass, ask for growth in the pass (--pass "
                                 "count=N,radius=R,grow)");
        }
        /* a gap between solids is tested exactly on their shapes grown by
         * half of it: convex ones (a mesh shape's is not offered) */
        int mesh_pass = o->shape == VP_SHAPE_MESH;
        for (int i = 0; i < o->npasses; i++)
            mesh_pass |= o->passes[i].own_shape && o->passes[i].shape.shape == VP_SHAPE_MESH;
        if (o->gap > 0 && mesh_pass)
            return vp_cli_die(2, "pack: --gap is kept between spheres, solids and superballs in "
                                 "this version, not mesh shapes (--margin is)");
        if (o->gap > 0 && any_solid(o) && o->overlap == VP_OVERLAP_BBOX)
            return vp_cli_die(2, "pack: --gap is kept by the exact overlap test, not with "
                                 "--overlap bbox");
        if (o->pass_shapes && o->overlap == VP_OVERLAP_BBOX)
            return vp_cli_die(2, "pack: --overlap bbox takes one shape; passes with a shape= of "
                                 "their own are tested exactly");
        for (int i = 0; i < o->npasses; i++) {
            if (o->gap > 0 && !o->rsa_count_radius && !(o->gap < vp_size_dist_min(&o->passes[i].radius)))
                return vp_cli_die(2, "pack: --gap %g must be smaller than the smallest radius "
                                     "(%g, pass %d)", o->gap,
                                  vp_size_dist_min(&o->passes[i].radius), i + 1);
            /* each pass its own point group: a name=passK given to another
             * pass than the K-th made two groups of one name, which the
             * .vdb writer refused after packing and CSV merged */
            char ni[32], nk[32];
            snprintf(ni, sizeof ni, "%s", o->passes[i].name);
            if (!ni[0]) snprintf(ni, sizeof ni, "pass%d", i + 1);
            for (int k = 0; k < i; k++) {
                snprintf(nk, sizeof nk, "%s", o->passes[k].name);
                if (!nk[0]) snprintf(nk, sizeof nk, "pass%d", k + 1);
                if (!strcmp(nk, ni))
                    return vp_cli_die(2, "pack: passes %d and %d would both be group '%s'; give "
                                         "each pass its own name=", k + 1, i + 1, ni);
            }
            if (o->retries && !o->passes[i].retries) o->passes[i].retries = (int)o->retries;
        }
        return 0;
    }
    if (jam) {
        /* the radii's shape (1 when absent: equal spheres); their scale is
         * the jamming point's. N from --count, or from --radius and the
         * target fraction */
        if (!have_count && !have_radius)
            return vp_cli_die(2, "pack: --method jam needs --count N, or --radius SIZE (with "
                                 "--target-fraction F, default 0.64, for the number)");
        if (have_count && o->target_fraction > 0)
            return vp_cli_die(2, "pack: --method jam takes --count N or --target-fraction F, "
                                 "not both");
        if (!have_radius) {
            vp_size_dist_constant(&o->sizes, 1.0);
            return 0;
        }
        return vp_cli_parse_sizes("--radius", o->radius_text, &o->sizes);
    }
    /* relax (with an absolute radius field, the field gives the radii) */
    if (!have_radius && o->fields.radius.text && o->fields.mode == VP_FIELD_ABSOLUTE && have_count) {
        vp_size_dist_constant(&o->sizes, 1.0);
        return 0;
    }
    if (!have_radius || !have_count)
        return vp_cli_die(2, "pack: --method relax needs --radius R (or a distribution) and "
                             "--count N");
    return vp_cli_parse_sizes("--radius", o->radius_text, &o->sizes);
}

/* The long options of `vdbpack pack`, parsed by getopt_long: --opt=value
 * and --opt value, unambiguous abbreviations (--rad for --radius), -- ends
 * the options. Each option's id, and the methods it goes with (0: all). */
enum {
    OPT_OUTPUT = 'o', OPT_QUIET = 'q', OPT_HELP = 'h',
    OPT_FORMAT = 256, OPT_METHOD, OPT_SHAPE, OPT_ORIENT, OPT_OVERLAP, OPT_LATTICE, OPT_RADIUS,
    OPT_COUNT, OPT_PASS, OPT_RETRIES, OPT_GROW, OPT_TARGET_FRACTION, OPT_TOLERANCE, OPT_FIT,
    OPT_OFFSETS, OPT_ROTATE, OPT_ROTATIONS, OPT_SEED, OPT_VOXEL_SIZE, OPT_ALLOW_OPEN,
    OPT_INSIDE, OPT_ISO, OPT_GRID, OPT_PRECISION, OPT_SAVE_CONTAINER, OPT_SHAPE_OUT,
    OPT_PREVIEW, OPT_THREADS, OPT_MAX_MEMORY, OPT_JSON, OPT_ALLOW_SHORT, OPT_MARGIN, OPT_GAP,
    OPT_PROGRESS, OPT_MASK, OPT_RADIUS_FIELD, OPT_RADIUS_FIELD_MODE, OPT_DENSITY_FIELD,
    OPT_LAST
};

enum { M_LATTICE = 1, M_RSA = 2, M_RELAX = 4, M_JAM = 8 };

static const struct option PACK_OPTIONS[] = {
    {"output", required_argument, NULL, OPT_OUTPUT},
    {"quiet", no_argument, NULL, OPT_QUIET},
    {"help", no_argument, NULL, OPT_HELP},
    {"format", required_argument, NULL, OPT_FORMAT},
    {"method", required_argument, NULL, OPT_METHOD},
    {"shape", required_argument, NULL, OPT_SHAPE},
    {"orient", required_argument, NULL, OPT_ORIENT},
    {"overlap", required_argument, NULL, OPT_OVERLAP},
    {"lattice", required_argument, NULL, OPT_LATTICE},
    {"radius", required_argument, NULL, OPT_RADIUS},
    {"count", required_argument, NULL, OPT_COUNT},
    {"pass", required_argument, NULL, OPT_PASS},
    {"retries", required_argument, NULL, OPT_RETRIES},
    {"grow", no_argument, NULL, OPT_GROW},
    {"target-fraction", required_argument, NULL, OPT_TARGET_FRACTION},
    {"tolerance", required_argument, NULL, OPT_TOLERANCE},
    {"fit", required_argument, NULL, OPT_FIT},
    {"offsets", required_argument, NULL, OPT_OFFSETS},
    {"rotate", no_argument, NULL, OPT_ROTATE},
    {"rotations", required_argument, NULL, OPT_ROTATIONS},
    {"seed", required_argument, NULL, OPT_SEED},
    {"voxel-size", required_argument, NULL, OPT_VOXEL_SIZE},
    {"allow-open", no_argument, NULL, OPT_ALLOW_OPEN},
    {"inside", required_argument, NULL, OPT_INSIDE},
    {"iso", required_argument, NULL, OPT_ISO},
    {"grid", required_argument, NULL, OPT_GRID},
    {"precision", required_argument, NULL, OPT_PRECISION},
    {"save-container", required_argument, NULL, OPT_SAVE_CONTAINER},
    {"shape-out", required_argument, NULL, OPT_SHAPE_OUT},
    {"preview", required_argument, NULL, OPT_PREVIEW},
    {"threads", required_argument, NULL, OPT_THREADS},
    {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
    {"json", no_argument, NULL, OPT_JSON},
    {"allow-short", no_argument, NULL, OPT_ALLOW_SHORT},
    {"margin", required_argument, NULL, OPT_MARGIN},
    {"gap", required_argument, NULL, OPT_GAP},
    {"progress", no_argument, NULL, OPT_PROGRESS},
    {"mask", required_argument, NULL, OPT_MASK},
    {"radius-field", required_argument, NULL, OPT_RADIUS_FIELD},
    {"radius-field-mode", required_argument, NULL, OPT_RADIUS_FIELD_MODE},
    {"density-field", required_argument, NULL, OPT_DENSITY_FIELD},
    {NULL, 0, NULL, 0}};

/* The options that go with some methods only; the others go with all. */
static const struct {
    int id;
    unsigned methods;
} METHOD_OPTIONS[] = {
    {OPT_LATTICE, M_LATTICE}, {OPT_OFFSETS, M_LATTICE}, {OPT_ROTATE, M_LATTICE},
    {OPT_ROTATIONS, M_LATTICE}, {OPT_PASS, M_RSA}, {OPT_RETRIES, M_RSA}, {OPT_GROW, M_RSA},
    {OPT_ORIENT, M_RSA}, {OPT_OVERLAP, M_RSA}, {OPT_TARGET_FRACTION, M_RSA | M_RELAX | M_JAM},
    {OPT_TOLERANCE, M_RELAX | M_JAM},
    {OPT_MARGIN, M_RSA | M_RELAX | M_JAM}, {OPT_GAP, M_RSA | M_RELAX | M_JAM},
    {OPT_RADIUS_FIELD, M_RSA | M_RELAX | M_JAM}, {OPT_RADIUS_FIELD_MODE, M_RSA | M_RELAX | M_JAM},
    {OPT_DENSITY_FIELD, M_RSA},
};

static const char *option_name(int id) {
    for (const struct option *lo = PACK_OPTIONS; lo->name; lo++)
        if (lo->val == id) return lo->name;
    return "?";
}

/* "--name" of option id, in storage that lasts the process. */
static const char *dashed_name(int id) {
    static char names[sizeof PACK_OPTIONS / sizeof PACK_OPTIONS[0]][32];
    for (size_t i = 0; PACK_OPTIONS[i].name; i++)
        if (PACK_OPTIONS[i].val == id) {
            if (!names[i][0]) snprintf(names[i], sizeof names[i], "--%s", PACK_OPTIONS[i].name);
            return names[i];
        }
    return "?";
}

static unsigned method_bit(const char *m) {
    return !strcmp(m, "lattice") ? M_LATTICE : !strcmp(m, "rsa") ? M_RSA
           : !strcmp(m, "relax") ? M_RELAX : M_JAM;
}

/* "rsa", "relax and jam", "rsa, relax and jam" */
static void methods_text(unsigned m, char *out, size_t len) {
    static const char *const names[] = {"lattice", "rsa", "relax", "jam"};
    int n = 0, total = 0;
    for (int k = 0; k < 4; k++) total += (m >> k) & 1;
    out[0] = 0;
    for (int k = 0; k < 4; k++) {
        if (!((m >> k) & 1)) continue;
        size_t at = strlen(out);
        snprintf(out + at, len - at, "%s%s", n == 0 ? "" : n == total - 1 ? " and " : ", ",
                 names[k]);
        n++;
    }
}

/* An option given to a method that does not take it: one line naming the
 * methods that do. given[]: the option ids seen. */
static int check_option_methods(const pack_opts *o, const unsigned char *given) {
    unsigned mine = method_bit(o->method);
    for (size_t i = 0; i < sizeof METHOD_OPTIONS / sizeof METHOD_OPTIONS[0]; i++) {
        if (!given[METHOD_OPTIONS[i].id - OPT_FORMAT] || (METHOD_OPTIONS[i].methods & mine))
            continue;
        char ms[64];
        methods_text(METHOD_OPTIONS[i].methods, ms, sizeof ms);
        return vp_cli_die(2, "pack: --%s goes with --method %s, not %s",
                          option_name(METHOD_OPTIONS[i].id), ms, o->method);
    }
    return 0;
}

/* getopt_long's refusal of argument `arg` as one line: an unknown option,
 * an ambiguous abbreviation (naming the candidates), a value missing or
 * given to an option that takes none. */
static int option_error(int c, const char *arg) {
    if (c == ':') {
        const char *name = optopt >= OPT_FORMAT ? option_name(optopt) : NULL;
        if (name) return vp_cli_die(2, "pack: --%s needs a value", name);
        if (optopt) return vp_cli_die(2, "pack: -%c needs a value", optopt);
        return vp_cli_die(2, "pack: %s needs a value", arg);
    }
    if (optopt >= OPT_FORMAT)
        return vp_cli_die(2, "pack: --%s takes no value ('%s')", option_name(optopt), arg);
    if (optopt) return vp_cli_die(2, "pack: unknown option '-%c' (see vdbpack pack --help)", optopt);
    if (!strncmp(arg, "--", 2)) {
        size_t n = strcspn(arg + 2, "=");
        char cands[512] = "";
        int k = 0;
        for (const struct option *lo = PACK_OPTIONS; lo->name; lo++)
            if (n && !strncmp(lo->name, arg + 2, n)) {
                size_t at = strlen(cands);
                snprintf(cands + at, sizeof cands - at, "%s--%s", k++ ? ", " : "", lo->name);
            }
        if (k > 1)
            return vp_cli_die(2, "pack: option '%.*s' is ambiguous (%s)", (int)n + 2, arg, cands);
    }
    return vp_cli_die(2, "pack: unknown option '%s' (see vdbpack pack --help)", arg);
}

static int fields_option(int c, const char *v, pack_fields *f);
static int check_field_options(pack_opts *o, int have_radius, const unsigned char *given);
static void container_params(const pack_opts *o, vp_container_params *cp);

/* One option (id c, value v, NULL for flags) into o. */
static int take_option(int c, const char *v, pack_opts *o, int *have_radius, int *have_count) {
    switch (c) {
    case OPT_OUTPUT: o->output = v; break;
    case OPT_FORMAT: o->format = v; break;
    case OPT_METHOD:
        if (strcmp(v, "lattice") != 0 && strcmp(v, "rsa") != 0 && strcmp(v, "relax") != 0 &&
            strcmp(v, "jam") != 0)
            return vp_cli_die(2, "pack: unknown --method '%s' (lattice, rsa, relax, jam)", v);
        o->method = v;
        break;
    case OPT_SHAPE: {
        int sr = vp_shape_parse_param(v, &o->shape, &o->shape_param);
        if (sr == -2)
            return vp_cli_die(2, "pack: --shape '%s': a superball's exponent P "
                                 "(superball:P) must be a number in [0.5, 1000] (convex "
                                 "superballs; concave ones, P < 0.5, are not offered)", v);
        if (sr != 0) {
            /* not a built-in name: a mesh file, when it looks like one */
            if (!strchr(v, '.') && !strchr(v, '/'))
                return vp_cli_die(2, "pack: unknown --shape '%s' (sphere, a platonic or "
                                     "Archimedean solid such as cube or truncated-octahedron "
                                     "(vdbpack pack --help lists them), superball:P, "
                                     "or a closed mesh file such as shape.obj)", v);
            o->shape = VP_SHAPE_MESH;
            o->shape_file = v;
        }
        break;
    }
    case OPT_ORIENT:
        if (!strcmp(v, "random")) o->orient = VP_ORIENT_RANDOM;
        else if (!strcmp(v, "fixed")) o->orient = VP_ORIENT_FIXED;
        else return vp_cli_die(2, "pack: unknown --orient '%s' (random, fixed)", v);
        break;
    case OPT_OVERLAP:
        if (!strcmp(v, "exact")) o->overlap = VP_OVERLAP_EXACT;
        else if (!strcmp(v, "bbox")) o->overlap = VP_OVERLAP_BBOX;
        else return vp_cli_die(2, "pack: unknown --overlap '%s' (exact, bbox)", v);
        break;
    case OPT_LATTICE:
        if (vp_lattice_parse(v, &o->lattice) != 0)
            return vp_cli_die(2, "pack: unknown --lattice '%s' (sc, bcc, fcc, hcp, densest)", v);
        break;
    case OPT_RADIUS:
        o->radius_text = v; /* a number, or a distribution for rsa/relax: see below */
        *have_radius = 1;
        break;
    case OPT_COUNT:
        if (!strcmp(v, "max")) {
            o->count_max = 1;
        } else if (vp_cli_parse_u64(v, &o->count) != 0 || o->count == 0) {
            return vp_cli_die(2, "pack: --count must be a whole number > 0%s, not '%s'",
                              " (or max with --method rsa)", v);
        }
        *have_count = 1;
        break;
    case OPT_PASS: {
        if (o->npasses >= VP_MAX_GROUPS)
            return vp_cli_die(2, "pack: at most %d --pass options", VP_MAX_GROUPS);
        int rc = vp_cli_parse_pass(v, &o->passes[o->npasses], o->pass_mesh_file[o->npasses],
                                   sizeof o->pass_mesh_file[o->npasses]);
        if (rc) return rc;
        if (o->passes[o->npasses].own_shape) o->pass_shapes = 1;
        o->npasses++;
        break;
    }
    case OPT_RETRIES:
        if (vp_cli_parse_u64(v, &o->retries) != 0 || o->retries == 0 || o->retries > 1000000000)
            return vp_cli_die(2, "pack: --retries must be a whole number in 1..1e9, not '%s'", v);
        break;
    case OPT_GROW: o->grow = 1; break;
    case OPT_TARGET_FRACTION:
        if (vp_cli_parse_double(v, &o->target_fraction) != 0 || !(o->target_fraction > 0) ||
            !(o->target_fraction < 1))
            return vp_cli_die(2, "pack: --target-fraction must be a number in (0, 1), not '%s'",
                              v);
        break;
    case OPT_TOLERANCE:
        if (vp_cli_parse_double(v, &o->tolerance) != 0 || !(o->tolerance > 0) ||
            !(o->tolerance < 0.1))
            return vp_cli_die(2, "pack: --tolerance must be a number in (0, 0.1), not '%s'", v);
        break;
    case OPT_FIT:
        if (!strcmp(v, "inside")) o->fit = VP_FIT_INSIDE;
        else if (!strcmp(v, "center") || !strcmp(v, "centre")) o->fit = VP_FIT_CENTER;
        else return vp_cli_die(2, "pack: unknown --fit '%s' (inside, center)", v);
        break;
    case OPT_OFFSETS:
        if (vp_cli_parse_u64(v, &o->offsets) != 0 || o->offsets == 0 || o->offsets > 1000000)
            return vp_cli_die(2, "pack: --offsets must be a whole number in 1..1000000, not '%s'",
                              v);
        break;
    case OPT_ROTATE: o->rotate = 1; break;
    case OPT_ROTATIONS:
        if (vp_cli_parse_u64(v, &o->rotations) != 0 || o->rotations == 0 ||
            o->rotations > 100000)
            return vp_cli_die(2, "pack: --rotations must be a whole number in 1..100000, not "
                                 "'%s'", v);
        o->rotate = 1;
        break;
    case OPT_SEED:
        if (vp_cli_parse_u64(v, &o->seed) != 0)
            return vp_cli_die(2, "pack: --seed must be a whole number >= 0, not '%s'", v);
        break;
    case OPT_VOXEL_SIZE:
        if (vp_cli_parse_double(v, &o->voxel_size) != 0 || !(o->voxel_size > 0))
            return vp_cli_die(2, "pack: --voxel-size must be a positive number, not '%s'", v);
        break;
    case OPT_ALLOW_OPEN:
        return vp_cli_die(2, "pack: --allow-open was removed in 0.2.0: an open mesh now gets "
                             "the inside its winding number gives (--inside auto, the "
                             "default; --inside winding forces it); see CHANGELOG.md");
    case OPT_INSIDE:
        if (vp_inside_parse(v, &o->inside) != 0)
            return vp_cli_die(2, "pack: unknown --inside '%s' (auto, closed, winding)", v);
        o->inside_set = 1;
        break;
    case OPT_ISO:
        if (vp_cli_parse_double(v, &o->iso) != 0)
            return vp_cli_die(2, "pack: --iso must be a number, not '%s'", v);
        o->has_iso = 1;
        break;
    case OPT_GRID: o->grid = v; break;
    case OPT_PRECISION:
        if (!strcmp(v, "full") || !strcmp(v, "float")) o->full_precision = 1;
        else if (!strcmp(v, "fixed16") || !strcmp(v, "16")) o->full_precision = 0;
        else return vp_cli_die(2, "pack: unknown --precision '%s' (fixed16, full)", v);
        o->precision_set = 1;
        break;
    case OPT_SAVE_CONTAINER: o->save_container = v; break;
    case OPT_SHAPE_OUT: o->shape_out = v; break;
    case OPT_PREVIEW: {
        int rc = vp_cli_preview_path_check("pack: --preview", v);
        if (rc) return rc;
        o->preview = v;
        break;
    }
    case OPT_THREADS:
        if (vp_cli_parse_u64(v, &o->threads) != 0 || o->threads == 0 || o->threads > 256)
            return vp_cli_die(2, "pack: --threads must be a whole number in 1..256, not '%s'", v);
        break;
    case OPT_MAX_MEMORY:
        if (vp_cli_parse_size(v, &o->max_memory) != 0)
            return vp_cli_die(2, "pack: --max-memory must be a size such as 8G or 500M, not "
                                 "'%s'", v);
        break;
    case OPT_JSON: o->json = 1; break;
    case OPT_QUIET: o->quiet = 1; break;
    case OPT_ALLOW_SHORT: o->allow_short = 1; break;
    case OPT_PROGRESS: o->progress = 1; break;
    case OPT_MASK:
    case OPT_RADIUS_FIELD:
    case OPT_DENSITY_FIELD:
    case OPT_RADIUS_FIELD_MODE: return fields_option(c, v, &o->fields);
    case OPT_MARGIN:
    case OPT_GAP: {
        double *x = c == OPT_MARGIN ? &o->margin : &o->gap;
        if (vp_cli_parse_double(v, x) != 0 || !(*x >= 0))
            return vp_cli_die(2, "pack: --%s must be a distance >= 0 (world units), not '%s'",
                              option_name(c), v);
        break;
    }
    default: break;
    }
    return 0;
}

static int take_container(pack_opts *o, const char *a) {
    if (o->container)
        return vp_cli_die(2, "pack: more than one container given ('%s' and '%s')", o->container,
                          a);
    o->container = a;
    return 0;
}

/* getopt_long refuses an abbreviation that several long options start
 * with; where all of them start with the shortest (--rad: --radius,
 * --radius-field, --radius-field-mode) it means that one, as it did before
 * the longer ones came. A malloc'd "--radius[=VALUE]", or NULL: arg as is. */
static char *shortest_prefix_option(const char *arg) {
    if (strncmp(arg, "--", 2) != 0 || !arg[2]) return NULL;
    size_t n = strcspn(arg + 2, "=");
    const struct option *best = NULL;
    for (const struct option *lo = PACK_OPTIONS; lo->name; lo++) {
        if (strncmp(lo->name, arg + 2, n) != 0) continue;
        if (strlen(lo->name) == n) return NULL; /* the option itself */
        if (!best || strlen(lo->name) < strlen(best->name)) best = lo;
    }
    if (!best) return NULL;
    size_t bl = strlen(best->name);
    for (const struct option *lo = PACK_OPTIONS; lo->name; lo++)
        if (!strncmp(lo->name, arg + 2, n) && strncmp(lo->name, best->name, bl) != 0)
            return NULL; /* ambiguous: getopt_long says so */
    size_t k = 2 + bl + strlen(arg + 2 + n) + 1;
    char *s = malloc(k);
    if (s) snprintf(s, k, "--%s%s", best->name, arg + 2 + n);
    return s;
}

/* optarg as the user typed it. getopt takes values from args, where
 * shortest_prefix_option may have rewritten an argument (owned[i], freed
 * after parsing): a whole argument taken as a value (-o --d: the file
 * "--d") is the original argv[i]; a value after '=' is the same last
 * characters of the original, which the rewrite copied. */
static const char *typed_value(const char *v, char *const *owned, char *const *orig, int n) {
    for (int i = 0; v && i < n; i++) {
        if (!owned[i] || v < owned[i] || v > owned[i] + strlen(owned[i])) continue;
        return v == owned[i] ? orig[i] : orig[i] + strlen(orig[i]) - strlen(v);
    }
    return v;
}

static int parse_pack(int argc, char **argv, pack_opts *o) {
    memset(o, 0, sizeof *o);
    o->method = "lattice";
    o->shape = VP_SHAPE_SPHERE;
    o->orient = -1;
    o->overlap = -1;
    o->lattice = VP_LATTICE_DEFAULT;
    o->fit = VP_FIT_INSIDE;
    o->seed = 1;
    int have_radius = 0, have_count = 0;
    vp_cli_seen seen = {0};
    unsigned char given[OPT_LAST - OPT_FORMAT] = {0};
    /* getopt_long on a copy from "pack" on: argv itself (the command line
     * the file records) stays as given. "-" first: arguments in order, the
     * container as option 1; ":" a missing value as ':' */
    int n = argc - 1;
    char **args = malloc((size_t)(n + 1) * sizeof *args);
    if (!args) return vp_cli_die(1, "out of memory");
    memcpy(args, argv + 1, (size_t)n * sizeof *args);
    args[n] = NULL;
    char **owned = calloc((size_t)n + 1, sizeof *owned);
    if (!owned) {
        free(args);
        return vp_cli_die(1, "out of memory");
    }
    for (int i = 0; i < n && strcmp(args[i], "--") != 0; i++)
        if ((owned[i] = shortest_prefix_option(args[i])) != NULL) args[i] = owned[i];
    optind = 0; /* a full re-initialisation (glibc): parse_pack may run more than once */
    opterr = 0;
    int rc = 0, c, idx;
    while (!rc && (c = getopt_long(n, args, "-:o:qh", PACK_OPTIONS, &idx)) != -1) {
        const char *v = typed_value(optarg, owned, argv + 1, n);
        if (c == '?' || c == ':') {
            rc = option_error(c, args[optind - 1]);
        } else if (c == 1) {
            rc = take_container(o, v);
        } else {
            if (c >= OPT_FORMAT) given[c - OPT_FORMAT] = 1;
            /* every value option once, but --pass (one per pass); -o and
             * --output are one option */
            if (v && c != OPT_PASS) {
                /* as typed: -o, or the long name (an abbreviation in full);
                 * vp_cli_once keeps the pointer: a string that stays */
                const char *opt_arg = optarg == args[optind - 1] ? args[optind - 2] : args[optind - 1];
                const char *typed = c == OPT_OUTPUT && opt_arg[1] != '-' ? "-o" : dashed_name(c);
                rc = vp_cli_once(&seen, "pack", typed, v);
            }
            if (!rc) rc = take_option(c, v, o, &have_radius, &have_count);
        }
    }
    for (int i = optind; !rc && i < n; i++) rc = take_container(o, args[i]); /* after -- */
    free(args);
    for (int i = 0; i < n; i++) free(owned[i]);
    free(owned);
    if (rc) return rc;
    if (!o->container || !*o->container)
        return vp_cli_die(2, "pack: no container given (see vdbpack pack --help)");
    if (!o->output) return vp_cli_die(2, "pack: no output given: use -o OUT.vdb");
    rc = vp_cli_output_format("pack", o->output, o->format, &o->out_format);
    if (rc) return rc;
    if (o->shape_out && vp_format_from_path(o->shape_out) != VP_FORMAT_OBJ)
        return vp_cli_die(2, "pack: --shape-out writes OBJ: give a name ending in .obj, not '%s'",
                          o->shape_out);
    if (o->save_container && vp_format_from_path(o->save_container) != VP_FORMAT_VDB)
        return vp_cli_die(2, "pack: --save-container writes a .vdb: give a name ending in .vdb, "
                             "not '%s'", o->save_container);
    /* every file written must be distinct from the others and from the
     * files read (the container, a --shape mesh): a TD would lose one */
    const char *outs[4] = {o->output, o->save_container, o->shape_out, o->preview};
    const char *names[4] = {"-o", "--save-container", "--shape-out", "--preview"};
    const char *ins[5] = {o->container, o->shape_file,
                          o->fields.mask.text ? o->fields.mask.path : NULL,
                          o->fields.radius.text ? o->fields.radius.path : NULL,
                          o->fields.density.text ? o->fields.density.path : NULL};
    const char *inames[5] = {"the container", "the --shape mesh", "the --mask",
                             "the --radius-field", "the --density-field"};
    for (int i = 0; i < 4; i++) {
        if (!outs[i]) continue;
        for (int k = 0; k < 5; k++)
            if (ins[k] && vp_cli_same_file(outs[i], ins[k]))
                return vp_cli_die(2, "pack: %s %s is %s itself: writing would replace it",
                                  names[i], outs[i], inames[k]);
        for (int k = 0; k < i; k++)
            if (outs[k] && vp_cli_same_file(outs[i], outs[k]))
                return vp_cli_die(2, "pack: %s and %s name the same file (%s)", names[k],
                                  names[i], outs[i]);
    }
    rc = check_option_methods(o, given);
    if (rc) return rc;
    rc = check_method_options(o, have_radius, have_count);
    if (rc) return rc;
    rc = check_field_options(o, have_radius, given);
    if (rc) return rc;
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

static const char *kind_name(vp_container_kind k) {
    return k == VP_CONTAINER_MESH ? "mesh" : k == VP_CONTAINER_LEVEL_SET ? "level_set" : "analytic";
}

/* What a method produced, for metadata and the summary. */
typedef struct run_result {
    vp_lattice_report lat;
    vp_rsa_report rsa;
    vp_relax_report relax;
    vp_jam_report jam;
    double pack_seconds;
    double max_radius;
} run_result;

static const char *lattice_label(const pack_opts *o) {
    return vp_lattice_name(o->lattice == VP_LATTICE_DEFAULT
                               ? (o->shape == VP_SHAPE_SPHERE ? VP_LATTICE_FCC : VP_LATTICE_DENSEST)
                               : o->lattice);
}

static const char *stop_name(vp_rsa_stop s) {
    return s == VP_RSA_STOP_COUNT ? "count" : s == VP_RSA_STOP_RETRIES ? "retries" : "maximal";
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

/* The passes that placed fewer than they asked for (a maximal pass never
 * does): how many, and the totals asked and placed over them. */
static int shortfall(const pack_opts *o, const vp_rsa_report *r, size_t *asked, size_t *placed) {
    int n = 0;
    *asked = *placed = 0;
    if (strcmp(o->method, "rsa") != 0) return 0;
    for (size_t i = 0; i < r->npasses; i++) {
        if (o->passes[i].maximal || r->passes[i].placed >= r->passes[i].requested) continue;
        n++;
        *asked += r->passes[i].requested;
        *placed += r->passes[i].placed;
    }
    return n;
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
    return vp_cli_die(2, "pack: --margin %g%s leave%s no room in %s, whose inradius is %g", o->margin,
                      r > 0 ? " and the smallest radius" : "", r > 0 ? "" : "s", o->container, in);
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
    return vp_cli_die(1, "pack: %llu spheres of radius %s fill %.3g times the container's volume, "
                         "more than %s; use fewer or smaller spheres (or leave out --radius: jam "
                         "then finds the radius)", (unsigned long long)o->count, o->radius_text,
                      v / ci->volume, equal ? "equal spheres can fill (0.7405)" : "it has");
}

/* A radius that a .vdb cannot hold (positions to within VP_POSITION_ERROR_LIMIT
 * of it): one line naming the radius, before the packing's work. */
static int vdb_radius_check(const pack_opts *o, const vp_container_info *ci, double r) {
    if (o->out_format != VP_FORMAT_VDB || !(r > 0)) return 0;
    double m = 0;
    for (int k = 0; k < 3; k++) m = fmax(m, fmax(fabs(ci->bmin[k]), fabs(ci->bmax[k])));
    double least = vp_points_min_radius(m);
    if (r >= least) return 0;
    return vp_cli_die(2, "pack: radius %g is too small for a .vdb: OpenVDB's points grid stores "
                         "positions%s only to within %.3g, more than %g of it (radii from %.3g "
                         "fit); write .csv or .ply instead, or scale the scene up",
                      r, m > 536870912.0 * VP_POINTS_MIN_VOXEL ? " this far from the origin" : "",
                      least * VP_POSITION_ERROR_LIMIT, VP_POSITION_ERROR_LIMIT, least);
}

/* --- fields and masks: options, loading, checks (docs/fields.md) ---------- */

/* FILE.vdb:GRID into the file and the grid's name (after the last ".vdb:",
 * so that a path holding colons stays whole); other names whole. */
static int split_field(const char *opt, const char *v, field_arg *a) {
    a->text = v;
    a->grid = NULL;
    const char *cut = NULL;
    for (const char *q = v; *q; q++)
        if (!strncasecmp(q, ".vdb:", 5)) cut = q;
    size_t n = cut ? (size_t)(cut + 4 - v) : strlen(v);
    if (!n) return vp_cli_die(2, "pack: %s needs a file name (FILE.vdb[:GRID])", opt);
    if (n >= sizeof a->path) return vp_cli_die(2, "pack: %s: the file name is too long", opt);
    memcpy(a->path, v, n);
    a->path[n] = 0;
    if (cut) {
        a->grid = cut + 5;
        if (!*a->grid)
            return vp_cli_die(2, "pack: %s '%s': give the grid's name after the colon, or no "
                                 "colon (the first float grid)", opt, v);
    }
    return 0;
}

static int fields_option(int c, const char *v, pack_fields *f) {
    switch (c) {
    case OPT_MASK: return split_field("--mask", v, &f->mask);
    case OPT_RADIUS_FIELD: return split_field("--radius-field", v, &f->radius);
    case OPT_DENSITY_FIELD: return split_field("--density-field", v, &f->density);
    case OPT_RADIUS_FIELD_MODE:
        if (vp_field_mode_parse(v, &f->mode) != 0)
            return vp_cli_die(2, "pack: unknown --radius-field-mode '%s' (scale, absolute)", v);
        f->mode_set = 1;
        return 0;
    default: return 0;
    }
}

/* The fields' options against the rest (after check_method_options). */
static int check_field_options(pack_opts *o, int have_radius, const unsigned char *given) {
    pack_fields *f = &o->fields;
    if (f->mode_set && !f->radius.text)
        return vp_cli_die(2, "pack: --radius-field-mode goes with --radius-field");
    if (!f->radius.text && !f->density.text) return 0;
    if (o->shape != VP_SHAPE_SPHERE)
        return vp_cli_die(2, "pack: --radius-field and --density-field pack spheres in this "
                             "version, not --shape %s",
                          o->shape_file ? o->shape_file : vp_shape_name(o->shape));
    if (o->pass_shapes)
        return vp_cli_die(2, "pack: --radius-field and --density-field pack spheres in this "
                             "version, not passes with a shape= of their own");
    for (int i = 0; i < o->npasses; i++)
        if (o->passes[i].grow)
            return vp_cli_die(2, "pack: grow does not go with --radius-field or --density-field");
    if (f->radius.text && f->mode == VP_FIELD_ABSOLUTE) {
        if (have_radius)
            return vp_cli_die(2, "pack: --radius-field-mode absolute: the field is the radius; "
                                 "leave out --radius (scale, the default, multiplies it)");
        if (given[OPT_TARGET_FRACTION - OPT_FORMAT] && !strcmp(o->method, "rsa"))
            return vp_cli_die(2, "pack: --radius-field-mode absolute: the field is the radius; "
                                 "--target-fraction does not go with it");
        /* the passes' radius is not used: the field's largest value sizes
         * the container's band (set once the field is read) */
        if (!strcmp(o->method, "rsa")) {
            o->rsa_count_radius = 0;
            o->target_fraction = 0;
        }
        for (int i = 0; i < o->npasses; i++) vp_size_dist_constant(&o->passes[i].radius, 1.0);
    }
    return 0;
}

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
                return vp_cli_die(1, "%s: the radius field has no positive value (largest %g); "
                                     "radii must be positive", f->radius.path, fi.max);
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
        return vp_cli_die(2, "pack: malformed analytic --mask '%s' (sphere:R or box:X,Y,Z with "
                             "positive sizes)", f->mask.text);
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
        return vp_cli_die(1, "pack: --mask %s: its level set holds distances only %g outside "
                             "it, and the particles need %g (radius and margin); give a mask "
                             "with a wider exterior band", f->mask.text, mi.interior_band, need);
    return 0;
}

/* The fields against the container they drive (its inside covered,
 * radii positive, a density not negative), each named by its file. */
static int check_fields(vp_context *ctx, pack_opts *o, const vp_container *c) {
    pack_fields *f = &o->fields;
    if (f->radius_field &&
        vp_field_check(ctx, f->radius_field, f->radius.text, "radius field", 1, c, &f->rmin,
                       &f->rmax) != VP_OK)
        return lib_error(ctx);
    if (f->density_field &&
        vp_field_check(ctx, f->density_field, f->density.text, "density field", 0, c, NULL,
                       NULL) != VP_OK)
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
        cp->particle_radius = o->fields.mode == VP_FIELD_SCALE ? cp->particle_radius * fi.max
                                                               : fi.max;
        return;
    }
    cp->particle_radius *= k;
    cp->space_per_particle /= k * k * k;
}

/* The fields in the summary: one line each. */
static void summary_fields(const pack_opts *o) {
    const pack_fields *f = &o->fields;
    if (f->mask.text) printf("  mask: %s (no particle inside it)\n", f->mask.text);
    if (f->radius.text)
        printf("  radius field: %s (%s), %.6g to %.6g over the container\n", f->radius.text,
               vp_field_mode_name(f->mode), f->rmin, f->rmax);
    if (f->density.text) printf("  density field: %s\n", f->density.text);
}

/* The fields in --json (rsa). */
static void json_fields(const pack_opts *o) {
    const pack_fields *f = &o->fields;
    if (f->radius.text) {
        printf(",\"radius_field\":");
        vp_cli_json_string(stdout, f->radius.text);
        printf(",\"radius_field_mode\":\"%s\",\"radius_field_min\":%.17g,"
               "\"radius_field_max\":%.17g", vp_field_mode_name(f->mode), f->rmin, f->rmax);
    }
    if (f->density.text) {
        printf(",\"density_field\":");
        vp_cli_json_string(stdout, f->density.text);
    }
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

static vp_result run_method(vp_context *ctx, const vp_container *c, pack_opts *o,
                            vp_particles **p, run_result *rr) {
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

/* Per pass, what was asked (which = 0: the count, or "max") or placed
 * (1), comma-separated in pass order, for metadata ("20000,max"). */
static void counts_text(const pack_opts *o, const vp_rsa_report *r, int which, char *out,
                        size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (size_t i = 0; i < r->npasses && at < outlen; i++) {
        int n = !which && o->passes[i].maximal
                    ? snprintf(out + at, outlen - at, "%smax", i ? "," : "")
                    : snprintf(out + at, outlen - at, "%s%zu", i ? "," : "",
                               which ? r->passes[i].placed : r->passes[i].requested);
        if (n < 0) break;
        at += (size_t)n;
    }
}

/* The --pass options as text, for metadata ("count=N,radius=R;..."). */
static void passes_text(const pack_opts *o, char *out, size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (int i = 0; i < o->npasses && at + 1 < outlen; i++) {
        const vp_rsa_pass *ps = &o->passes[i];
        char sz[256], cnt[32];
        vp_size_dist_format(&ps->radius, sz, sizeof sz);
        if (ps->maximal) snprintf(cnt, sizeof cnt, "max");
        else snprintf(cnt, sizeof cnt, "%zu", ps->count);
        char sh[300] = "";
        if (ps->own_shape && ps->shape.shape == VP_SHAPE_MESH)
            snprintf(sh, sizeof sh, ",shape=%.280s", o->pass_mesh_file[i]);
        else if (ps->own_shape)
            vp_shape_format(ps->shape.shape, ps->shape.param,
                            sh + snprintf(sh, sizeof sh, ",shape="), sizeof sh - 7);
        int n = snprintf(out + at, outlen - at, "%scount=%s,radius=%s,retries=%d%s%s%s%s",
                         i ? ";" : "", cnt, sz, ps->retries ? ps->retries : VP_RSA_DEFAULT_RETRIES,
                         ps->grow ? ",grow" : "", ps->name[0] ? ",name=" : "", ps->name, sh);
        if (n < 0) break;
        at += (size_t)n;
        if (at >= outlen) break;
    }
}

/* A lattice --count whose radius (estimated: about "about ") is below
 * float's smallest normal value, which pscale cannot hold: exit 2. */
static int count_radius_too_small(const pack_opts *o, const char *about, double r) {
    return vp_cli_die(2, "pack: --count %llu in %s gives a radius of %s%g, below 1.2e-38 (radii "
                         "are stored as float): ask for fewer particles",
                      (unsigned long long)o->count, o->container, about, r);
}

/* A mixed set's particles per shape (counts[shape_index]); its shapes'
 * names in names (split from vp_particles_shape_list). */
static void shape_counts(const vp_particles *p, size_t *counts, char names[][300]) {
    char list[4096];
    vp_particles_shape_list(p, list, sizeof list);
    unsigned k = 0;
    for (char *a = list, *b; k < p->shape_count && k < VP_MAX_SHAPES; a = b + 1) {
        b = strchr(a, ';');
        if (b) *b = 0;
        snprintf(names[k++], 300, "%.299s", a);
        if (!b) break;
    }
    for (; k < VP_MAX_SHAPES; k++) names[k][0] = 0;
    memset(counts, 0, VP_MAX_SHAPES * sizeof *counts);
    for (size_t i = 0; i < p->count; i++) counts[p->shape_index[i]]++;
}

static void print_json(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                       const run_result *rr, const vp_write_report *w, double fraction,
                       int threads, double seconds) {
    printf("{\"command\":\"pack\",\"container\":");
    vp_cli_json_string(stdout, o->container);
    printf(",\"container_kind\":\"%s\",\"container_volume\":%.17g", kind_name(ci->kind),
           ci->volume);
    if (o->fields.mask.text) {
        printf(",\"mask\":");
        vp_cli_json_string(stdout, o->fields.mask.text);
    }
    printf(",\"voxel_size\":%.17g,\"voxel_reason\":", ci->voxel_size);
    vp_cli_json_string(stdout, ci->voxel_reason);
    printf(",\"grid\":");
    vp_cli_json_string(stdout, ci->grid_name);
    printf(",\"mesh_triangles\":%zu,\"boundary_edges\":%zu,\"nonmanifold_edges\":%zu",
           ci->mesh_triangles, ci->boundary_edges, ci->nonmanifold_edges);
    if (ci->kind == VP_CONTAINER_MESH) {
        printf(",\"inconsistent_edges\":%zu,\"pieces\":%zu,\"inside\":\"%s\"",
               ci->inconsistent_edges, ci->mesh_pieces,
               ci->inside == VP_INSIDE_WINDING ? "winding" : "closed");
        printf(",\"duplicate_triangles\":%zu,\"opposite_triangles\":%zu,"
               "\"reoriented_triangles\":%zu,\"turned_pieces\":%zu,\"cavities\":%zu",
               ci->duplicate_triangles, ci->opposite_triangles, ci->reoriented_triangles,
               ci->turned_pieces, ci->cavities);
        printf(",\"volume_estimate\":%.17g,\"volume_estimate_kind\":\"%s\","
               "\"volume_mismatch\":%s", ci->volume_estimate,
               ci->volume_estimate_kind == VP_ESTIMATE_MESH_VOLUME ? "mesh_volume" : "winding",
               ci->volume_mismatch ? "true" : "false");
    }
    if (o->has_iso) printf(",\"iso\":%.17g", o->iso);
    printf(",\"method\":\"%s\",\"shape\":\"%s\",\"fit\":\"%s\"", o->method,
           o->shape_text, o->fit == VP_FIT_INSIDE ? "inside" : "center");
    if (o->mesh) {
        printf(",\"shape_file\":");
        vp_cli_json_string(stdout, vp_mesh_shape_name(o->mesh));
        printf(",\"shape_triangles\":%zu", vp_mesh_shape_triangles(o->mesh));
    }
    if (o->mixed) { /* the "shape" attribute's values, in order */
        size_t counts[VP_MAX_SHAPES];
        char names[VP_MAX_SHAPES][300];
        shape_counts(p, counts, names);
        printf(",\"shapes\":[");
        for (unsigned k = 0; k < p->shape_count; k++) {
            printf("%s{\"shape\":", k ? "," : "");
            vp_cli_json_string(stdout, names[k]);
            printf(",\"count\":%zu}", counts[k]);
        }
        printf("]");
    }
    printf(",\"count\":%zu,\"requested_count\":%llu,\"packing_fraction\":%.17g", p->count,
           (unsigned long long)o->count, fraction);
    {
        size_t asked, placed;
        printf(",\"short\":%s", shortfall(o, &rr->rsa, &asked, &placed) ? "true" : "false");
    }
    printf(",\"max_radius\":%.17g", rr->max_radius);
    if (!strcmp(o->method, "lattice")) {
        const vp_lattice_report *l = &rr->lat;
        printf(",\"lattice\":\"%s\",\"radius\":%.17g,\"lattice_fraction\":%.17g", lattice_label(o),
               l->radius, l->lattice_fraction);
        printf(",\"offsets_tried\":%d,\"rotations_tried\":%d,\"radius_iterations\":%d",
               l->offsets_tried, l->rotations_tried, l->radius_iterations);
        printf(",\"offset\":[%.17g,%.17g,%.17g],\"rotation\":[%.17g,%.17g,%.17g,%.17g]",
               l->offset[0], l->offset[1], l->offset[2], l->rotation[0], l->rotation[1],
               l->rotation[2], l->rotation[3]);
    } else if (!strcmp(o->method, "rsa")) {
        if (o->shape != VP_SHAPE_SPHERE)
            printf(",\"orient\":\"%s\",\"overlap\":\"%s\"",
                   o->orient == VP_ORIENT_FIXED ? "fixed" : "random",
                   o->overlap == VP_OVERLAP_BBOX ? "bbox" : "exact");
        if (o->rsa_count_radius)
            printf(",\"target_fraction\":%.17g", o->target_fraction);
        json_fields(o);
        printf(",\"passes\":[");
        for (size_t i = 0; i < rr->rsa.npasses; i++) {
            const vp_rsa_pass_report *pr = &rr->rsa.passes[i];
            char sz[256];
            vp_size_dist_format(&o->passes[i].radius, sz, sizeof sz);
            char psh[300];
            if (o->passes[i].own_shape && o->passes[i].shape.shape == VP_SHAPE_MESH)
                snprintf(psh, sizeof psh, "mesh:%.280s",
                         vp_mesh_shape_name(o->passes[i].shape.mesh));
            else if (o->passes[i].own_shape)
                vp_shape_format(o->passes[i].shape.shape, o->passes[i].shape.param, psh,
                                sizeof psh);
            else
                snprintf(psh, sizeof psh, "%s", o->default_shape_text);
            printf("%s{\"shape\":", i ? "," : "");
            vp_cli_json_string(stdout, psh);
            printf(",\"group\":\"%s\",\"radius\":\"%s\",\"requested\":%zu,\"maximal\":%s,"
                   "\"placed\":%zu,\"stop\":\"%s\",\"tries\":%llu,\"cell_budget_reached\":%s,"
                   "\"short\":%s,\"grow\":%s,\"grow_mean\":%.17g,\"seconds\":%.6f}",
                   p->group_names[i], sz, pr->requested,
                   o->passes[i].maximal ? "true" : "false", pr->placed, stop_name(pr->stop),
                   (unsigned long long)pr->tries, pr->budget_hit ? "true" : "false",
                   !o->passes[i].maximal && pr->placed < pr->requested ? "true" : "false",
                   o->passes[i].grow ? "true" : "false",
                   pr->grow_mean, pr->seconds);
        }
        printf("]");
    } else if (!strcmp(o->method, "jam")) {
        const vp_jam_report *x = &rr->jam;
        printf(",\"radius_scale\":%.17g,\"max_overlap\":%.17g,\"mean_contacts\":%.17g,"
               "\"rattler_fraction\":%.17g,\"core_fraction\":%.17g,\"core_count\":%zu,"
               "\"core_volume\":%.17g,\"minimizations\":%d,\"iterations\":%ld",
               x->radius_scale, x->max_overlap, x->mean_contacts, x->rattler_fraction,
               x->core_fraction, x->core_count, x->core_volume, x->minimizations, x->iterations);
    } else {
        const vp_relax_report *x = &rr->relax;
        printf(",\"sweeps\":%d,\"radius_scale\":%.17g,\"initial_fraction\":%.17g,"
               "\"max_overlap\":%.17g", x->sweeps, x->radius_scale, x->initial_fraction,
               x->max_overlap);
    }
    if (strcmp(o->method, "rsa") != 0) json_fields(o); /* (rsa: with its passes) */
    if (strcmp(o->method, "lattice") != 0)
        printf(",\"margin\":%.17g,\"gap\":%.17g", o->margin, o->gap);
    printf(",\"seed\":%llu,\"threads\":%d,\"pack_seconds\":%.6f,\"seconds\":%.6f,\"output\":",
           (unsigned long long)o->seed, threads, rr->pack_seconds, seconds);
    vp_cli_json_string(stdout, o->output);
    if (o->out_format == VP_FORMAT_VDB)
        printf(",\"position_precision\":\"%s\",\"precision_promoted\":%s,"
               "\"position_error\":%.17g", w->full_precision ? "full" : "fixed16",
               w->promoted ? "true" : "false", w->position_error);
    printf("}\n");
}

static void print_summary(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                          const run_result *rr, const vp_write_report *w, double fraction,
                          double seconds) {
    char what[96];
    vp_cli_shape_count(what, sizeof what, p->count, o->shape);
    if (!strcmp(o->method, "lattice"))
        printf("vdbpack: packed %s (radius %.6g) on %s in %s\n", what, rr->lat.radius,
               lattice_label(o), o->container);
    else
        printf("vdbpack: packed %s%s%s%s%s by %s in %s\n", what, o->mesh ? " (" : "",
               o->mesh ? vp_mesh_shape_name(o->mesh) : "", o->mesh ? ")" : "",
               o->shape == VP_SHAPE_SPHERE ? ""
               : o->overlap == VP_OVERLAP_BBOX ? " (fixed orientation, bounding-box overlap)"
               : o->orient == VP_ORIENT_FIXED  ? " (fixed orientation, exact overlap)"
                                               : " (random orientations, exact overlap)",
               !strcmp(o->method, "rsa")   ? "random sequential addition"
               : !strcmp(o->method, "jam") ? "jamming (random close packing)"
                                           : "relaxation",
               o->container);
    if (o->mixed) {
        size_t counts[VP_MAX_SHAPES];
        char names[VP_MAX_SHAPES][300];
        shape_counts(p, counts, names);
        printf("  shapes:");
        for (unsigned k = 0; k < p->shape_count; k++) {
            vp_shape_ref r = p->shapes[k];
            char what_k[96];
            vp_cli_shape_count(what_k, sizeof what_k, counts[k], r.shape);
            printf("%s %s", k ? "," : "", what_k);
            if (r.shape == VP_SHAPE_MESH || r.shape == VP_SHAPE_SUPERBALL)
                printf(" (%s)", r.shape == VP_SHAPE_MESH ? vp_mesh_shape_name(r.mesh) : names[k]);
            printf(" [shape %u]", k);
        }
        printf("\n");
    }
    if (ci->kind == VP_CONTAINER_MESH)
        vp_cli_print_mesh_container(stdout, ci);
    else if (ci->kind == VP_CONTAINER_LEVEL_SET)
        printf("  container: level set '%s', %zu active voxels, volume %.6g\n", ci->grid_name,
               ci->active_voxels, ci->volume);
    else
        printf("  container: analytic, volume %.6g\n", ci->volume);
    if (ci->voxel_size > 0) printf("  voxel size %.6g: %s\n", ci->voxel_size, ci->voxel_reason);
    summary_fields(o);
    if (o->margin > 0 || o->gap > 0)
        printf("  kept apart: margin %g from the wall, gap %g between surfaces\n", o->margin,
               o->gap);
    if (!strcmp(o->method, "lattice")) {
        const vp_lattice_report *l = &rr->lat;
        printf("  placement: %d offsets tried over %d orientation%s", l->offsets_tried,
               l->rotations_tried, l->rotations_tried == 1 ? "" : "s");
        if (o->count) {
            printf(", %d %s tried for --count %llu", l->radius_iterations,
                   l->radius_iterations == 1 ? "radius" : "radii", (unsigned long long)o->count);
            double off = fabs((double)l->count - (double)o->count);
            if (off > 0.02 * (double)o->count)
                printf(" (%zu is the closest count found: with few particles, or layers "
                       "in a box, the count jumps as the radius changes)",
                       l->count);
        }
        printf("\n  packing fraction %.4f (the infinite lattice: %.4f)\n", fraction,
               l->lattice_fraction);
    } else if (!strcmp(o->method, "rsa")) {
        if (o->rsa_count_radius)
            printf("  radius %.6g: %llu of them fill %.3g of the container (--target-fraction)\n",
                   vp_size_dist_max(&o->passes[0].radius), (unsigned long long)o->count,
                   o->target_fraction);
        for (size_t i = 0; i < rr->rsa.npasses; i++) {
            const vp_rsa_pass_report *pr = &rr->rsa.passes[i];
            char sz[256];
            vp_size_dist_format(&o->passes[i].radius, sz, sizeof sz);
            printf("  %s: radius %s, placed %zu", p->group_names[i], sz, pr->placed);
            if (o->passes[i].maximal && pr->stop == VP_RSA_STOP_MAXIMAL)
                printf(" (maximal: no room left)");
            else if (o->passes[i].maximal && (o->fields.radius_field || o->fields.density_field))
                printf(" (with a field, count=max ends after %d failed tries in a row, see "
                       "docs/fields.md)",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (o->passes[i].maximal && o->shape != VP_SHAPE_SPHERE)
                printf(" (maximal mode for %s: stopped by %d failed tries in a row, see "
                       "docs/rsa.md)", o->mixed ? "several shapes" : "solids",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (o->passes[i].maximal)
                printf(" (maximal mode stopped by %d failed tries in a row: refining the empty "
                       "space further would exceed its memory budget)",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (pr->stop == VP_RSA_STOP_RETRIES)
                printf(" of %zu (stopped: %d failed tries in a row)", pr->requested,
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (pr->stop == VP_RSA_STOP_MAXIMAL && pr->placed < pr->requested)
                printf(" of %zu (stopped: no room left for another)", pr->requested);
            else
                printf(" of %zu", pr->requested);
            if (o->passes[i].grow) printf(", grown by %.3fx on average", pr->grow_mean);
            printf(", %.2f s\n", pr->seconds);
        }
        printf("  packing fraction %.4f%s\n", fraction,
               fraction > 1.0 ? " (over 1: with --fit center the wall does not hold the "
                                "particles, nor their growth)"
                              : "");
    } else if (!strcmp(o->method, "jam")) {
        const vp_jam_report *x = &rr->jam;
        printf("  jamming: %d minimisations, %ld FIRE steps; radii scaled by %.6g; largest "
               "overlap %.3g of r_i + r_j\n", x->minimizations, x->iterations, x->radius_scale,
               x->max_overlap);
        printf("  contacts: Z = %.3f over non-rattlers, rattlers %.1f %%\n", x->mean_contacts,
               100.0 * x->rattler_fraction);
        if (x->core_count)
            printf("  packing fraction %.4f (core, 5 diameters from the wall: %.4f over %zu "
                   "spheres)\n", fraction, x->core_fraction, x->core_count);
        else
            printf("  packing fraction %.4f (no core 5 diameters from the wall)\n", fraction);
    } else {
        const vp_relax_report *x = &rr->relax;
        printf("  relaxation: %d sweeps, radii scaled by %.4f, largest overlap %.3g of r_i + r_j\n",
               x->sweeps, x->radius_scale, x->max_overlap);
        printf("  packing fraction %.4f (%.4f before relaxation)\n", fraction,
               x->initial_fraction);
    }
    if (o->out_format == VP_FORMAT_VDB && w->promoted)
        vp_cli_print_promoted(w);
    printf("  wrote %s in %.2f s (packing %.2f s)\n", o->output, seconds, rr->pack_seconds);
}

static int malformed_analytic(const char *spec) {
    return vp_cli_die(2, "pack: malformed analytic container '%s' (sphere:R or box:X,Y,Z with "
                         "positive sizes)", spec);
}

int vp_cli_pack_parse_only(int argc, char **argv) {
    pack_opts o;
    int rc = parse_pack(argc, argv, &o);
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

int vp_cli_pack(int argc, char **argv) {
    pack_opts o;
    int rc = parse_pack(argc, argv, &o);
    if (rc) return rc;
    vp_shape_format(o.shape, o.shape_param, o.shape_text, sizeof o.shape_text);
    double t0 = now();
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    if (!o.threads && getenv("VDBPACK_THREADS")) {
        const char *e = getenv("VDBPACK_THREADS");
        if (vp_cli_parse_u64(e, &o.threads) != 0 || o.threads == 0 || o.threads > 256) {
            vp_context_destroy(ctx);
            return vp_cli_die(2, "pack: VDBPACK_THREADS must be a whole number in 1..256, not "
                                 "'%s'", e);
        }
    }
    if (o.threads) vp_context_set_threads(ctx, (int)o.threads);
    if (o.max_memory) vp_context_set_max_memory(ctx, o.max_memory);
    progress prog;
    memset(&prog, 0, sizeof prog);
    prog.ctx = ctx;
    prog.start = now();
    prog.lines = o.progress;
    prog.bar = !o.progress && !o.quiet && !o.json && isatty(2);
    prog.phase = "starting";
    vp_context_set_progress(ctx, on_progress, &prog);
    vp_cli_signals_install();

    int status = 1;
    vp_container *c = NULL;
    vp_particles *p = NULL;
    vp_mesh_shape *mesh = NULL;
    const char *created[2] = {NULL, NULL};
    int ncreated = 0;

    /* the particle shape first: a bad shape file fails before a long
     * voxelization */
    if (o.shape == VP_SHAPE_MESH) {
        if (vp_mesh_shape_load(ctx, o.shape_file, &mesh) != VP_OK) {
            status = lib_error(ctx);
            goto done;
        }
        o.mesh = mesh;
    }
    if ((status = load_pass_shapes(ctx, &o)) != 0) goto done;
    if ((status = load_fields(ctx, &o)) != 0) goto done;
    status = 1;
    int an = vp_cli_analytic_container(ctx, o.container, &c);
    if (an == -2) {
        status = vp_cli_die(2, "pack: %s", vp_context_message(ctx));
        goto done;
    }
    if (an < 0) {
        status = malformed_analytic(o.container);
        goto done;
    }
    if (an == 0) {
        vp_container_params cp;
        container_params(&o, &cp);
        progress_phase(&prog, "loading", 0.3);
        if (vp_container_load(ctx, o.container, &cp, &c) != VP_OK) {
            status = lib_error(ctx);
            goto done;
        }
    } else if (o.voxel_size > 0 || o.grid || o.save_container || o.inside_set || o.has_iso) {
        status = vp_cli_die(2, "pack: --voxel-size, --grid, --inside, --iso and --save-container "
                               "need a mesh or .vdb container, not '%s'", o.container);
        goto done;
    }

    if ((status = apply_mask(ctx, &o, &c)) != 0) goto done;
    if ((status = check_fields(ctx, &o, c)) != 0) goto done;
    status = 1;
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    if (!o.quiet) vp_cli_warn_container(&ci);
    /* a mesh this small packs (voxelized in scaled units), but OpenVDB's
     * transforms cannot hold its level set in a file: said before packing */
    if (o.save_container && ci.voxel_size > 0 && ci.voxel_size < VP_POINTS_MIN_VOXEL) {
        status = vp_cli_die(2, "pack: --save-container %s: the container's voxel size %g is "
                               "below the smallest a .vdb can hold (%g); give --voxel-size %g "
                               "or more, or scale the mesh up", o.save_container,
                            ci.voxel_size, VP_POINTS_MIN_VOXEL, VP_POINTS_MIN_VOXEL);
        goto done;
    }
    if (o.rsa_count_radius) {
        double r = rsa_count_radius(&o, &ci);
        if (!(r >= FLT_MIN) || !(r <= FLT_MAX)) {
            status = count_radius_too_small(&o, "", r);
            goto done;
        }
        vp_size_dist_constant(&o.passes[0].radius, r);
        if (o.gap > 0 && !(o.gap < r)) {
            status = vp_cli_die(2, "pack: --gap %g must be smaller than the radius %g that "
                                   "--count %llu gives", o.gap, r, (unsigned long long)o.count);
            goto done;
        }
    }
    if ((status = margin_check(&o, &ci)) != 0) goto done;
    if (!strcmp(o.method, "lattice") && o.count && !(lattice_count_radius(&o, &ci) >= FLT_MIN)) {
        status = count_radius_too_small(&o, "about ", lattice_count_radius(&o, &ci));
        goto done;
    }
    if ((status = vdb_radius_check(&o, &ci, smallest_radius(&o, &ci))) != 0) goto done;
    if ((status = jam_count_check(&o, &ci)) != 0) goto done;
    status = 1;

    run_result rr;
    /* what is left: packing, then writing (and a preview) */
    progress_phase(&prog, "packing", o.preview ? 0.8 : 0.9);
    if (run_method(ctx, c, &o, &p, &rr) != VP_OK) {
        status = lib_error(ctx);
        goto done;
    }
    if (!strcmp(o.method, "lattice") && !(rr.lat.radius >= FLT_MIN)) {
        status = count_radius_too_small(&o, "", rr.lat.radius);
        goto done;
    }
    if (o.mesh) snprintf(o.default_shape_text, sizeof o.default_shape_text, "mesh:%.280s",
                         vp_mesh_shape_name(o.mesh));
    else snprintf(o.default_shape_text, sizeof o.default_shape_text, "%s", o.shape_text);
    if (o.pass_shapes) { /* the shapes are those the passes made */
        o.mixed = p->shape == VP_SHAPE_MIXED;
        o.shape = p->shape;
        o.shape_param = p->shape_param;
        o.mesh = p->mesh;
        if (o.mixed) snprintf(o.shape_text, sizeof o.shape_text, "mixed");
        else vp_shape_format(o.shape, o.shape_param, o.shape_text, sizeof o.shape_text);
    }
    double fraction = ci.volume > 0 ? vp_particles_volume(p) / ci.volume : 0.0;

    if (o.save_container) {
        if (vp_container_save(ctx, o.fields.base ? o.fields.base : c, o.save_container) !=
            VP_OK) {
            status = lib_error(ctx);
            goto done;
        }
        created[ncreated++] = o.save_container;
        vp_cli_signals_track_output(o.save_container);
    }
    if (o.shape_out) {
        if ((o.mixed  ? vp_particles_write_shapes_obj(ctx, p, o.shape_out)
             : o.mesh ? vp_mesh_shape_write_obj(ctx, o.mesh, o.shape_out)
                      : vp_shape_write_obj_param(ctx, o.shape, o.shape_param, o.shape_out)) !=
            VP_OK) {
            status = lib_error(ctx);
            goto done;
        }
        created[ncreated++] = o.shape_out;
        vp_cli_signals_track_output(o.shape_out);
    }

    char cmdline[4096], method_params[4096] = "";
    char requested_text[VP_MAX_GROUPS * 24] = "", placed_text[VP_MAX_GROUPS * 24] = "";
    size_t short_asked = 0, short_placed = 0;
    int nshort = shortfall(&o, &rr.rsa, &short_asked, &short_placed);
    join_args(argc, argv, cmdline, sizeof cmdline);
    const char *cname = strrchr(o.container, '/');
    cname = cname ? cname + 1 : o.container;
    vp_meta meta[40] = {
        {"creator", VP_META_STRING, "vdbpack " VP_VERSION_STRING, 0, 0},
        {"command_line", VP_META_STRING, cmdline, 0, 0},
        {"seed", VP_META_INT, NULL, (int64_t)o.seed, 0},
        {"method", VP_META_STRING, o.method, 0, 0},
        {"shape", VP_META_STRING, o.shape_text, 0, 0},
        {"fit", VP_META_STRING, o.fit == VP_FIT_INSIDE ? "inside" : "center", 0, 0},
        {"container", VP_META_STRING, cname, 0, 0},
        {"particle_count", VP_META_INT, NULL, (int64_t)p->count, 0},
        {"max_radius", VP_META_DOUBLE, NULL, 0, rr.max_radius},
        {"container_volume", VP_META_DOUBLE, NULL, 0, ci.volume},
        {"packing_fraction", VP_META_DOUBLE, NULL, 0, fraction},
        {"voxel_size", VP_META_DOUBLE, NULL, 0, ci.voxel_size},
    };
    size_t nmeta = 12;
    if (o.mesh) meta[nmeta++] = (vp_meta){"shape_file", VP_META_STRING, vp_mesh_shape_name(o.mesh), 0, 0};
    char shape_list[4096];
    if (o.mixed)
        meta[nmeta++] = (vp_meta){"shapes", VP_META_STRING,
                                  vp_particles_shape_list(p, shape_list, sizeof shape_list), 0, 0};
    if (ci.kind == VP_CONTAINER_MESH)
        meta[nmeta++] = (vp_meta){"inside", VP_META_STRING, vp_inside_name(o.inside), 0, 0};
    if (o.has_iso) meta[nmeta++] = (vp_meta){"iso", VP_META_DOUBLE, NULL, 0, o.iso};
    if (o.fields.mask.text)
        meta[nmeta++] = (vp_meta){"mask", VP_META_STRING, o.fields.mask.text, 0, 0};
    if (o.fields.mask_voxel > 0)
        meta[nmeta++] = (vp_meta){"mask_voxel_size", VP_META_DOUBLE, NULL, 0, o.fields.mask_voxel};
    if (o.fields.radius.text) {
        meta[nmeta++] = (vp_meta){"radius_field", VP_META_STRING, o.fields.radius.text, 0, 0};
        meta[nmeta++] = (vp_meta){"radius_field_mode", VP_META_STRING,
                                  vp_field_mode_name(o.fields.mode), 0, 0};
    }
    if (o.fields.density.text)
        meta[nmeta++] = (vp_meta){"density_field", VP_META_STRING, o.fields.density.text, 0, 0};
    if (!strcmp(o.method, "lattice")) {
        meta[nmeta++] = (vp_meta){"lattice", VP_META_STRING, lattice_label(&o), 0, 0};
        meta[nmeta++] = (vp_meta){"radius", VP_META_DOUBLE, NULL, 0, rr.lat.radius};
    } else if (!strcmp(o.method, "rsa")) {
        passes_text(&o, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"passes", VP_META_STRING, method_params, 0, 0};
        counts_text(&o, &rr.rsa, 0, requested_text, sizeof requested_text);
        counts_text(&o, &rr.rsa, 1, placed_text, sizeof placed_text);
        meta[nmeta++] = (vp_meta){"requested", VP_META_STRING, requested_text, 0, 0};
        meta[nmeta++] = (vp_meta){"placed", VP_META_STRING, placed_text, 0, 0};
        meta[nmeta++] = (vp_meta){"short", VP_META_INT, NULL, nshort > 0, 0};
        if (o.rsa_count_radius)
            meta[nmeta++] = (vp_meta){"target_fraction", VP_META_DOUBLE, NULL, 0,
                                      o.target_fraction};
        if (o.shape != VP_SHAPE_SPHERE) {
            meta[nmeta++] = (vp_meta){"orient", VP_META_STRING,
                                      o.orient == VP_ORIENT_FIXED ? "fixed" : "random", 0, 0};
            meta[nmeta++] = (vp_meta){"overlap", VP_META_STRING,
                                      o.overlap == VP_OVERLAP_BBOX ? "bbox" : "exact", 0, 0};
        }
    } else if (!strcmp(o.method, "jam")) {
        vp_size_dist_format(&o.sizes, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"radius", VP_META_STRING, method_params, 0, 0};
        meta[nmeta++] = (vp_meta){"radius_scale", VP_META_DOUBLE, NULL, 0, rr.jam.radius_scale};
        meta[nmeta++] = (vp_meta){"max_overlap", VP_META_DOUBLE, NULL, 0, rr.jam.max_overlap};
        meta[nmeta++] = (vp_meta){"mean_contacts", VP_META_DOUBLE, NULL, 0, rr.jam.mean_contacts};
        meta[nmeta++] = (vp_meta){"rattler_fraction", VP_META_DOUBLE, NULL, 0,
                                  rr.jam.rattler_fraction};
        meta[nmeta++] = (vp_meta){"core_fraction", VP_META_DOUBLE, NULL, 0, rr.jam.core_fraction};
    } else {
        vp_size_dist_format(&o.sizes, method_params, sizeof method_params);
        meta[nmeta++] = (vp_meta){"radius", VP_META_STRING, method_params, 0, 0};
        meta[nmeta++] = (vp_meta){"target_fraction", VP_META_DOUBLE, NULL, 0, o.target_fraction};
        meta[nmeta++] = (vp_meta){"radius_scale", VP_META_DOUBLE, NULL, 0, rr.relax.radius_scale};
        meta[nmeta++] = (vp_meta){"max_overlap", VP_META_DOUBLE, NULL, 0, rr.relax.max_overlap};
    }
    /* what `vdbpack check` then holds the file to by default */
    if (o.margin > 0) meta[nmeta++] = (vp_meta){"margin", VP_META_DOUBLE, NULL, 0, o.margin};
    if (o.gap > 0) meta[nmeta++] = (vp_meta){"gap", VP_META_DOUBLE, NULL, 0, o.gap};
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.full_precision = o.full_precision;
    wp.meta = meta;
    wp.meta_count = nmeta;
    vp_write_report wrep;
    memset(&wrep, 0, sizeof wrep);
    wp.report = &wrep;
    progress_phase(&prog, "writing", o.preview ? 0.5 : 1.0);
    if (vp_cli_write_particles(ctx, o.output, o.out_format, p, &wp, o.quiet) != 0) {
        status = lib_error(ctx);
        goto done;
    }
    if (vp_cli_interrupted()) {
        vp_cli_signals_track_output(o.output);
        status = vp_cli_interrupted_exit();
        goto done;
    }
    if (o.preview) {
        /* the preview is part of the job: if it fails, no output stays */
        vp_cli_signals_track_output(o.output);
        progress_phase(&prog, "preview", 1.0);
        if (vp_cli_render_particles(ctx, p, NULL, o.preview) != 0) {
            vp_remove_output(o.output);
            status = lib_error(ctx);
            goto done;
        }
        vp_cli_signals_track_output(o.preview);
        if (vp_cli_interrupted()) {
            status = vp_cli_interrupted_exit();
            goto done;
        }
    }
    vp_cli_signals_done();
    ncreated = 0; /* success: keep every output */
    double seconds = now() - t0;
    if (prog.shown) fprintf(stderr, "\r%*s\r", 96, "");
    progress_end(&prog);

    if (o.json)
        print_json(&o, &ci, p, &rr, &wrep, fraction, vp_context_threads(ctx), seconds);
    else if (!o.quiet)
        print_summary(&o, &ci, p, &rr, &wrep, fraction, seconds);
    /* the summary or JSON asked for and lost (stdout on a full disk): an
     * error, and an error leaves no output */
    status = vp_cli_flush_stdout(0);
    if (status) {
        const char *outs[4] = {o.output, o.save_container, o.shape_out, o.preview};
        for (int i = 0; i < 4; i++)
            if (outs[i]) vp_remove_output(outs[i]);
    } else if (nshort) {
        /* packed, but short: the file stays, a script sees it */
        if (!o.quiet)
            fprintf(stderr, "vdbpack: warning: packed, but short: placed %zu of the %zu "
                            "particles asked for in %d %s; %s\n", short_placed, short_asked,
                    nshort, nshort == 1 ? "pass" : "passes",
                    o.allow_short ? "exit status 0 (--allow-short)"
                                  : "exit status 4 (--allow-short makes it 0)");
        if (!o.allow_short) status = VP_CLI_EXIT_SHORT;
    }

done:
    for (int i = 0; i < ncreated; i++) vp_remove_output(created[i]);
    if (prog.shown && status) fprintf(stderr, "\r%*s\r", 96, "");
    vp_particles_destroy(p);
    vp_mesh_shape_destroy(mesh);
    for (int i = 0; i < o.npasses; i++) vp_mesh_shape_destroy(o.pass_mesh[i]);
    vp_container_destroy(c);
    vp_container_destroy(o.fields.base); /* (after c, which borrows them) */
    vp_container_destroy(o.fields.mask_c);
    vp_field_destroy(o.fields.radius_field);
    vp_field_destroy(o.fields.density_field);
    vp_context_destroy(ctx);
    return status;
}

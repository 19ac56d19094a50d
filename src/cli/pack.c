/* `vdbpack pack`: options, container, packer, outputs and the summary. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"

typedef struct pack_opts {
    const char *container;
    const char *output;
    const char *method;
    vp_shape shape;
    vp_lattice lattice;
    vp_fit fit;
    double radius;
    uint64_t count;
    uint64_t offsets;
    int rotate;
    uint64_t rotations;
    uint64_t seed;
    double voxel_size;
    int allow_open;
    const char *grid;
    int full_precision;
    const char *save_container;
    const char *shape_out;
    uint64_t threads;
    uint64_t max_memory;
    int json;
    int quiet;
} pack_opts;

/* --- progress bar (stderr, only on a terminal, only for long work) ------- */

typedef struct progress {
    double start;
    int shown;
} progress;

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int on_progress(void *user, double fraction, const char *stage) {
    progress *p = user;
    if (now() - p->start < 0.5) return 1;
    int w = 30, filled = (int)(fraction * w + 0.5);
    if (filled > w) filled = w;
    if (filled < 0) filled = 0;
    fprintf(stderr, "\r[%.*s%*s] %3d%% %-24s", filled, "##############################",
            w - filled, "", (int)(fraction * 100 + 0.5), stage);
    fflush(stderr);
    p->shown = 1;
    return 1;
}

/* --- option parsing -------------------------------------------------------- */

static int need_value(int argc, char **argv, int *i, const char **val) {
    if (*i + 1 >= argc) return vp_cli_die(2, "pack: %s needs a value", argv[*i]);
    *val = argv[++*i];
    return 0;
}

static int parse_pack(int argc, char **argv, pack_opts *o) {
    memset(o, 0, sizeof *o);
    o->method = "lattice";
    o->shape = VP_SHAPE_SPHERE;
    o->lattice = VP_LATTICE_DEFAULT;
    o->fit = VP_FIT_INSIDE;
    o->seed = 1;
    int have_radius = 0, have_count = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        int rc = 0;
#define VALUE() do { if ((rc = need_value(argc, argv, &i, &v)) != 0) return rc; } while (0)
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            VALUE();
            o->output = v;
        } else if (!strcmp(a, "--method")) {
            VALUE();
            if (strcmp(v, "lattice") != 0) {
                if (!strcmp(v, "rsa") || !strcmp(v, "relax"))
                    return vp_cli_die(2, "pack: --method %s is not available in this version "
                                         "(only lattice)", v);
                return vp_cli_die(2, "pack: unknown --method '%s' (lattice)", v);
            }
            o->method = v;
        } else if (!strcmp(a, "--shape")) {
            VALUE();
            if (vp_shape_parse(v, &o->shape) != 0)
                return vp_cli_die(2, "pack: unknown --shape '%s' (sphere, tetrahedron, cube, "
                                     "octahedron, dodecahedron, icosahedron)", v);
        } else if (!strcmp(a, "--lattice")) {
            VALUE();
            if (vp_lattice_parse(v, &o->lattice) != 0)
                return vp_cli_die(2, "pack: unknown --lattice '%s' (sc, bcc, fcc, hcp, densest)",
                                  v);
        } else if (!strcmp(a, "--radius")) {
            VALUE();
            if (vp_cli_parse_double(v, &o->radius) != 0 || !(o->radius > 0))
                return vp_cli_die(2, "pack: --radius must be a positive number, not '%s'", v);
            have_radius = 1;
        } else if (!strcmp(a, "--count")) {
            VALUE();
            if (vp_cli_parse_u64(v, &o->count) != 0 || o->count == 0)
                return vp_cli_die(2, "pack: --count must be a whole number > 0, not '%s'", v);
            have_count = 1;
        } else if (!strcmp(a, "--fit")) {
            VALUE();
            if (!strcmp(v, "inside")) o->fit = VP_FIT_INSIDE;
            else if (!strcmp(v, "center") || !strcmp(v, "centre")) o->fit = VP_FIT_CENTER;
            else return vp_cli_die(2, "pack: unknown --fit '%s' (inside, center)", v);
        } else if (!strcmp(a, "--offsets")) {
            VALUE();
            if (vp_cli_parse_u64(v, &o->offsets) != 0 || o->offsets == 0 || o->offsets > 1000000)
                return vp_cli_die(2, "pack: --offsets must be a whole number in 1..1000000, "
                                     "not '%s'", v);
        } else if (!strcmp(a, "--rotate")) {
            o->rotate = 1;
        } else if (!strcmp(a, "--rotations")) {
            VALUE();
            if (vp_cli_parse_u64(v, &o->rotations) != 0 || o->rotations == 0 ||
                o->rotations > 100000)
                return vp_cli_die(2, "pack: --rotations must be a whole number in 1..100000, "
                                     "not '%s'", v);
            o->rotate = 1;
        } else if (!strcmp(a, "--seed")) {
            VALUE();
            if (vp_cli_parse_u64(v, &o->seed) != 0)
                return vp_cli_die(2, "pack: --seed must be a whole number >= 0, not '%s'", v);
        } else if (!strcmp(a, "--voxel-size")) {
            VALUE();
            if (vp_cli_parse_double(v, &o->voxel_size) != 0 || !(o->voxel_size > 0))
                return vp_cli_die(2, "pack: --voxel-size must be a positive number, not '%s'", v);
        } else if (!strcmp(a, "--allow-open")) {
            o->allow_open = 1;
        } else if (!strcmp(a, "--grid")) {
            VALUE();
            o->grid = v;
        } else if (!strcmp(a, "--precision")) {
            VALUE();
            if (!strcmp(v, "full") || !strcmp(v, "float")) o->full_precision = 1;
            else if (!strcmp(v, "fixed16") || !strcmp(v, "16")) o->full_precision = 0;
            else return vp_cli_die(2, "pack: unknown --precision '%s' (fixed16, full)", v);
        } else if (!strcmp(a, "--save-container")) {
            VALUE();
            o->save_container = v;
        } else if (!strcmp(a, "--shape-out")) {
            VALUE();
            o->shape_out = v;
        } else if (!strcmp(a, "--threads")) {
            VALUE();
            if (vp_cli_parse_u64(v, &o->threads) != 0 || o->threads == 0 || o->threads > 256)
                return vp_cli_die(2, "pack: --threads must be a whole number in 1..256, not '%s'",
                                  v);
        } else if (!strcmp(a, "--max-memory")) {
            VALUE();
            if (vp_cli_parse_size(v, &o->max_memory) != 0)
                return vp_cli_die(2, "pack: --max-memory must be a size such as 8G or 500M, "
                                     "not '%s'", v);
        } else if (!strcmp(a, "--json")) {
            o->json = 1;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            return vp_cli_die(2, "pack: unknown option '%s' (see vdbpack pack --help)", a);
        } else if (!o->container) {
            o->container = a;
        } else {
            return vp_cli_die(2, "pack: more than one container given ('%s' and '%s')",
                              o->container, a);
        }
#undef VALUE
    }
    if (!o->container) return vp_cli_die(2, "pack: no container given (see vdbpack pack --help)");
    if (!o->output) return vp_cli_die(2, "pack: no output given: use -o OUT.vdb");
    if (have_radius && have_count)
        return vp_cli_die(2, "pack: give either --radius or --count, not both");
    if (!have_radius && !have_count)
        return vp_cli_die(2, "pack: give the particle size with --radius R or --count N");
    if (o->shape == VP_SHAPE_SPHERE && o->lattice == VP_LATTICE_DENSEST) o->lattice = VP_LATTICE_FCC;
    if (o->shape != VP_SHAPE_SPHERE && o->lattice != VP_LATTICE_DEFAULT &&
        o->lattice != VP_LATTICE_DENSEST)
        return vp_cli_die(2, "pack: --lattice %s is for spheres; a %s packs on its densest "
                             "lattice (--lattice densest)", vp_lattice_name(o->lattice),
                          vp_shape_name(o->shape));
    return 0;
}

/* sphere:R or box:X,Y,Z (centred at the origin); 1 if it is one, -1 if
 * malformed, 0 if not analytic. */
static int analytic_container(vp_context *ctx, const char *spec, vp_container **out) {
    struct stat st;
    if (stat(spec, &st) == 0) return 0; /* a file of that name wins */
    double c[3] = {0, 0, 0};
    if (!strncmp(spec, "sphere:", 7)) {
        double r;
        if (vp_cli_parse_double(spec + 7, &r) != 0 || !(r > 0)) return -1;
        return vp_container_create_sphere(ctx, c, r, out) == VP_OK ? 1 : -1;
    }
    if (!strncmp(spec, "box:", 4)) {
        char buf[256];
        snprintf(buf, sizeof buf, "%s", spec + 4);
        double e[3];
        char *save = NULL, *tok = strtok_r(buf, ",", &save);
        int n = 0;
        while (tok && n < 3) {
            if (vp_cli_parse_double(tok, &e[n]) != 0 || !(e[n] > 0)) return -1;
            n++;
            tok = strtok_r(NULL, ",", &save);
        }
        if (n != 3 || tok) return -1;
        double lo[3] = {-e[0] / 2, -e[1] / 2, -e[2] / 2}, hi[3] = {e[0] / 2, e[1] / 2, e[2] / 2};
        return vp_container_create_box(ctx, lo, hi, out) == VP_OK ? 1 : -1;
    }
    return 0;
}

static void join_args(int argc, char **argv, char *out, size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (int i = 0; i < argc && at + 4 < outlen; i++) {
        const char *a = argv[i];
        int quote = strpbrk(a, " \t'\"$") != NULL || !*a;
        int n = snprintf(out + at, outlen - at, quote ? "%s'%s'" : "%s%s", i ? " " : "", a);
        if (n < 0) break;
        at += (size_t)n;
        if (at >= outlen) { at = outlen - 1; break; }
    }
}

static const char *kind_name(vp_container_kind k) {
    return k == VP_CONTAINER_MESH ? "mesh" : k == VP_CONTAINER_LEVEL_SET ? "level_set" : "analytic";
}

int vp_cli_pack(int argc, char **argv) {
    pack_opts o;
    int rc = parse_pack(argc, argv, &o);
    if (rc) return rc;
    double t0 = now();
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    if (o.threads) vp_context_set_threads(ctx, (int)o.threads);
    if (o.max_memory) vp_context_set_max_memory(ctx, o.max_memory);
    progress prog = {now(), 0};
    if (!o.quiet && !o.json && isatty(2)) vp_context_set_progress(ctx, on_progress, &prog);

    int status = 1;
    vp_container *c = NULL;
    vp_particles *p = NULL;
    const char *created[2] = {NULL, NULL};
    int ncreated = 0;

    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.shape = o.shape;
    lp.lattice = o.lattice;
    lp.fit = o.fit;
    lp.radius = o.radius;
    lp.count = (size_t)o.count;
    lp.offsets = (int)o.offsets;
    lp.rotate = o.rotate;
    lp.rotations = (int)o.rotations;
    lp.seed = o.seed;

    int an = analytic_container(ctx, o.container, &c);
    if (an < 0) {
        status = vp_cli_die(2, "pack: malformed analytic container '%s' (sphere:R or box:X,Y,Z "
                               "with positive sizes)", o.container);
        goto done;
    }
    if (an == 0) {
        vp_container_params cp;
        vp_container_params_init(&cp);
        cp.voxel_size = o.voxel_size;
        cp.allow_open = o.allow_open;
        cp.grid_name = o.grid;
        cp.particle_radius = o.radius;
        cp.particle_count = (size_t)o.count;
        /* space one particle takes: shape volume / lattice fraction */
        {
            static const double frac[VP_SHAPE_COUNT] = {0.74048, 18.0 / 49.0, 1.0, 18.0 / 19.0,
                                                        0.904508, 0.836357};
            double f = frac[o.shape];
            if (o.shape == VP_SHAPE_SPHERE) {
                if (o.lattice == VP_LATTICE_SC) f = 0.5236;
                else if (o.lattice == VP_LATTICE_BCC) f = 0.6802;
            }
            cp.space_per_particle = vp_shape_unit_volume(o.shape) / f;
        }
        if (vp_container_load(ctx, o.container, &cp, &c) != VP_OK) {
            status = vp_cli_die(1, "%s", vp_context_message(ctx));
            goto done;
        }
    } else if (o.voxel_size > 0 || o.grid || o.save_container) {
        status = vp_cli_die(2, "pack: --voxel-size, --grid and --save-container need a mesh or "
                               ".vdb container, not '%s'", o.container);
        goto done;
    }

    vp_lattice_report rep;
    if (vp_pack_lattice(ctx, c, &lp, &p, &rep) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    double fraction = ci.volume > 0 ? rep.particle_volume / ci.volume : 0.0;

    if (o.save_container) {
        if (vp_container_save(ctx, c, o.save_container) != VP_OK) {
            status = vp_cli_die(1, "%s", vp_context_message(ctx));
            goto done;
        }
        created[ncreated++] = o.save_container;
    }
    if (o.shape_out) {
        if (vp_shape_write_obj(ctx, o.shape, o.shape_out) != VP_OK) {
            status = vp_cli_die(1, "%s", vp_context_message(ctx));
            goto done;
        }
        created[ncreated++] = o.shape_out;
    }

    char cmdline[4096];
    join_args(argc, argv, cmdline, sizeof cmdline);
    const char *cname = strrchr(o.container, '/');
    cname = cname ? cname + 1 : o.container;
    vp_meta meta[] = {
        {"creator", VP_META_STRING, "vdbpack " VP_VERSION_STRING, 0, 0},
        {"command_line", VP_META_STRING, cmdline, 0, 0},
        {"seed", VP_META_INT, NULL, (int64_t)o.seed, 0},
        {"method", VP_META_STRING, o.method, 0, 0},
        {"shape", VP_META_STRING, vp_shape_name(o.shape), 0, 0},
        {"lattice", VP_META_STRING, vp_lattice_name(o.lattice == VP_LATTICE_DEFAULT
                                                        ? (o.shape == VP_SHAPE_SPHERE
                                                               ? VP_LATTICE_FCC
                                                               : VP_LATTICE_DENSEST)
                                                        : o.lattice), 0, 0},
        {"fit", VP_META_STRING, o.fit == VP_FIT_INSIDE ? "inside" : "center", 0, 0},
        {"container", VP_META_STRING, cname, 0, 0},
        {"particle_count", VP_META_INT, NULL, (int64_t)p->count, 0},
        {"radius", VP_META_DOUBLE, NULL, 0, rep.radius},
        {"container_volume", VP_META_DOUBLE, NULL, 0, ci.volume},
        {"packing_fraction", VP_META_DOUBLE, NULL, 0, fraction},
        {"voxel_size", VP_META_DOUBLE, NULL, 0, ci.voxel_size},
    };
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.full_precision = o.full_precision;
    wp.meta = meta;
    wp.meta_count = sizeof meta / sizeof meta[0];
    if (vp_write_points(ctx, o.output, p, &wp) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    ncreated = 0; /* success: keep every output */
    double seconds = now() - t0;
    if (prog.shown) fprintf(stderr, "\r%*s\r", 64, "");

    const char *lname = vp_lattice_name(o.lattice == VP_LATTICE_DEFAULT
                                            ? (o.shape == VP_SHAPE_SPHERE ? VP_LATTICE_FCC
                                                                          : VP_LATTICE_DENSEST)
                                            : o.lattice);
    if (o.json) {
        printf("{\"command\":\"pack\",\"container\":");
        vp_cli_json_string(stdout, o.container);
        printf(",\"container_kind\":\"%s\",\"container_volume\":%.17g", kind_name(ci.kind),
               ci.volume);
        printf(",\"voxel_size\":%.17g,\"voxel_reason\":", ci.voxel_size);
        vp_cli_json_string(stdout, ci.voxel_reason);
        printf(",\"grid\":");
        vp_cli_json_string(stdout, ci.grid_name);
        printf(",\"mesh_triangles\":%zu,\"boundary_edges\":%zu,\"nonmanifold_edges\":%zu",
               ci.mesh_triangles, ci.boundary_edges, ci.nonmanifold_edges);
        printf(",\"method\":\"%s\",\"shape\":\"%s\",\"lattice\":\"%s\",\"fit\":\"%s\"", o.method,
               vp_shape_name(o.shape), lname, o.fit == VP_FIT_INSIDE ? "inside" : "center");
        printf(",\"radius\":%.17g,\"count\":%zu,\"requested_count\":%llu", rep.radius, p->count,
               (unsigned long long)o.count);
        printf(",\"packing_fraction\":%.17g,\"lattice_fraction\":%.17g", fraction,
               rep.lattice_fraction);
        printf(",\"offsets_tried\":%d,\"rotations_tried\":%d,\"radius_iterations\":%d",
               rep.offsets_tried, rep.rotations_tried, rep.radius_iterations);
        printf(",\"offset\":[%.17g,%.17g,%.17g],\"rotation\":[%.17g,%.17g,%.17g,%.17g]",
               rep.offset[0], rep.offset[1], rep.offset[2], rep.rotation[0], rep.rotation[1],
               rep.rotation[2], rep.rotation[3]);
        printf(",\"seed\":%llu,\"threads\":%d,\"pack_seconds\":%.6f,\"seconds\":%.6f,\"output\":",
               (unsigned long long)o.seed, vp_context_threads(ctx), rep.seconds, seconds);
        vp_cli_json_string(stdout, o.output);
        printf("}\n");
    } else if (!o.quiet) {
        printf("vdbpack: packed %zu %s%s (radius %.6g) on %s in %s\n", p->count,
               vp_shape_name(o.shape), p->count == 1 ? "" : "s", rep.radius, lname, o.container);
        if (ci.kind == VP_CONTAINER_MESH)
            printf("  container: mesh, %zu triangles (%zu vertices after welding %zu), "
                   "level-set volume %.6g (mesh volume %.6g)\n",
                   ci.mesh_triangles, ci.mesh_vertices, ci.mesh_vertices_raw, ci.volume,
                   ci.mesh_volume);
        else if (ci.kind == VP_CONTAINER_LEVEL_SET)
            printf("  container: level set '%s', %zu active voxels, volume %.6g\n", ci.grid_name,
                   ci.active_voxels, ci.volume);
        else
            printf("  container: analytic, volume %.6g\n", ci.volume);
        if (ci.voxel_size > 0)
            printf("  voxel size %.6g: %s\n", ci.voxel_size, ci.voxel_reason);
        printf("  placement: %d offsets tried over %d orientation%s", rep.offsets_tried,
               rep.rotations_tried, rep.rotations_tried == 1 ? "" : "s");
        if (o.count) printf(", %d radii tried for --count %llu", rep.radius_iterations,
                            (unsigned long long)o.count);
        printf("\n  packing fraction %.4f (the infinite lattice: %.4f)\n", fraction,
               rep.lattice_fraction);
        printf("  wrote %s in %.2f s (packing %.2f s)\n", o.output, seconds, rep.seconds);
    }
    status = 0;

done:
    for (int i = 0; i < ncreated; i++) unlink(created[i]);
    if (prog.shown && status) fprintf(stderr, "\r%*s\r", 64, "");
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
    return status;
}

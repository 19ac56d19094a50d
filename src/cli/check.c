/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack check FILE.vdb --container C`: recomputes overlaps, particles
 * outside the container, the packing fraction and the mean contact number
 * from the file alone, and exits 3 on a violation. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli/cli.h"

const char *VP_CHECK_HELP =
    "Usage: vdbpack check FILE.vdb --container CONTAINER [options]\n"
    "\n"
    "Verifies the packing in FILE.vdb (its \"points\" grid) against CONTAINER (a\n"
    "mesh, a .vdb level set, sphere:R or box:X,Y,Z) from the file alone: pairs of\n"
    "overlapping particles and the largest overlap, particles outside the\n"
    "container, the packing fraction and the mean contact number. Positions stored\n"
    "to within more than 1e-3 of the smallest radius (a .vdb too coarse to show\n"
    "that particles do not overlap) are a violation too. Exit status: 0 when there\n"
    "is no violation, 3 when there is one, 1 on errors, 2 on usage.\n"
    "\n"
    "  --container C           the container (required)\n"
    "  --fit inside|center     what counts as outside (default: the file's fit\n"
    "                          metadata, else inside)\n"
    "  --overlap-tolerance X   overlaps up to X of r_i + r_j are not violations\n"
    "                          (default 1e-6; widened by twice the file's\n"
    "                          position error)\n"
    "  --contact-tolerance X   gaps up to X of r_i + r_j count as contacts\n"
    "                          (default 1e-3)\n"
    "  --wall-tolerance D      world distance a particle may cross the wall by\n"
    "                          (default: a tenth of the container's voxel)\n"
    "  --margin D              world distance every particle must keep from the\n"
    "                          wall (default: the file's margin metadata, else 0)\n"
    "  --gap G                 world distance between any two sphere surfaces\n"
    "                          (default: the file's gap metadata, else 0)\n"
    "  --voxel-size V          voxel size for a mesh container (default: the\n"
    "                          file's voxel_size metadata, else automatic)\n"
    "  --grid NAME             level-set grid of a .vdb container\n"
    "  --shape FILE            the particle mesh, for packings of a mesh shape\n"
    "                          (the one given to pack --shape; required for them);\n"
    "                          a packing of several shapes: once per mesh shape, in\n"
    "                          the order of its shapes metadata\n"
    "  --inside auto|closed|winding  how the inside of a mesh container is\n"
    "                          decided (default: the packing's, else auto)\n"
    "  --iso V                 a fog or density .vdb container: inside where the\n"
    "                          grid's value is >= V (default: the packing's)\n"
    "  --mask M|none           the mask taken out of the container (pack --mask;\n"
    "                          default: the file's mask metadata); none: no mask\n"
    "  --json                  print the report as JSON on stdout\n"
    "  -q, --quiet             print nothing but errors\n"
    "  -h, --help              this text\n";

/* Finds "key": in the "metadata" object of describe's JSON; returns a
 * pointer to the value text or NULL. */
static const char *meta_value(const char *json, const char *key) {
    const char *m = strstr(json, "\"metadata\":{");
    if (!m) return NULL;
    const char *end = strstr(m, "},\"grids\"");
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *v = strstr(m, pat);
    if (!v || (end && v > end)) return NULL;
    return v + strlen(pat);
}

/* --mask M: M's inside taken out of container *c (as pack --mask does):
 * analytic, a mesh (voxelized at the voxel pack recorded), or a .vdb level
 * set, FILE.vdb[:GRID]. 0, or the exit status after one line. */
static int check_mask(vp_context *ctx, const char *mask, double voxel, vp_container **c,
                      vp_container **base, vp_container **mask_c) {
    vp_container *m = NULL;
    int an = vp_cli_analytic_container(ctx, mask, &m);
    if (an == -2) return vp_cli_die(2, "check: --mask: %s", vp_context_message(ctx));
    if (an < 0)
        return vp_cli_die(2, "check: malformed analytic --mask '%s' (sphere:R or box:X,Y,Z)", mask);
    if (an == 0) {
        char path[4096];
        const char *cut = NULL, *grid = NULL;
        for (const char *q = mask; *q; q++)
            if (!strncasecmp(q, ".vdb:", 5)) cut = q;
        size_t n = cut ? (size_t)(cut + 4 - mask) : strlen(mask);
        if (n >= sizeof path) return vp_cli_die(2, "check: --mask: the file name is too long");
        memcpy(path, mask, n);
        path[n] = 0;
        if (cut && cut[5]) grid = cut + 5;
        vp_container_params kp;
        vp_container_params_init(&kp);
        kp.voxel_size = voxel;
        kp.grid_name = grid;
        if (vp_container_load(ctx, path, &kp, &m) != VP_OK)
            return vp_cli_die(1, "check: --mask: %s", vp_context_message(ctx));
    }
    *mask_c = m;
    vp_container *cm = NULL;
    if (vp_container_subtract(ctx, *c, m, &cm) != VP_OK)
        return vp_cli_die(1, "check: --mask %s: %s", mask, vp_context_message(ctx));
    *base = *c; /* borrowed by cm: freed after it */
    *c = cm;
    return 0;
}

int vp_cli_check(int argc, char **argv) {
    const char *file = NULL, *cont = NULL, *grid = NULL, *mask = NULL;
    const char *shape_files[VP_MAX_SHAPES] = {NULL};
    int nshape_files = 0;
    char mask_meta[4096] = "";
    double mask_voxel = 0;
    int json = 0, quiet = 0, fit_set = 0, inside_set = 0, has_iso = 0;
    int margin_set = 0, gap_set = 0; /* else from the file's metadata */
    vp_inside_mode inside = VP_INSIDE_AUTO;
    double voxel = 0, iso = 0;
    vp_check_params cp;
    vp_check_params_init(&cp);
    vp_cli_seen seen = {0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED()                                                                                     \
    do {                                                                                           \
        if (!v) return vp_cli_die(2, "check: %s needs a value", a);                                \
        if (vp_cli_once(&seen, "check", a, v)) return 2;                                           \
        i++;                                                                                       \
    } while (0)
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(VP_CHECK_HELP, stdout);
            return 0;
        } else if (!strcmp(a, "--container")) {
            NEED();
            cont = v;
        } else if (!strcmp(a, "--fit")) {
            NEED();
            if (!strcmp(v, "inside")) cp.fit = VP_FIT_INSIDE;
            else if (!strcmp(v, "center") || !strcmp(v, "centre")) cp.fit = VP_FIT_CENTER;
            else return vp_cli_die(2, "check: --fit must be inside or center, not '%s'", v);
            fit_set = 1;
        } else if (!strcmp(a, "--overlap-tolerance") || !strcmp(a, "--contact-tolerance") ||
                   !strcmp(a, "--wall-tolerance") || !strcmp(a, "--voxel-size") ||
                   !strcmp(a, "--margin") || !strcmp(a, "--gap")) {
            NEED();
            double x;
            if (vp_cli_parse_double(v, &x) != 0 || x < 0 ||
                (!strcmp(a, "--voxel-size") && !(x > 0)))
                return vp_cli_die(2, "check: %s must be a number %s, not '%s'", a,
                                  strcmp(a, "--voxel-size") ? ">= 0" : "> 0", v);
            if (!strcmp(a, "--overlap-tolerance")) cp.overlap_tolerance = x;
            else if (!strcmp(a, "--contact-tolerance")) cp.contact_tolerance = x;
            else if (!strcmp(a, "--wall-tolerance")) cp.wall_tolerance = x;
            else if (!strcmp(a, "--margin")) cp.margin = x, margin_set = 1;
            else if (!strcmp(a, "--gap")) cp.gap = x, gap_set = 1;
            else voxel = x;
        } else if (!strcmp(a, "--grid")) {
            NEED();
            grid = v;
        } else if (!strcmp(a, "--shape")) { /* once per mesh shape of a mixed set */
            if (!v) return vp_cli_die(2, "check: %s needs a value", a);
            i++;
            if (nshape_files == VP_MAX_SHAPES)
                return vp_cli_die(2, "%s: at most %d --shape options", "check", VP_MAX_SHAPES);
            shape_files[nshape_files++] = v;
        } else if (!strcmp(a, "--mask")) {
            NEED();
            mask = v;
        } else if (!strcmp(a, "--allow-open")) {
            return vp_cli_die(2, "check: --allow-open was removed in 0.2.0: an open mesh now gets "
                                 "the inside its winding number gives (--inside auto, the "
                                 "default); see CHANGELOG.md");
        } else if (!strcmp(a, "--inside")) {
            NEED();
            if (vp_inside_parse(v, &inside) != 0)
                return vp_cli_die(2, "check: unknown --inside '%s' (auto, closed, winding)", v);
            inside_set = 1;
        } else if (!strcmp(a, "--iso")) {
            NEED();
            if (vp_cli_parse_double(v, &iso) != 0)
                return vp_cli_die(2, "check: --iso must be a number, not '%s'", v);
            has_iso = 1;
        } else if (!strcmp(a, "--json")) {
            json = 1;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            return vp_cli_die(2, "check: unknown option '%s' (see vdbpack check --help)", a);
        } else if (!file) {
            file = a;
        } else {
            return vp_cli_die(2, "check: more than one file given ('%s')", a);
        }
#undef NEED
    }
    if (!file || !*file) return vp_cli_die(2, "check: no file given (see vdbpack check --help)");
    if (!cont || !*cont) return vp_cli_die(2, "check: no container given: use --container C");

    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    int status = 1;
    vp_particles *p = NULL;
    vp_container *c = NULL, *base = NULL, *mask_c = NULL;
    vp_mesh_shape *meshes[VP_MAX_SHAPES] = {NULL};
    char *desc = NULL;
    if (vp_read_points(ctx, file, &p) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    /* the packer's choices, from the file's metadata. The points were just
     * read, so a file that cannot be described is a failure to report, not
     * a file without metadata: falling back to the defaults would check
     * a --fit center packing as fit inside */
    if (vp_describe_file(ctx, file, 1, &desc) != VP_OK) {
        status = vp_cli_die(1, "check: cannot read the metadata of %s: %s", file,
                            vp_context_message(ctx));
        goto done;
    }
    {
        const char *f = meta_value(desc, "fit");
        if (f && !fit_set) cp.fit = !strncmp(f, "\"center\"", 8) ? VP_FIT_CENTER : VP_FIT_INSIDE;
        const char *in = meta_value(desc, "inside");
        if (in && !inside_set) {
            char mode[16] = "";
            if (*in == '"') sscanf(in + 1, "%15[^\"]", mode);
            vp_inside_parse(mode, &inside); /* an unknown value keeps auto */
        }
        const char *is = meta_value(desc, "iso");
        /* a fog container's iso; not carried over to another kind */
        if (is && !has_iso && vp_format_from_path(cont) == VP_FORMAT_VDB) {
            double x = strtod(is, NULL);
            if (isfinite(x)) {
                iso = x;
                has_iso = 1;
            }
        }
        /* the distances the packing was asked to keep */
        const char *mg = meta_value(desc, "margin"), *gp = meta_value(desc, "gap");
        if (mg && !margin_set) {
            double x = strtod(mg, NULL);
            if (x >= 0 && isfinite(x)) cp.margin = x;
        }
        if (gp && !gap_set) {
            double x = strtod(gp, NULL);
            if (x >= 0 && isfinite(x)) cp.gap = x;
        }
        /* pack --mask: the mask as given, and the voxel of a mesh mask */
        const char *mk = meta_value(desc, "mask"), *mv = meta_value(desc, "mask_voxel_size");
        if (mk && *mk == '"') sscanf(mk + 1, "%4095[^\"]", mask_meta);
        if (!mask && mask_meta[0]) mask = mask_meta;
        if (mv) {
            double x = strtod(mv, NULL);
            if (x > 0 && isfinite(x)) mask_voxel = x;
        }
        const char *vs = meta_value(desc, "voxel_size");
        if (vs && !(voxel > 0)) {
            double x = strtod(vs, NULL);
            if (x > 0 && isfinite(x)) voxel = x;
        }
    }
    {
        const char *sf = desc ? meta_value(desc, "shape_file") : NULL;
        char name[256] = "";
        if (sf && *sf == '"') sscanf(sf + 1, "%255[^\"]", name);
        if ((status = vp_cli_attach_mesh(ctx, "check", file, name, shape_files, nshape_files, p,
                                         meshes)) != 0)
            goto done;
        status = 1;
    }
    double rmax = p->uniform_radius;
    if (p->radii)
        for (size_t i = 0; i < p->count; i++)
            if (p->radii[i] > rmax) rmax = p->radii[i];
    int an = vp_cli_analytic_container(ctx, cont, &c);
    if (an == -2) {
        status = vp_cli_die(2, "check: %s", vp_context_message(ctx));
        goto done;
    }
    if (an < 0) {
        status = vp_cli_die(2,
                            "check: malformed analytic container '%s' (sphere:R or box:X,Y,Z "
                            "with positive sizes)",
                            cont);
        goto done;
    }
    if (an > 0 && (voxel > 0 || grid || inside_set || has_iso)) {
        status = vp_cli_die(2,
                            "check: --voxel-size, --grid, --inside and --iso need a mesh or "
                            ".vdb container, not '%s'",
                            cont);
        goto done;
    }
    if (an == 0) {
        vp_container_params kp;
        vp_container_params_init(&kp);
        kp.voxel_size = voxel;
        kp.particle_radius = rmax > 0 ? rmax : 0;
        kp.particle_count = p->count;
        kp.inside = inside;
        kp.has_iso = has_iso;
        kp.iso = iso;
        kp.grid_name = grid;
        kp.extra_depth = cp.margin; /* the wall test reads the margin deeper */
        if (vp_container_load(ctx, cont, &kp, &c) != VP_OK) {
            status = vp_cli_die(1, "%s", vp_context_message(ctx));
            goto done;
        }
        vp_container_info ci;
        vp_container_get_info(c, &ci);
        if (!quiet) vp_cli_warn_container(&ci);
    }
    if (mask && strcmp(mask, "none") != 0 &&
        (status = check_mask(ctx, mask, mask_voxel, &c, &base, &mask_c)) != 0)
        goto done;
    status = 1;
    vp_check_report rep;
    if (vp_check_particles(ctx, c, p, &cp, &rep) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    int bad = rep.overlapping_pairs > 0 || rep.outside > 0 || rep.imprecise;
    const char *fit = cp.fit == VP_FIT_INSIDE ? "inside" : "center";
    if (json) {
        printf("{\"file\":");
        vp_cli_json_string(stdout, file);
        printf(",\"container\":");
        vp_cli_json_string(stdout, cont);
        if (mask && strcmp(mask, "none") != 0) {
            printf(",\"mask\":");
            vp_cli_json_string(stdout, mask);
        }
        printf(",\"margin\":%.17g,\"gap\":%.17g", cp.margin, cp.gap);
        printf(",\"fit\":\"%s\",\"shape\":\"%s\",\"count\":%zu,\"overlapping_pairs\":%zu,"
               "\"max_overlap\":%.17g,\"max_overlap_world\":%.17g,\"overlap_tolerance\":%.17g,"
               "\"position_error\":%.17g,\"position_error_ratio\":%.17g,\"imprecise\":%s,"
               "\"outside\":%zu,\"max_outside\":%.17g,"
               "\"particle_volume\":%.17g,\"container_volume\":%.17g,\"packing_fraction\":%.17g,"
               "\"contact_pairs\":%zu,\"mean_contacts\":%.17g,\"contact_tolerance\":%.17g,"
               "\"ok\":%s,\"seconds\":%.6f}\n",
               fit, vp_shape_name(p->shape), rep.count, rep.overlapping_pairs, rep.max_overlap,
               rep.max_overlap_world, cp.overlap_tolerance, p->position_error,
               rep.position_error_ratio, rep.imprecise ? "true" : "false", rep.outside,
               rep.max_outside, rep.particle_volume, rep.container_volume, rep.fraction,
               rep.contact_pairs, rep.mean_contacts, cp.contact_tolerance, bad ? "false" : "true",
               rep.seconds);
    } else if (!quiet) {
        char what[96];
        vp_cli_shape_count(what, sizeof what, rep.count, p->shape);
        printf("vdbpack check %s: %s against %s (fit %s)\n", file, what, cont, fit);
        if (mask && strcmp(mask, "none") != 0) printf("  less the mask %s\n", mask);
        if (cp.margin > 0 || cp.gap > 0)
            printf("  kept apart: margin %.6g from the wall, gap %.6g between surfaces\n",
                   cp.margin, cp.gap);
        printf("  overlaps: %zu pairs beyond %.3g of %s (largest %.3g, %.3g world)\n",
               rep.overlapping_pairs, cp.overlap_tolerance,
               p->shape == VP_SHAPE_SPHERE ? "r_i + r_j" : "the smaller radius", rep.max_overlap,
               rep.max_overlap_world);
        if (rep.imprecise)
            printf("  positions stored to within %.3g (world), %.3g of the smallest radius: "
                   "more than %.3g, too coarse to show that particles do not overlap\n",
                   p->position_error, rep.position_error_ratio, cp.position_tolerance);
        else if (p->position_error > 0)
            printf("  positions stored to within %.3g (world), allowed for above\n",
                   p->position_error);
        printf("  outside the container: %zu (largest excursion %.3g)\n", rep.outside,
               rep.max_outside);
        printf("  packing fraction %.6f (particles %.6g / container %.6g)\n", rep.fraction,
               rep.particle_volume, rep.container_volume);
        printf("  mean contacts %.3f (%zu pairs within %.3g of r_i + r_j)\n", rep.mean_contacts,
               rep.contact_pairs, cp.contact_tolerance);
        printf("  %s\n", bad ? "VIOLATION" : "OK");
    }
    /* the report asked for and lost (stdout on a full disk): an error */
    if ((status = vp_cli_flush_stdout(0)) != 0) goto done;
    if (bad && (quiet || json)) {
        if (rep.imprecise)
            fprintf(stderr,
                    "vdbpack: check: %s: positions stored to within %.3g, %.3g of the "
                    "smallest radius (more than %.3g): too coarse to check; %zu "
                    "overlapping pairs, %zu particles outside\n",
                    file, p->position_error, rep.position_error_ratio, cp.position_tolerance,
                    rep.overlapping_pairs, rep.outside);
        else
            fprintf(stderr, "vdbpack: check: %s: %zu overlapping pairs, %zu particles outside\n",
                    file, rep.overlapping_pairs, rep.outside);
    }
    status = bad ? 3 : 0;
done:
    free(desc);
    vp_particles_destroy(p);
    for (int k = 0; k < VP_MAX_SHAPES; k++) vp_mesh_shape_destroy(meshes[k]);
    vp_container_destroy(c);
    vp_container_destroy(base); /* (after c, which borrows it and the mask) */
    vp_container_destroy(mask_c);
    vp_context_destroy(ctx);
    return status;
}

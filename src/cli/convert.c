/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack convert IN OUT`: a packing from one format to another (.vdb,
 * .ply, .csv in; .vdb, .ply, .csv, .obj out), and the output-format pieces
 * `vdbpack pack -o` shares (choosing the format, the OBJ size warning). */
#include "vdbpack/vdbpack.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

const char *VP_CONVERT_HELP =
    "Usage: vdbpack convert IN OUT [options]\n"
    "\n"
    "Reads the particles of IN (a .vdb with a points grid, or a .ply or .csv as\n"
    "vdbpack writes them) and writes them to OUT, in the format its extension names:\n"
    ".vdb (OpenVDB points), .ply (binary), .csv or .obj (every particle's surface).\n"
    "Ids, positions, pscale, orient, groups and the shape are kept; the metadata\n"
    "of a packing (command line, seed, ...) only in a .vdb written by pack. An\n"
    "input without particles is an error. See docs/export.md.\n"
    "\n"
    "  --format F              OUT's format: vdb, ply, csv or obj (default: by its\n"
    "                          extension)\n"
    "  --shape NAME            the particle shape of a .csv input (CSV does not\n"
    "                          record it; default sphere, required when it has\n"
    "                          orient columns)\n"
    "  --precision fixed16|full  .vdb output: P as 16-bit fixed point or 32-bit float\n"
    "                          (default full; float wherever 16 bits would round by\n"
    "                          over 1e-3 of the smallest radius)\n"
    "  --max-memory SIZE       refuse a .vdb output estimated above SIZE (e.g. 8G;\n"
    "                          default: RAM)\n"
    "  -q, --quiet             print nothing but errors\n"
    "  -h, --help              this text\n";

int vp_cli_output_format(const char *cmd, const char *path, const char *format, int *out) {
    vp_format f = VP_FORMAT_UNKNOWN;
    if (format) {
        if (vp_format_parse(format, &f) != 0)
            return vp_cli_die(2, "%s: unknown --format '%s' (vdb, ply, csv, obj)", cmd, format);
    } else if ((f = vp_format_from_path(path)) == VP_FORMAT_UNKNOWN) {
        return vp_cli_die(2,
                          "%s: cannot tell the format of '%s' from its extension: name it .vdb, "
                          ".ply, .csv or .obj, or give --format",
                          cmd, path);
    }
    *out = (int)f;
    return 0;
}

int vp_cli_write_particles(vp_context *ctx, const char *path, int format, const vp_particles *p,
                           const vp_write_params *wp, int quiet) {
    vp_export_params ep;
    vp_export_params_init(&ep);
    ep.format = (vp_format)format;
    if (wp) ep.vdb = *wp;
    if (format == VP_FORMAT_OBJ && !quiet) {
        double bytes = vp_export_estimate_bytes(p, VP_FORMAT_OBJ, &ep);
        int v = 0, f = 0;
        vp_export_obj_counts(p->shape, ep.sphere_subdivisions, &v, &f);
        if (bytes > VP_CLI_OBJ_WARN_BYTES || p->count > VP_CLI_OBJ_WARN_COUNT)
            fprintf(stderr,
                    "vdbpack: warning: %s: %zu particles of %d vertices and %d faces make "
                    "about %.1f GB of OBJ; .ply or .vdb with instancing is far smaller\n",
                    path, p->count, v, f, bytes / 1e9);
    }
    if (format == VP_FORMAT_PLY && !quiet && p->count) {
        /* PLY positions are absolute 32-bit floats: far from the origin they
         * round by a fair part of a radius, and touching particles overlap
         * in the file (the .vdb stores offsets within voxels, CSV %.17g) */
        double cmax = 0.0, rmin = HUGE_VAL;
        for (size_t i = 0; i < 3 * p->count; i++) cmax = fmax(cmax, fabs(p->positions[i]));
        for (size_t i = 0; i < (p->radii ? p->count : 1); i++)
            rmin = fmin(rmin, p->radii ? (double)p->radii[i] : (double)p->uniform_radius);
        double half_ulp = cmax > 0 ? ldexp(1.0, ilogb(cmax) - 24) : 0.0; /* float rounding */
        /* (past the largest float the writer refuses: that line alone) */
        if (rmin > 0 && cmax <= FLT_MAX && sqrt(3.0) * half_ulp > 1e-4 * rmin)
            fprintf(stderr,
                    "vdbpack: warning: %s: PLY stores positions as 32-bit floats, which "
                    "at coordinates up to %.6g round by up to %.3g (%.2g %% of the "
                    "smallest radius): touching particles may overlap in it; .vdb and "
                    ".csv keep them, or move the container near the origin\n",
                    path, cmax, sqrt(3.0) * half_ulp, 100.0 * sqrt(3.0) * half_ulp / rmin);
    }
    if (vp_export(ctx, path, p, &ep) != VP_OK) return 1;
    vp_cli_divert_stdout(path);
    return 0;
}

void vp_cli_print_promoted(const vp_write_report *w) {
    printf("  P stored as 32-bit float, not 16-bit fixed point: that would round positions by "
           "up to %.3g, %.3g of the smallest radius (more than %g)\n",
           w->fixed16_error, w->min_radius > 0 ? w->fixed16_error / w->min_radius : 0.0,
           VP_POSITION_ERROR_LIMIT);
}

int vp_cli_convert(int argc, char **argv) {
    const char *in = NULL, *out = NULL, *format = NULL, *shape_name = NULL;
    int quiet = 0, full = 1;
    uint64_t max_memory = 0;
    vp_cli_seen seen = {0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(VP_CONVERT_HELP, stdout);
            return 0;
        } else if (!strcmp(a, "--max-memory")) {
            if (!v) return vp_cli_die(2, "convert: %s needs a value", a);
            if (vp_cli_once(&seen, "convert", a, v)) return 2;
            i++;
            if (vp_cli_parse_size(v, &max_memory) != 0)
                return vp_cli_die(2,
                                  "convert: --max-memory must be a size such as 8G or 500M, "
                                  "not '%s'",
                                  v);
        } else if (!strcmp(a, "--format") || !strcmp(a, "--shape") || !strcmp(a, "--precision")) {
            if (!v) return vp_cli_die(2, "convert: %s needs a value", a);
            if (vp_cli_once(&seen, "convert", a, v)) return 2;
            i++;
            if (!strcmp(a, "--format")) {
                format = v;
            } else if (!strcmp(a, "--shape")) {
                shape_name = v;
            } else if (!strcmp(v, "full") || !strcmp(v, "float")) {
                full = 1;
            } else if (!strcmp(v, "fixed16") || !strcmp(v, "16")) {
                full = 0;
            } else {
                return vp_cli_die(2, "convert: unknown --precision '%s' (fixed16, full)", v);
            }
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            return vp_cli_die(2, "convert: unknown option '%s' (see vdbpack convert --help)", a);
        } else if (!in) {
            in = a;
        } else if (!out) {
            out = a;
        } else {
            return vp_cli_die(2, "convert: more than two files given ('%s')", a);
        }
    }
    if (!in || !out || !*in || !*out)
        return vp_cli_die(2,
                          "convert: give an input and an output file (see vdbpack convert --help)");
    vp_shape shape = VP_SHAPE_SPHERE;
    double shape_param = 0.0;
    int sr = shape_name ? vp_shape_parse_param(shape_name, &shape, &shape_param) : 0;
    if (sr == -2)
        return vp_cli_die(2,
                          "convert: --shape '%s': a superball's exponent P (superball:P) must "
                          "be a number in [0.5, 1000]",
                          shape_name);
    if (sr != 0 || shape == VP_SHAPE_MESH)
        return vp_cli_die(2,
                          "convert: unknown --shape '%s' (sphere, a platonic or Archimedean "
                          "solid such as cube or truncated-octahedron (vdbpack pack --help "
                          "lists them), superball:P)",
                          shape_name);
    vp_format in_fmt = vp_format_from_path(in);
    if (in_fmt == VP_FORMAT_UNKNOWN || in_fmt == VP_FORMAT_OBJ)
        return vp_cli_die(2, "convert: cannot read '%s': the input must be .vdb, .ply or .csv", in);
    if (shape_name && in_fmt != VP_FORMAT_CSV)
        return vp_cli_die(2, "convert: --shape is for a .csv input ('%s' records its shape)", in);
    int out_fmt = 0;
    int rc = vp_cli_output_format("convert", out, format, &out_fmt);
    if (rc) return rc;
    /* in place, the input's pack metadata (seed, passes, command line)
     * would be lost with the file it is read from */
    if (vp_cli_same_file(in, out))
        return vp_cli_die(2, "convert: the output is the input ('%s'); give another name", out);

    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    if (max_memory) vp_context_set_max_memory(ctx, max_memory);
    vp_cli_signals_install();
    vp_particles *p = NULL;
    int status = 1, needs_shape = 0;
    if (vp_import(ctx, in, in_fmt, &p, &needs_shape) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    if (p->count == 0) {
        status = vp_cli_die(1, "%s: holds no particles: nothing to convert", in);
        goto done;
    }
    for (size_t i = 0; i < p->count; i++) { /* a points grid without pscale reads as 0 */
        double r = p->radii ? (double)p->radii[i] : (double)p->uniform_radius;
        if (!(r > 0) || !isfinite(r)) {
            status = vp_cli_die(1,
                                "%s: particle %zu has no positive radius (pscale missing or "
                                "%g): a packing needs P and pscale",
                                in, i, r);
            goto done;
        }
        if (!p->radii) break;
    }
    if (shape_name && shape == VP_SHAPE_SPHERE && p->has_orient) {
        status = vp_cli_die(1,
                            "%s: has orientations (qx..qw), which spheres do not carry: give "
                            "the solid's --shape",
                            in);
        goto done;
    }
    if (needs_shape && !shape_name) {
        status = vp_cli_die(1,
                            "%s: has orientations but does not record the particle shape: give "
                            "--shape NAME",
                            in);
        goto done;
    }
    if (shape_name) {
        p->shape = shape;
        p->shape_param = shape_param;
        if (shape != VP_SHAPE_SPHERE && !p->has_orient) {
            p->has_orient = 1; /* every particle in the canonical orientation */
            p->uniform_orient[0] = p->uniform_orient[1] = p->uniform_orient[2] = 0.0f;
            p->uniform_orient[3] = 1.0f;
        }
    }
    const char *base = strrchr(in, '/');
    base = base ? base + 1 : in;
    char shape_text[64];
    vp_shape_format(p->shape, p->shape_param, shape_text, sizeof shape_text);
    vp_meta meta[4] = {
        {"creator", VP_META_STRING, "vdbpack " VP_VERSION_STRING, 0, 0},
        {"converted_from", VP_META_STRING, base, 0, 0},
        {"shape", VP_META_STRING, shape_text, 0, 0},
        {"particle_count", VP_META_INT, NULL, (int64_t)p->count, 0},
    };
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.full_precision = full;
    wp.meta = meta;
    wp.meta_count = 4;
    vp_write_report wrep;
    memset(&wrep, 0, sizeof wrep);
    wp.report = &wrep;
    status = vp_cli_finish_output(
        ctx, vp_cli_write_particles(ctx, out, out_fmt, p, &wp, quiet) != 0, out);
    if (status) goto done;
    if (!quiet) {
        char what[96];
        vp_cli_shape_count(what, sizeof what, p->count, p->shape);
        printf("vdbpack: converted %s from %s (%s) to %s (%s)\n", what, in, vp_format_name(in_fmt),
               out, vp_format_name((vp_format)out_fmt));
    }
    if (!quiet && out_fmt == VP_FORMAT_VDB && wrep.promoted) vp_cli_print_promoted(&wrep);
    /* the summary lost (stdout on a full disk): an error, which leaves no
     * output */
    if ((status = vp_cli_flush_stdout(0)) != 0) vp_remove_output(out);
done:
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
    return status;
}

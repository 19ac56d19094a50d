/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack pack`'s parts: the options (pack_options.c: parsing and the
 * checks that need no container), the report (pack_report.c: the summary,
 * --json and the metadata texts) and the job (pack.c: shapes, container,
 * packer, outputs, as a list of named steps). Internal to the CLI. */
#ifndef VDBPACK_CLI_PACK_INTERNAL_H
#define VDBPACK_CLI_PACK_INTERNAL_H

#include "vdbpack/vdbpack.h"

#include <stddef.h>

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
    const char *text; /* as given, or NULL */
    char path[4096];  /* the file (text without :GRID) */
    const char *grid; /* points into text after ".vdb:", or NULL */
} field_arg;

typedef struct pack_fields {
    field_arg mask, radius, density;
    vp_field_mode mode;
    int mode_set;
    vp_field *radius_field, *density_field; /* loaded; owned by vp_cli_pack */
    double rmin, rmax;                      /* the radius field's range over the container */
    double mask_voxel;           /* a mesh or level-set mask's voxel (metadata, for check) */
    vp_container *base, *mask_c; /* with --mask: the container and the mask, which
                                    the masked container borrows (freed after it) */
} pack_fields;

typedef struct pack_opts {
    const char *container;
    const char *output;
    const char *format; /* --format, or NULL: by the output's extension */
    int out_format;     /* vp_format of the output */
    const char *method;
    vp_shape shape;
    double shape_param;        /* superball: the exponent */
    char shape_text[64];       /* the shape as files record it ("superball:2") */
    const char *shape_file;    /* --shape FILE: a mesh (shape == VP_SHAPE_MESH) */
    const vp_mesh_shape *mesh; /* loaded from shape_file before packing */
    int orient;                /* -1 unset, else vp_orient_mode */
    int overlap;               /* -1 unset, else vp_overlap_mode */
    vp_lattice lattice;
    vp_fit fit;
    double radius; /* lattice: the radius */
    const char *radius_text;
    vp_size_dist sizes; /* rsa/relax: --radius as a distribution */
    uint64_t count;
    int count_max; /* rsa: --count max */
    vp_rsa_pass passes[VP_MAX_GROUPS];
    int npasses;
    char pass_mesh_file[VP_MAX_GROUPS][1024]; /* --pass shape=FILE ("" for the others) */
    vp_mesh_shape *pass_mesh[VP_MAX_GROUPS];  /* loaded from them (owned; NULL where a
                                                 pass reuses an earlier one's) */
    int pass_shapes;                          /* some --pass has shape= */
    int mixed;                    /* the packing holds several shapes (VP_SHAPE_MIXED) */
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
    vp_inside_mode inside; /* --inside (meshes) */
    int inside_set;
    int has_iso; /* --iso V (fog or density .vdb grids) */
    double iso;
    const char *grid;
    int full_precision;
    const char *save_container;
    const char *shape_out;
    const char *preview; /* --preview IMAGE.exr|.png */
    uint64_t threads;
    uint64_t max_memory;
    int json;
    int quiet;
    int allow_short;      /* --allow-short: a shortfall exits 0 */
    int progress;         /* --progress: one line per stage on stderr */
    double margin;        /* --margin: distance kept from the wall (rsa) */
    double gap;           /* --gap: distance kept between surfaces (rsa) */
    int rsa_count_radius; /* rsa --count N without --radius: the radius is
                               the one N fill target_fraction with */
    pack_fields fields;   /* --mask, --radius-field, --density-field */
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

/* What a method produced, for metadata and the summary. */
typedef struct run_result {
    vp_lattice_report lat;
    vp_rsa_report rsa;
    vp_relax_report relax;
    vp_jam_report jam;
    double pack_seconds;
    double max_radius;
} run_result;

/* pack_options.c: parses argv into *o (which it fills wholly), with the
 * checks that need no container; 0, or the exit status after one line.
 * --help prints VP_PACK_HELP and returns -1 (exit 0). */
int pack_parse_options(int argc, char **argv, pack_opts *o);
/* 1 when some particle is not a sphere: --shape, or a --pass shape=. */
int pack_any_solid(const pack_opts *o);

/* pack_report.c */
const char *pack_lattice_label(const pack_opts *o);
/* The passes that placed fewer than asked (maximal ones never): their
 * number, what they asked and placed in all. */
int pack_shortfall(const pack_opts *o, const vp_rsa_report *r, size_t *asked, size_t *placed);
/* Per pass, what was asked (which = 0) or placed (1), for metadata. */
void pack_counts_text(const pack_opts *o, const vp_rsa_report *r, int which, char *out,
                      size_t outlen);
/* The --pass options as text, for metadata. */
void pack_passes_text(const pack_opts *o, char *out, size_t outlen);
void pack_print_json(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                     const run_result *rr, const vp_write_report *w, double fraction, int threads,
                     double seconds);
void pack_print_summary(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                        const run_result *rr, const vp_write_report *w, double fraction,
                        double seconds);
#endif

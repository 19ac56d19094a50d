/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack pack`'s options: getopt_long over the long options, each
 * option's methods, the checks that need no container (which options go
 * together, sizes, passes, fields), and its --help text. */
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

/* `vdbpack pack --help` (main.c prints it; docs/cli.md holds a copy that
 * tests/sh_docs_help.sh compares). */
const char *VP_PACK_HELP =
    "Usage: vdbpack pack CONTAINER -o OUT.vdb [options]\n"
    "\n"
    "Fills CONTAINER with particles and writes a PointDataGrid \"points\" (P, pscale =\n"
    "bounding-sphere radius, id, orient for solids, a group per pass).\n"
    "\n"
    "Method:\n"
    "  --method NAME           lattice (default), rsa (random sequential addition, in\n"
    "                          passes), relax (He et al. 1999 relaxation) or jam\n"
    "                          (jammed random close packing); relax and jam pack\n"
    "                          spheres\n"
    "  --fit inside|center     inside (default): every particle wholly inside (every\n"
    "                          vertex for solids); center: the centre inside\n"
    "  --seed N                random seed (default 1); same seed, same file\n"
    "  --count N               N particles, for every method: lattice chooses the\n"
    "                          radius that gives about N; rsa places N, of --radius\n"
    "                          or else of the radius at which N fill\n"
    "                          --target-fraction; relax and jam pack N spheres\n"
    "\n"
    "Options are --opt VALUE or --opt=VALUE, abbreviated where unambiguous (--rad);\n"
    "-- ends the options.\n"
    "\n"
    "Lattice (--method lattice):\n"
    "  --shape NAME            sphere (default), tetrahedron, cube, octahedron,\n"
    "                          dodecahedron, icosahedron, an Archimedean solid\n"
    "                          (truncated-tetrahedron, cuboctahedron, truncated-cube,\n"
    "                          truncated-octahedron, rhombicuboctahedron,\n"
    "                          truncated-cuboctahedron, snub-cube, icosidodecahedron,\n"
    "                          truncated-dodecahedron, truncated-icosahedron,\n"
    "                          rhombicosidodecahedron, truncated-icosidodecahedron,\n"
    "                          snub-dodecahedron), or superball:P (|x|^2P +\n"
    "                          |y|^2P + |z|^2P <= 1, P in [0.5, 1000]: 0.5 octahedron,\n"
    "                          1 sphere, large P nearly a cube)\n"
    "  --lattice NAME          spheres: sc, bcc, fcc (default, ABC stacking), hcp (AB);\n"
    "                          solids: densest (default, their densest known lattice;\n"
    "                          superballs: the densest of Jiao et al.'s C0, C1, O0, O1)\n"
    "  --radius R              bounding-sphere radius in world units\n"
    "  --count N               instead of --radius: choose the radius that gives about N\n"
    "  --offsets N             lattice offsets to try (default 128, 32 with --rotate,\n"
    "                          fewer for large packings); 1 = no search\n"
    "  --rotate                also search orientations of the lattice\n"
    "  --rotations N           orientations to try (implies --rotate; default 24)\n"
    "  --margin D, --gap G     as for rsa: every particle D from the wall; spheres\n"
    "                          spaced G apart (the lattice of radius R + G/2)\n"
    "\n"
    "Random sequential addition (--method rsa):\n"
    "  --pass SPEC             one pass; repeat for binary, ternary, ... packings.\n"
    "                          SPEC: count=N|max,radius=SIZE[,retries=K][,grow][,name=G]\n"
    "                          [,shape=S]\n"
    "                          count=max fills until no room is left for the\n"
    "                          smallest radius of SIZE, drawing radii from SIZE;\n"
    "                          grow: afterwards each particle of the pass grows until\n"
    "                          it touches; the pass's particles form group passK or G\n"
    "                          (G: 1-31 letters, digits or _, not __..., unique);\n"
    "                          shape=S: the pass's own shape (a --shape name or a\n"
    "                          closed mesh file; default --shape): passes of several\n"
    "                          shapes (at most 16) write an int shape attribute and\n"
    "                          the metadata shapes=\"cube;sphere;mesh:rock.obj\"\n"
    "  --radius SIZE --count N|max   a single pass, instead of --pass\n"
    "  --count N               alone: a single pass of N at the radius that makes\n"
    "                          them fill --target-fraction F (default 0.3)\n"
    "  --retries K             failed tries in a row that end a pass (default 5000)\n"
    "  --grow                  with --radius/--count: grow the pass's particles\n"
    "  --margin D              particles keep D (world units) from the wall: their\n"
    "                          surface (--fit inside) or centre (--fit center)\n"
    "  --gap G                 particles keep G (world units, < the smallest radius)\n"
    "                          between their surfaces (not mesh shapes); vdbpack\n"
    "                          check tests both\n"
    "  --radius-field F.vdb[:GRID]  spheres: the radius at each centre from a float\n"
    "                          grid (trilinear), as --radius-field-mode says\n"
    "  --radius-field-mode scale|absolute  scale (default): the field multiplies\n"
    "                          the radius drawn from --radius or the pass; absolute:\n"
    "                          the field is the radius (no --radius)\n"
    "  --density-field F.vdb[:GRID]  spheres: relative number density (a dart at x\n"
    "                          is kept with probability f(x) / max f); fields must\n"
    "                          cover the container (docs/fields.md)\n"
    "  --shape NAME|FILE       as for lattice, or any closed mesh file (OBJ, PLY,\n"
    "                          STL, glTF, ...; concave too), centred on the centroid\n"
    "                          of its volume and scaled to bounding radius 1\n"
    "  --orient random|fixed   solids: uniform random rotations (default) or all in\n"
    "                          the canonical orientation\n"
    "  --overlap exact|bbox    solids: exact separating-axis test (default), or the\n"
    "                          original axis-aligned bounding boxes (--orient fixed,\n"
    "                          the default with bbox); count=max for solids ends by\n"
    "                          the retry limit\n"
    "\n"
    "Relaxation (--method relax):\n"
    "  --radius SIZE           initial radii\n"
    "  --count N               number of spheres\n"
    "  --target-fraction F     scale the radii so that the spheres fill F of the\n"
    "                          container before relaxation (0 < F < 1)\n"
    "  --tolerance X           largest overlap allowed at the end, as a fraction of\n"
    "                          r_i + r_j (default 1e-6)\n"
    "  --margin D, --gap G     as for rsa (the radii shrink until both hold)\n"
    "  --radius-field F.vdb[:GRID]  radii from the field at the starting centres\n"
    "                          (and --radius-field-mode), as for rsa\n"
    "\n"
    "Jamming (--method jam; docs/jam.md):\n"
    "  --count N               number of spheres; their radii are scaled together\n"
    "                          until the packing jams (about 0.64 for equal spheres)\n"
    "  --radius SIZE           the radii's distribution (default: equal); with\n"
    "                          --target-fraction F instead of --count, N is what\n"
    "                          fills F of the container at these radii (default 0.64);\n"
    "                          radii spread by 0.1 of their mean or more trade\n"
    "                          places between neighbours as they pack (denser)\n"
    "  --tolerance X           largest overlap at the end (default 1e-6 of r_i + r_j)\n"
    "  --margin D, --gap G     as for rsa: the spheres jam D from the wall and G\n"
    "                          apart (the radii scale until spheres G apart touch)\n"
    "  --radius-field F.vdb[:GRID]  radii in the field's ratios at the starting\n"
    "                          centres, then scaled together to the jamming point\n"
    "\n"
    "SIZE is a radius (0.01) or a distribution of radii: uniform:A:B,\n"
    "lognormal:MEAN:SD (mean and standard deviation of the radius) or\n"
    "list:R1:R2:... (equal weights).\n"
    "\n"
    "Container:\n"
    "  --voxel-size V          voxel size for meshes (default: automatic, see summary)\n"
    "  --inside auto|closed|winding  how a mesh's inside is decided: auto (default):\n"
    "                          a closed, consistently oriented mesh as a closed\n"
    "                          surface, any other (open, holed, overlapping or\n"
    "                          nested pieces, flipped faces) by its winding number;\n"
    "                          closed: refuse other meshes; winding: always\n"
    "  --iso V                 a fog or density .vdb grid as the container: inside\n"
    "                          where its value is >= V\n"
    "  --grid NAME             level-set grid to use from a .vdb (default: the first;\n"
    "                          NAME[k]: the k-th of several grids named NAME)\n"
    "  --mask M                no particle where M is inside (any method; with --fit\n"
    "                          inside no part of one): a mesh, a .vdb level set\n"
    "                          (FILE.vdb[:GRID]), sphere:R or box:X,Y,Z\n"
    "\n"
    "Output:\n"
    "  -o, --output FILE       output file (required): .vdb (OpenVDB points), .ply,\n"
    "                          .csv or .obj, by its extension (docs/export.md)\n"
    "  --format F              the output's format: vdb, ply, csv or obj (default:\n"
    "                          by its extension)\n"
    "  --precision fixed16|full  .vdb: P as 16-bit fixed point or 32-bit float (default:\n"
    "                          fixed16 for lattice, full for rsa and relax, whose\n"
    "                          particles touch); float wherever 16 bits would round\n"
    "                          by over 1e-3 of the smallest radius\n"
    "  --save-container FILE   also write the container level set as its own .vdb\n"
    "  --shape-out FILE        also write the unit particle shape as OBJ (instancing;\n"
    "                          for a mesh shape, the mesh as normalised; several\n"
    "                          shapes: group shapeK for the points of shape K)\n"
    "  --preview IMAGE         also render the packing (default settings of vdbpack\n"
    "                          render) into IMAGE.exr or IMAGE.png\n"
    "\n"
    "Run:\n"
    "  --threads N             worker threads (default: $VDBPACK_THREADS, else all\n"
    "                          cores); the output does not depend on it\n"
    "  --max-memory SIZE       refuse jobs estimated above SIZE (e.g. 8G; default: RAM)\n"
    "  --json                  print the summary as JSON on stdout\n"
    "  --allow-short           exit 0 when fewer particles were placed than asked\n"
    "                          for (default: exit status 4, \"packed, but short\",\n"
    "                          with one warning line; the file is written)\n"
    "  --progress              one line per stage on stderr (\"progress: STAGE\n"
    "                          FRACTION SECONDS\"), instead of the bar a terminal\n"
    "                          gets (a bar: stages, elapsed and remaining time)\n"
    "  -q, --quiet             print nothing but errors\n"
    "  -h, --help              this text\n";

/* 1 when some particle is not a sphere: --shape, or a --pass shape=. */
int pack_any_solid(const pack_opts *o) {
    if (o->shape != VP_SHAPE_SPHERE) return 1;
    for (int i = 0; i < o->npasses; i++)
        if (o->passes[i].own_shape && o->passes[i].shape.shape != VP_SHAPE_SPHERE) return 1;
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
        return vp_cli_die(2,
                          "pack: --method %s packs spheres in this version (--shape %s "
                          "needs --method lattice or rsa)",
                          m, vp_shape_name(o->shape));
    if ((o->orient >= 0 || o->overlap >= 0) && !(rsa && pack_any_solid(o)))
        return vp_cli_die(2, "pack: --orient and --overlap go with --method rsa and a --shape "
                             "(or a --pass shape=) other than sphere");
    if (o->overlap == VP_OVERLAP_BBOX && o->orient == VP_ORIENT_RANDOM)
        return vp_cli_die(2, "pack: --overlap bbox needs --orient fixed (the axis-aligned box "
                             "of a rotated solid does not bound it)");
    if (o->overlap < 0) o->overlap = VP_OVERLAP_EXACT;
    if (o->orient < 0)
        o->orient = o->overlap == VP_OVERLAP_BBOX ? VP_ORIENT_FIXED : VP_ORIENT_RANDOM;
    /* Random packings have particles in contact (grow, relax) or nearly so:
     * 16-bit fixed-point positions (1/65536 of a points voxel) would turn
     * contacts into overlaps, so they default to full precision. */
    if (!lattice && !o->precision_set) o->full_precision = 1;
    if (lattice) {
        if (have_radius && have_count)
            return vp_cli_die(2, "pack: give either --radius or --count, not both");
        if (!have_radius && !have_count)
            return vp_cli_die(2, "pack: give the particle size with --radius R or --count N");
        if (have_radius &&
            (vp_cli_parse_double(o->radius_text, &o->radius) != 0 || !(o->radius > 0)))
            return vp_cli_die(2,
                              "pack: --radius must be a positive number for --method lattice, "
                              "not '%s'%s",
                              o->radius_text,
                              strchr(o->radius_text, ':')
                                  ? " (distributions of radii go with --method rsa, relax and "
                                    "jam)"
                                  : "");
        /* as for rsa and relax (vp_size_dist_parse): a radius below a
         * normal float would be stored as a denormal or 0 */
        if (have_radius && !(o->radius >= FLT_MIN))
            return vp_cli_die(2,
                              "pack: --radius: size '%s': a radius must be at least 1.2e-38 "
                              "(radii are stored as float)",
                              o->radius_text);
        if (have_radius && !(o->radius <= FLT_MAX))
            return vp_cli_die(2,
                              "pack: --radius: size '%s': a radius must be at most 3.4e38 "
                              "(radii are stored as float)",
                              o->radius_text);
        if (o->gap > 0 && o->shape != VP_SHAPE_SPHERE)
            return vp_cli_die(2, "pack: --gap spaces a lattice of spheres in this version, not "
                                 "--shape %s (--method rsa keeps a gap between any convex shapes)",
                              o->shape_file ? o->shape_file : vp_shape_name(o->shape));
        if (o->shape == VP_SHAPE_SPHERE && o->lattice == VP_LATTICE_DENSEST)
            o->lattice = VP_LATTICE_FCC;
        if (o->shape != VP_SHAPE_SPHERE && o->lattice != VP_LATTICE_DEFAULT &&
            o->lattice != VP_LATTICE_DENSEST)
            return vp_cli_die(2,
                              "pack: --lattice %s is for spheres; a %s packs on its densest "
                              "lattice (--lattice densest)",
                              vp_lattice_name(o->lattice), vp_shape_name(o->shape));
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
        if (o->gap > 0 && pack_any_solid(o) && o->overlap == VP_OVERLAP_BBOX)
            return vp_cli_die(2, "pack: --gap is kept by the exact overlap test, not with "
                                 "--overlap bbox");
        if (o->pass_shapes && o->overlap == VP_OVERLAP_BBOX)
            return vp_cli_die(2, "pack: --overlap bbox takes one shape; passes with a shape= of "
                                 "their own are tested exactly");
        for (int i = 0; i < o->npasses; i++) {
            if (o->gap > 0 && !o->rsa_count_radius &&
                !(o->gap < vp_size_dist_min(&o->passes[i].radius)))
                return vp_cli_die(2,
                                  "pack: --gap %g must be smaller than the smallest radius "
                                  "(%g, pass %d)",
                                  o->gap, vp_size_dist_min(&o->passes[i].radius), i + 1);
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
                    return vp_cli_die(2,
                                      "pack: passes %d and %d would both be group '%s'; give "
                                      "each pass its own name=",
                                      k + 1, i + 1, ni);
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
    if (!have_radius && o->fields.radius.text && o->fields.mode == VP_FIELD_ABSOLUTE &&
        have_count) {
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
    OPT_OUTPUT = 'o',
    OPT_QUIET = 'q',
    OPT_HELP = 'h',
    OPT_FORMAT = 256,
    OPT_METHOD,
    OPT_SHAPE,
    OPT_ORIENT,
    OPT_OVERLAP,
    OPT_LATTICE,
    OPT_RADIUS,
    OPT_COUNT,
    OPT_PASS,
    OPT_RETRIES,
    OPT_GROW,
    OPT_TARGET_FRACTION,
    OPT_TOLERANCE,
    OPT_FIT,
    OPT_OFFSETS,
    OPT_ROTATE,
    OPT_ROTATIONS,
    OPT_SEED,
    OPT_VOXEL_SIZE,
    OPT_ALLOW_OPEN,
    OPT_INSIDE,
    OPT_ISO,
    OPT_GRID,
    OPT_PRECISION,
    OPT_SAVE_CONTAINER,
    OPT_SHAPE_OUT,
    OPT_PREVIEW,
    OPT_THREADS,
    OPT_MAX_MEMORY,
    OPT_JSON,
    OPT_ALLOW_SHORT,
    OPT_MARGIN,
    OPT_GAP,
    OPT_PROGRESS,
    OPT_MASK,
    OPT_RADIUS_FIELD,
    OPT_RADIUS_FIELD_MODE,
    OPT_DENSITY_FIELD,
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
    {OPT_LATTICE, M_LATTICE},
    {OPT_OFFSETS, M_LATTICE},
    {OPT_ROTATE, M_LATTICE},
    {OPT_ROTATIONS, M_LATTICE},
    {OPT_PASS, M_RSA},
    {OPT_RETRIES, M_RSA},
    {OPT_GROW, M_RSA},
    {OPT_ORIENT, M_RSA},
    {OPT_OVERLAP, M_RSA},
    {OPT_TARGET_FRACTION, M_RSA | M_RELAX | M_JAM},
    {OPT_TOLERANCE, M_RELAX | M_JAM},
    {OPT_RADIUS_FIELD, M_RSA | M_RELAX | M_JAM},
    {OPT_RADIUS_FIELD_MODE, M_RSA | M_RELAX | M_JAM},
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
    return !strcmp(m, "lattice") ? M_LATTICE
           : !strcmp(m, "rsa")   ? M_RSA
           : !strcmp(m, "relax") ? M_RELAX
                                 : M_JAM;
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
        snprintf(out + at, len - at, "%s%s",
                 n == 0           ? ""
                 : n == total - 1 ? " and "
                                  : ", ",
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
    if (optopt)
        return vp_cli_die(2, "pack: unknown option '-%c' (see vdbpack pack --help)", optopt);
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
            return vp_cli_die(2,
                              "pack: --shape '%s': a superball's exponent P "
                              "(superball:P) must be a number in [0.5, 1000] (convex "
                              "superballs; concave ones, P < 0.5, are not offered)",
                              v);
        if (sr != 0) {
            /* not a built-in name: a mesh file, when it looks like one */
            if (!strchr(v, '.') && !strchr(v, '/'))
                return vp_cli_die(2,
                                  "pack: unknown --shape '%s' (sphere, a platonic or "
                                  "Archimedean solid such as cube or truncated-octahedron "
                                  "(vdbpack pack --help lists them), superball:P, "
                                  "or a closed mesh file such as shape.obj)",
                                  v);
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
            return vp_cli_die(2, "pack: --target-fraction must be a number in (0, 1), not '%s'", v);
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
        if (vp_cli_parse_u64(v, &o->rotations) != 0 || o->rotations == 0 || o->rotations > 100000)
            return vp_cli_die(2,
                              "pack: --rotations must be a whole number in 1..100000, not "
                              "'%s'",
                              v);
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
            return vp_cli_die(2,
                              "pack: --max-memory must be a size such as 8G or 500M, not "
                              "'%s'",
                              v);
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

int pack_parse_options(int argc, char **argv, pack_opts *o) {
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
                const char *opt_arg =
                    optarg == args[optind - 1] ? args[optind - 2] : args[optind - 1];
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
        return vp_cli_die(2,
                          "pack: --save-container writes a .vdb: give a name ending in .vdb, "
                          "not '%s'",
                          o->save_container);
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
                return vp_cli_die(2, "pack: %s %s is %s itself: writing would replace it", names[i],
                                  outs[i], inames[k]);
        for (int k = 0; k < i; k++)
            if (outs[k] && vp_cli_same_file(outs[i], outs[k]))
                return vp_cli_die(2, "pack: %s and %s name the same file (%s)", names[k], names[i],
                                  outs[i]);
    }
    rc = check_option_methods(o, given);
    if (rc) return rc;
    rc = check_method_options(o, have_radius, have_count);
    if (rc) return rc;
    rc = check_field_options(o, have_radius, given);
    if (rc) return rc;
    return 0;
}

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
            return vp_cli_die(2,
                              "pack: %s '%s': give the grid's name after the colon, or no "
                              "colon (the first float grid)",
                              opt, v);
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
        return vp_cli_die(2,
                          "pack: --radius-field and --density-field pack spheres in this "
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

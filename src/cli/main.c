/* SPDX-License-Identifier: Apache-2.0 */
/* vdbpack command-line tool: a thin layer over the public C API.
 * Every failure ends in one line on stderr ("vdbpack: ...") and a non-zero
 * exit status: 2 for usage errors, 1 for everything else. */
#include "vdbpack/vdbpack.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"

static const char *MAIN_HELP =
    "vdbpack " VP_VERSION_STRING ": fill a container with non-overlapping particles\n"
    "and write them as OpenVDB points.\n"
    "\n"
    "Usage:\n"
    "  vdbpack pack CONTAINER -o OUT.vdb [options]   pack particles (vdbpack pack --help)\n"
    "  vdbpack info FILE.vdb [--json]                describe a .vdb file\n"
    "  vdbpack check FILE.vdb --container C          verify a packing (vdbpack check --help)\n"
    "  vdbpack render FILE.vdb -o IMAGE.exr|.png     preview render (vdbpack render --help)\n"
    "  vdbpack convert IN OUT                        convert a packing between .vdb, .ply,\n"
    "                                                .csv and .obj (vdbpack convert --help)\n"
    "  vdbpack --version                             print the version\n"
    "  vdbpack --help                                this text\n"
    "\n"
    "CONTAINER is a mesh (OBJ, PLY, STL, glTF, ... anything Assimp reads; closed or\n"
    "not: an open or broken mesh is taken by its winding number, see --inside), a\n"
    ".vdb holding a float level set (or a fog grid, with --iso), or an analytic\n"
    "shape: sphere:R or box:X,Y,Z (both centred at the origin).\n";

static const char *PACK_HELP =
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
    "                          fills F of the container at these radii (default 0.64)\n"
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

static const char *INFO_HELP =
    "Usage: vdbpack info FILE.vdb [--json]\n"
    "\n"
    "Lists the grids of FILE.vdb (name, type, class, voxel size, active voxels,\n"
    "bounds; for points: count, attributes with codecs, groups) and its metadata.\n"
    "  --json      machine-readable output\n"
    "  -h, --help  this text\n";

static int cmd_info(int argc, char **argv) {
    const char *file = NULL;
    int json = 0;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(INFO_HELP, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--json")) {
            json = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return vp_cli_die(2, "info: unknown option '%s' (see vdbpack info --help)", argv[i]);
        } else if (!file) {
            file = argv[i];
        } else {
            return vp_cli_die(2, "info: more than one file given ('%s')", argv[i]);
        }
    }
    if (!file || !*file) return vp_cli_die(2, "info: no file given (see vdbpack info --help)");
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    char *text = NULL;
    vp_result r = vp_describe_file(ctx, file, json, &text);
    int status = 0;
    if (r != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
    } else {
        fputs(text, stdout);
        size_t n = strlen(text);
        if (n && text[n - 1] != '\n') fputc('\n', stdout);
    }
    free(text);
    vp_context_destroy(ctx);
    return status;
}

static int run_command(int argc, char **argv) {
    if (argc < 2) {
        fputs(MAIN_HELP, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "-V")) {
        printf("vdbpack %s\n", VP_VERSION_STRING);
        /* tests read this line: sanitizer builds cannot contain a reader's
         * crash in a child process */
        printf("file readers (Assimp, OpenVDB): %s\n",
               vp_readers_isolated() ? "checked in a child process first"
                                            : "in-process (sanitizer or fuzz build)");
        return 0;
    }
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(MAIN_HELP, stdout);
        return 0;
    }
    if (!strcmp(cmd, "pack")) {
        /* -h, --help or an abbreviation of it (--he), before the options'
         * end (--) */
        for (int i = 2; i < argc && strcmp(argv[i], "--") != 0; i++)
            if (!strcmp(argv[i], "-h") ||
                (strlen(argv[i]) >= 3 && !strncmp(argv[i], "--help", strlen(argv[i])))) {
                fputs(PACK_HELP, stdout);
                return 0;
            }
        return vp_cli_pack(argc, argv);
    }
    if (!strcmp(cmd, "info")) return cmd_info(argc - 2, argv + 2);
    if (!strcmp(cmd, "check")) return vp_cli_check(argc - 2, argv + 2);
    if (!strcmp(cmd, "render")) return vp_cli_render(argc - 2, argv + 2);
    if (!strcmp(cmd, "convert")) return vp_cli_convert(argc - 2, argv + 2);
    return vp_cli_die(2, "unknown command '%s' (see vdbpack --help)", cmd);
}

int main(int argc, char **argv) {
    vp_cli_std_fds();
    /* a result printed but lost (stdout on a full disk) is an error */
    return vp_cli_flush_stdout(run_command(argc, argv));
}

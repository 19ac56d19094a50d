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
                fputs(VP_PACK_HELP, stdout);
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

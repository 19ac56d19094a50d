/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: `vdbpack pack` option parsing. The input is split into
 * arguments at NUL and newline bytes (at most 48), after "vdbpack pack";
 * parsing must end with 0 or an exit status and exactly one message, never
 * a crash, an overflow or a leak. Nothing is packed. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

#define MAX_ARGS 48

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size > 4096) return 0;
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = 0;
    char *argv[MAX_ARGS + 3];
    int argc = 0;
    argv[argc++] = "vdbpack";
    argv[argc++] = "pack";
    char *start = buf;
    for (size_t i = 0; i <= size && argc < MAX_ARGS + 2; i++) {
        if (buf[i] == '\n' || buf[i] == 0) {
            buf[i] = 0;
            argv[argc++] = start;
            start = buf + i + 1;
        }
    }
    argv[argc] = NULL;
    int rc = vp_cli_pack_parse_only(argc, argv);
    if (rc != 0 && rc != 1 && rc != 2) __builtin_trap(); /* statuses are 0, 1, 2 */
    free(buf);
    return 0;
}

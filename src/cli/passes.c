/* SPDX-License-Identifier: Apache-2.0 */
/* Parsing of the random packers' options: sizes (a radius or a
 * distribution) and `--pass count=N|max,radius=R|DIST[,retries=K][,grow]
 * [,name=NAME][,shape=SHAPE]`. Errors print one line and return the exit
 * status 2. */
#include "vdbpack/vdbpack.h"

#include <stdio.h>
#include <string.h>

#include "cli/cli.h"

int vp_cli_parse_sizes(const char *opt, const char *text, vp_size_dist *out) {
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    int rc = 0;
    if (vp_size_dist_parse(ctx, text, out) != VP_OK)
        rc = vp_cli_die(2, "pack: %s: %s", opt, vp_context_message(ctx));
    vp_context_destroy(ctx);
    return rc;
}

/* Letters, digits and _, not starting with "__" (OpenVDB's own attribute
 * names, such as its group attribute "__group", start so). */
static int valid_group_name(const char *s) {
    if (!*s || strlen(s) >= VP_GROUP_NAME_MAX || !strncmp(s, "__", 2)) return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
              *s == '_'))
            return 0;
    return 1;
}

int vp_cli_parse_pass(const char *text, vp_rsa_pass *out, char *mesh_file, size_t mesh_len) {
    vp_rsa_pass_init(out);
    mesh_file[0] = 0;
    char buf[1024];
    if (strlen(text) >= sizeof buf)
        return vp_cli_die(2, "pack: --pass '%.40s...' is too long", text);
    strcpy(buf, text);
    /* fields split by hand: strtok would skip empty ones ("a,,b", a trailing comma) */
    static const char *const fields[] = {"count", "radius", "retries", "grow", "name", "shape"};
    enum { NFIELDS = 6 };
    int seen[NFIELDS] = {0}; /* count and radius are required, each field allowed once */
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next) *next++ = 0;
        if (!*tok) return vp_cli_die(2, "pack: --pass '%s': empty field (a stray comma)", text);
        char *eq = strchr(tok, '=');
        const char *val = eq ? eq + 1 : NULL;
        if (eq) *eq = 0;
        int f = 0;
        while (f < NFIELDS && strcmp(tok, fields[f])) f++;
        if (f == NFIELDS)
            return vp_cli_die(2,
                              "pack: --pass '%s': unknown field '%s' (count, radius, retries, "
                              "grow, name, shape)",
                              text, tok);
        if (seen[f]++) return vp_cli_die(2, "pack: --pass '%s': %s is given twice", text, tok);
        if (!strcmp(tok, "count")) {
            uint64_t n;
            if (val && !strcmp(val, "max")) {
                out->maximal = 1;
            } else if (!val || vp_cli_parse_u64(val, &n) != 0 || n == 0) {
                return vp_cli_die(2,
                                  "pack: --pass '%s': count must be a whole number > 0 or "
                                  "'max', not '%s'",
                                  text, val ? val : "");
            } else {
                out->count = (size_t)n;
            }
        } else if (!strcmp(tok, "radius")) {
            if (!val) return vp_cli_die(2, "pack: --pass '%s': radius needs a value", text);
            char opt[64];
            snprintf(opt, sizeof opt, "--pass radius");
            int rc = vp_cli_parse_sizes(opt, val, &out->radius);
            if (rc) return rc;
        } else if (!strcmp(tok, "retries")) {
            uint64_t k;
            if (!val || vp_cli_parse_u64(val, &k) != 0 || k == 0 || k > 1000000000)
                return vp_cli_die(2,
                                  "pack: --pass '%s': retries must be a whole number in "
                                  "1..1e9, not '%s'",
                                  text, val ? val : "");
            out->retries = (int)k;
        } else if (!strcmp(tok, "grow")) {
            if (val) return vp_cli_die(2, "pack: --pass '%s': grow takes no value", text);
            out->grow = 1;
        } else if (!strcmp(tok, "name")) {
            if (!val || !valid_group_name(val))
                return vp_cli_die(2,
                                  "pack: --pass '%s': name must be 1-31 letters, digits or "
                                  "_, not starting with __",
                                  text);
            snprintf(out->name, sizeof out->name, "%s", val);
        } else if (!strcmp(tok, "shape")) {
            /* a built-in name or superball:P, else a mesh file (read
             * before packing: a missing one fails there, with its name) */
            if (!val || !*val)
                return vp_cli_die(2,
                                  "pack: --pass '%s': shape needs a value (a shape name, "
                                  "superball:P or a closed mesh file)",
                                  text);
            out->own_shape = 1;
            int sr = vp_shape_parse_param(val, &out->shape.shape, &out->shape.param);
            if (sr == -2)
                return vp_cli_die(2,
                                  "pack: --pass '%s': a superball's exponent P must be a "
                                  "number in [0.5, 1000] (concave superballs, P < 0.5, are "
                                  "not offered)",
                                  text);
            if (sr != 0) {
                if (strlen(val) >= mesh_len)
                    return vp_cli_die(2, "pack: --pass '%s': the shape's file name is too long",
                                      text);
                out->shape.shape = VP_SHAPE_MESH;
                out->shape.param = 0.0;
                snprintf(mesh_file, mesh_len, "%s", val);
            }
        }
    }
    if (!seen[0] || !seen[1])
        return vp_cli_die(2, "pack: --pass '%s' needs count=N (or count=max) and radius=R", text);
    return 0;
}

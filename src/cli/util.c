/* SPDX-License-Identifier: Apache-2.0 */
/* Parsing and JSON helpers for the command-line tool. */
#include "vdbpack/vdbpack.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/cli.h"

/* text into out[len], its middle replaced by "..." when it is too long, so
 * that the reason at the end of a message with a path of 4000 bytes
 * survives (the library's messages are shortened the same way, in
 * src/os/text.c, which the command-line tool does not link). */
static void shorten_middle(char *out, size_t len, const char *text) {
    size_t n = strlen(text);
    if (n < len) {
        memcpy(out, text, n + 1);
        return;
    }
    size_t room = len - 4, head = room / 3, from = n - (room - head);
    while (head > 0 && ((unsigned char)text[head] & 0xC0) == 0x80) head--;
    while (from < n && ((unsigned char)text[from] & 0xC0) == 0x80) from++;
    memcpy(out, text, head);
    memcpy(out + head, "...", 3);
    memcpy(out + head + 3, text + from, n - from + 1);
}

/* One line, always: control characters from file names or option values
 * (a newline in a path) are shown as '?'. */
int vp_cli_die(int status, const char *fmt, ...) {
    char msg[4096];
    va_list ap, again;
    va_start(ap, fmt);
    va_copy(again, ap);
    int n = vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (n >= (int)sizeof msg) {
        char *full = malloc((size_t)n + 1);
        if (full) {
            vsnprintf(full, (size_t)n + 1, fmt, again);
            shorten_middle(msg, sizeof msg, full);
            free(full);
        }
    }
    va_end(again);
    for (char *c = msg; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
    fprintf(stderr, "vdbpack: %s\n", msg);
    return status;
}

static const char *canonical_option(const char *opt) {
    if (!strcmp(opt, "-o")) return "--output";
    if (!strcmp(opt, "--color")) return "--colour";
    return opt;
}

int vp_cli_once(vp_cli_seen *s, const char *cmd, const char *opt, const char *value) {
    const char *key = canonical_option(opt);
    for (int k = 0; k < s->n; k++)
        if (!strcmp(s->opt[k], key))
            return vp_cli_die(2, "%s: %s is given twice ('%s' and '%s'); give it once", cmd, opt,
                              s->value[k], value);
    if (s->n < VP_CLI_SEEN_MAX) {
        s->opt[s->n] = key;
        s->value[s->n] = value;
        s->n++;
    }
    return 0;
}

const char *vp_cli_shape_plural(int shape) {
    switch (shape) {
    case VP_SHAPE_SPHERE: return "spheres";
    case VP_SHAPE_TETRAHEDRON: return "tetrahedra";
    case VP_SHAPE_CUBE: return "cubes";
    case VP_SHAPE_OCTAHEDRON: return "octahedra";
    case VP_SHAPE_DODECAHEDRON: return "dodecahedra";
    case VP_SHAPE_ICOSAHEDRON: return "icosahedra";
    case VP_SHAPE_TRUNCATED_TETRAHEDRON: return "truncated tetrahedra";
    case VP_SHAPE_CUBOCTAHEDRON: return "cuboctahedra";
    case VP_SHAPE_TRUNCATED_CUBE: return "truncated cubes";
    case VP_SHAPE_TRUNCATED_OCTAHEDRON: return "truncated octahedra";
    case VP_SHAPE_RHOMBICUBOCTAHEDRON: return "rhombicuboctahedra";
    case VP_SHAPE_TRUNCATED_CUBOCTAHEDRON: return "truncated cuboctahedra";
    case VP_SHAPE_SNUB_CUBE: return "snub cubes";
    case VP_SHAPE_ICOSIDODECAHEDRON: return "icosidodecahedra";
    case VP_SHAPE_TRUNCATED_DODECAHEDRON: return "truncated dodecahedra";
    case VP_SHAPE_TRUNCATED_ICOSAHEDRON: return "truncated icosahedra";
    case VP_SHAPE_RHOMBICOSIDODECAHEDRON: return "rhombicosidodecahedra";
    case VP_SHAPE_TRUNCATED_ICOSIDODECAHEDRON: return "truncated icosidodecahedra";
    case VP_SHAPE_SNUB_DODECAHEDRON: return "snub dodecahedra";
    case VP_SHAPE_MESH: return "mesh shapes";
    case VP_SHAPE_SUPERBALL: return "superballs";
    case VP_SHAPE_MIXED: return "particles of several shapes";
    default: return "particles";
    }
}

int vp_cli_shape_count(char *buf, size_t len, size_t count, int shape) {
    const char *one = shape == VP_SHAPE_MESH    ? "mesh shape"
                      : shape == VP_SHAPE_MIXED ? "particle"
                                                : vp_shape_name((vp_shape)shape);
    return snprintf(buf, len, "%zu %s", count, count == 1 ? one : vp_cli_shape_plural(shape));
}

/* The file path names, spelled one way (out: PATH_MAX bytes): realpath()
 * when it exists; otherwise, after following a dangling link at the name
 * (it names the file a write creates), the resolved directory and the
 * name. 0, or -1 when it cannot be told (a missing directory, a loop). */
static int resolve_file(const char *path, char *out) {
    char cur[PATH_MAX];
    if (strlen(path) >= sizeof cur) return -1;
    strcpy(cur, path);
    for (int depth = 0; depth < 40; depth++) {
        if (realpath(cur, out)) return 0;
        const char *slash = strrchr(cur, '/');
        struct stat st;
        if (lstat(cur, &st) == 0 && S_ISLNK(st.st_mode)) {
            char link[PATH_MAX], next[PATH_MAX];
            ssize_t n = readlink(cur, link, sizeof link - 1);
            if (n < 0) return -1;
            link[n] = 0;
            int w = link[0] == '/' || !slash
                        ? snprintf(next, sizeof next, "%s", link)
                        : snprintf(next, sizeof next, "%.*s/%s", (int)(slash - cur), cur, link);
            if (w < 0 || (size_t)w >= sizeof next) return -1;
            strcpy(cur, next);
            continue;
        }
        const char *name = slash ? slash + 1 : cur;
        if (!*name || !strcmp(name, ".") || !strcmp(name, "..")) return -1;
        char dir[PATH_MAX];
        if (!slash) strcpy(dir, ".");
        else if (slash == cur) strcpy(dir, "/");
        else snprintf(dir, sizeof dir, "%.*s", (int)(slash - cur), cur);
        char rdir[PATH_MAX];
        if (!realpath(dir, rdir)) return -1;
        int w = snprintf(out, PATH_MAX, "%s/%s", strcmp(rdir, "/") ? rdir : "", name);
        return w < 0 || w >= PATH_MAX ? -1 : 0;
    }
    return -1;
}

int vp_cli_same_file(const char *a, const char *b) {
    if (!a || !b) return 0;
    if (!strcmp(a, b)) return 1;
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0) /* (hard links too) */
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    /* one that does not exist yet: by the file it would be (./x.vdb and
     * x.vdb, ln/x.png and real/x.png with ln a link to real) */
    char ra[PATH_MAX], rb[PATH_MAX];
    return resolve_file(a, ra) == 0 && resolve_file(b, rb) == 0 && !strcmp(ra, rb);
}

void vp_cli_std_fds(void) {
    for (int fd = 0; fd < 3; fd++)
        if (fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
            int got = open("/dev/null", fd ? O_WRONLY : O_RDONLY);
            if (got >= 0 && got != fd) { /* (cannot happen: the lowest is free) */
                dup2(got, fd);
                close(got);
            }
        }
}

/* set once the loss of the standard output has been reported */
static int g_stdout_told = 0;

int vp_cli_flush_stdout(int status) {
    if (g_stdout_told) return status;
    errno = 0;
    int bad = fflush(stdout) != 0;
    int e = errno;
    if (!bad && !ferror(stdout)) return status;
    g_stdout_told = 1;
    if (status != 0 && status != 3) return status; /* an error was told already */
    /* (the reason is known when the last write failed; an earlier one,
     * inside a long printf, leaves only the stream's error flag) */
    return vp_cli_die(1, "cannot write the result to the standard output%s%s%s", e ? " (" : "",
                      e ? strerror(e) : "", e ? ")" : "");
}

int vp_cli_parse_double(const char *s, double *out) {
    if (!s || !*s || isspace((unsigned char)*s)) return -1;
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || !end || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int vp_cli_parse_u64(const char *s, uint64_t *out) {
    if (!s || !*s || !isdigit((unsigned char)*s)) return -1;
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || !end || *end) return -1;
    *out = (uint64_t)v;
    return 0;
}

int vp_cli_parse_size(const char *s, uint64_t *out) {
    if (!s || !*s || !isdigit((unsigned char)*s)) return -1;
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || !isfinite(v) || v <= 0) return -1;
    double mult = 1;
    if (*end) {
        switch (toupper((unsigned char)*end)) {
        case 'K': mult = 1024.0; break;
        case 'M': mult = 1024.0 * 1024; break;
        case 'G': mult = 1024.0 * 1024 * 1024; break;
        case 'T': mult = 1024.0 * 1024 * 1024 * 1024; break;
        default: return -1;
        }
        end++;
        if (*end == 'B' || *end == 'b') end++;
        if (*end) return -1;
    }
    v *= mult;
    if (v >= 1.8e19) return -1;
    *out = (uint64_t)v;
    return 0;
}

void vp_cli_json_string(FILE *f, const char *s) {
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++) {
        switch (*p) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (*p < 0x20) fprintf(f, "\\u%04x", *p);
            else fputc(*p, f);
        }
    }
    fputc('"', f);
}

/* sphere:R or box:X,Y,Z (centred at the origin); 1 if it is one, -1 if
 * malformed, -2 if refused by the library (its message in ctx), 0 if not
 * analytic. */
int vp_cli_analytic_container(vp_context *ctx, const char *spec, vp_container **out) {
    struct stat st;
    if (stat(spec, &st) == 0) return 0; /* a file of that name wins */
    double c[3] = {0, 0, 0};
    if (!strncmp(spec, "sphere:", 7)) {
        double r;
        if (vp_cli_parse_double(spec + 7, &r) != 0 || !(r > 0)) return -1;
        return vp_container_create_sphere(ctx, c, r, out) == VP_OK ? 1 : -2;
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
        return vp_container_create_box(ctx, lo, hi, out) == VP_OK ? 1 : -2;
    }
    return 0;
}


int vp_cli_attach_mesh(struct vp_context *ctx, const char *cmd, const char *file,
                       const char *recorded, const char *const *shape_files, int nfiles,
                       struct vp_particles *p, struct vp_mesh_shape **meshes) {
    for (int k = 0; k < VP_MAX_SHAPES; k++) meshes[k] = NULL;
    if (p->shape == VP_SHAPE_MIXED) { /* its mesh shapes, in shape-index order */
        int want = 0;
        for (unsigned k = 0; k < p->shape_count; k++)
            want += p->shapes[k].shape == VP_SHAPE_MESH && !p->shapes[k].mesh;
        if (nfiles != want) {
            if (!want)
                return vp_cli_die(2,
                                  "%s: --shape is for packings with mesh shapes; %s holds "
                                  "none",
                                  cmd, file);
            return vp_cli_die(2,
                              "%s: %s holds %d mesh shape%s: give %s with --shape FILE, in "
                              "the order of its shapes (%d given)",
                              cmd, file, want, want == 1 ? "" : "s", want == 1 ? "it" : "them",
                              nfiles);
        }
        int f = 0;
        for (unsigned k = 0; k < p->shape_count; k++) {
            if (p->shapes[k].shape != VP_SHAPE_MESH || p->shapes[k].mesh) continue;
            if (vp_mesh_shape_load(ctx, shape_files[f], &meshes[f]) != VP_OK)
                return vp_cli_die(1, "%s", vp_context_message(ctx));
            const char *base = strrchr(shape_files[f], '/');
            base = base ? base + 1 : shape_files[f];
            if (p->shape_names[k][0] && strncmp(base, p->shape_names[k], VP_SHAPE_NAME_MAX) != 0)
                fprintf(stderr,
                        "vdbpack: warning: %s: shape %u was the mesh shape '%.*s', not "
                        "'%s'\n",
                        file, k, VP_SHAPE_NAME_MAX, p->shape_names[k], base);
            p->shapes[k].mesh = meshes[f++];
        }
        return 0;
    }
    const char *shape_file = nfiles ? shape_files[0] : NULL;
    if (nfiles > 1) return vp_cli_die(2, "%s: %s holds one shape: one --shape at most", cmd, file);
    if (p->shape == VP_SHAPE_MESH && !shape_file)
        return vp_cli_die(2,
                          "%s: %s holds particles of a mesh shape%s%s%s: give the mesh with "
                          "--shape FILE",
                          cmd, file, recorded[0] ? " (" : "", recorded, recorded[0] ? ")" : "");
    if (shape_file && p->shape != VP_SHAPE_MESH)
        return vp_cli_die(2, "%s: --shape is for packings of a mesh shape; %s holds %s", cmd, file,
                          vp_cli_shape_plural(p->shape));
    if (!shape_file) return 0;
    if (vp_mesh_shape_load(ctx, shape_file, &meshes[0]) != VP_OK)
        return vp_cli_die(1, "%s", vp_context_message(ctx));
    p->mesh = meshes[0];
    /* the file records the mesh's name only: another name is likely the
     * wrong mesh (check then reports its overlaps, render draws it) */
    const char *base = strrchr(shape_file, '/');
    base = base ? base + 1 : shape_file;
    if (recorded[0] && strcmp(base, recorded) != 0)
        fprintf(stderr, "vdbpack: warning: %s was packed with the mesh shape '%s', not '%s'\n",
                file, recorded, base);
    return 0;
}

void vp_cli_divert_stdout(const char *path) {
    struct stat a, b;
    if (stat(path, &a) != 0 || S_ISREG(a.st_mode) || fstat(1, &b) != 0) return;
    if (a.st_dev != b.st_dev || a.st_ino != b.st_ino) return;
    fflush(stdout);
    dup2(2, 1);
}

/* "1 piece", "3 pieces", ... */
static const char *plural(size_t n, const char *one, const char *many) {
    return n == 1 ? one : many;
}

void vp_cli_print_mesh_container(FILE *f, const vp_container_info *ci) {
    fprintf(f,
            "  container: mesh, %zu triangles (%zu vertices after welding %zu), %zu %s, "
            "level-set volume %.6g\n",
            ci->mesh_triangles, ci->mesh_vertices, ci->mesh_vertices_raw, ci->mesh_pieces,
            plural(ci->mesh_pieces, "piece", "pieces"), ci->volume);
    if (ci->inside == VP_INSIDE_WINDING) {
        fprintf(f,
                "  inside: by winding number (%zu boundary, %zu non-manifold, %zu inconsistently "
                "oriented edges)",
                ci->boundary_edges, ci->nonmanifold_edges, ci->inconsistent_edges);
        size_t mended = ci->duplicate_triangles + ci->opposite_triangles +
                        ci->reoriented_triangles + ci->turned_pieces + ci->cavities;
        if (mended) {
            const char *sep = "; ";
            if (ci->duplicate_triangles) {
                fprintf(f, "%s%zu duplicate %s dropped", sep, ci->duplicate_triangles,
                        plural(ci->duplicate_triangles, "triangle", "triangles"));
                sep = ", ";
            }
            if (ci->opposite_triangles) {
                fprintf(f, "%s%zu back-to-back triangles dropped", sep, ci->opposite_triangles);
                sep = ", ";
            }
            if (ci->reoriented_triangles) {
                fprintf(f, "%s%zu %s turned to agree with their neighbours", sep,
                        ci->reoriented_triangles,
                        plural(ci->reoriented_triangles, "triangle", "triangles"));
                sep = ", ";
            }
            if (ci->turned_pieces) {
                fprintf(f, "%s%zu inside-out %s turned", sep, ci->turned_pieces,
                        plural(ci->turned_pieces, "piece", "pieces"));
                sep = ", ";
            }
            if (ci->cavities)
                fprintf(f, "%s%zu reversed inner %s kept as %s", sep, ci->cavities,
                        plural(ci->cavities, "shell", "shells"),
                        plural(ci->cavities, "a cavity", "cavities"));
        }
        fputc('\n', f);
    } else {
        fprintf(f, "  inside: closed surface (OpenVDB's voxelization)\n");
    }
    if (ci->volume_estimate_kind != VP_ESTIMATE_NONE)
        fprintf(f, "  volume estimate %.6g (%s)\n", ci->volume_estimate,
                ci->volume_estimate_kind == VP_ESTIMATE_MESH_VOLUME
                    ? "the mesh's signed volume"
                    : "winding number on a 64-sample grid");
}

void vp_cli_warn_container(const vp_container_info *ci) {
    if (!ci->volume_mismatch) return;
    double rel = ci->volume_estimate > 0
                     ? 100.0 * (ci->volume - ci->volume_estimate) / ci->volume_estimate
                     : 0.0;
    fprintf(stderr,
            "vdbpack: warning: the container's inside (volume %.6g) differs from the %s "
            "(%.6g) by %+.1f %%: the voxel size %g may lose thin parts (try a smaller "
            "--voxel-size), or the mesh is broken in a way its inside cannot mend\n",
            ci->volume,
            ci->volume_estimate_kind == VP_ESTIMATE_MESH_VOLUME ? "mesh's signed volume"
                                                                : "volume its winding number gives",
            ci->volume_estimate, rel, ci->voxel_size);
}

/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack render FILE.vdb -o IMAGE.exr|.png`: a preview of a packing, and
 * the preview that `vdbpack pack --preview` writes. */
#include "vdbpack/vdbpack.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli/cli.h"

const char *VP_RENDER_HELP =
    "Usage: vdbpack render FILE.vdb -o IMAGE.exr|IMAGE.png [options]\n"
    "\n"
    "Ray-traces the particles of FILE.vdb (its \"points\" grid: spheres, or the\n"
    "platonic solid of its shape metadata with each particle's orient) with a key\n"
    "light, hard shadows and ambient occlusion. OpenEXR: channels R, G, B, A, Z\n"
    "(distance from the eye, +inf on the background) and id (the particle's id,\n"
    "4294967295 on the background); PNG: 8-bit sRGB with alpha.\n"
    "\n"
    "  -o, --output FILE       the image, .exr or .png (required)\n"
    "  --size WxH              image size in pixels (default 960x540; each side at\n"
    "                          most 16384, at most 67108864 pixels)\n"
    "  --view NAME             iso (default), front (from +Z) or top (from +Y); the\n"
    "                          camera frames all particles\n"
    "  --camera EX,EY,EZ:TX,TY,TZ   instead of --view: eye and target points (+Y up)\n"
    "  --fov DEG               vertical field of view in degrees (default 30)\n"
    "  --colour NAME           pass (default: one colour per point group), size (by\n"
    "                          radius), id (a colour per particle) or contacts\n"
    "                          (spheres: neighbours touched within 1e-4 of r_i +\n"
    "                          r_j; grey below 4, blue 4, cyan 5, green 6, yellow\n"
    "                          7, red 8+)\n"
    "  --cut AXIS:VALUE        remove everything where x, y or z > VALUE; particles\n"
    "                          crossing the plane show their cut faces\n"
    "  --ao N                  ambient-occlusion rays per pixel (default 8, 0..64)\n"
    "  --shape FILE            the particle mesh, for packings of a mesh shape (the\n"
    "                          one given to pack --shape; required for them); a\n"
    "                          packing of several shapes: once per mesh shape, in\n"
    "                          the order of its shapes metadata\n"
    "  --threads N             worker threads (default: all cores); the image does\n"
    "                          not depend on it\n"
    "  -q, --quiet             print nothing but errors\n"
    "  -h, --help              this text\n";

/* "WxH" with both sides positive whole numbers (the range is vp_render's). */
/* 1 when out is one of files[0..n). */
static int same_as_any(const char *out, const char *const *files, int n) {
    for (int k = 0; k < n; k++)
        if (vp_cli_same_file(out, files[k])) return 1;
    return 0;
}

static int parse_size(const char *s, int *w, int *h) {
    char *end;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X') || !isdigit((unsigned char)*s)) return -1;
    const char *t = end + 1;
    long b = strtol(t, &end, 10);
    if (end == t || *end || !isdigit((unsigned char)*t)) return -1;
    if (a < 1 || b < 1 || a > VP_RENDER_MAX_SIDE || b > VP_RENDER_MAX_SIDE ||
        (unsigned long long)a * (unsigned long long)b > VP_RENDER_MAX_PIXELS)
        return -2;
    *w = (int)a;
    *h = (int)b;
    return 0;
}

static int parse_vec3(const char *s, double v[3]) {
    char buf[256];
    if (strlen(s) >= sizeof buf) return -1;
    strcpy(buf, s);
    char *save = NULL, *tok = strtok_r(buf, ",", &save);
    for (int k = 0; k < 3; k++) {
        if (!tok || vp_cli_parse_double(tok, &v[k]) != 0) return -1;
        tok = strtok_r(NULL, ",", &save);
    }
    return tok ? -1 : 0;
}

static int parse_camera(const char *s, vp_render_params *rp) {
    const char *colon = strchr(s, ':');
    if (!colon || strchr(colon + 1, ':')) return -1;
    char eye[256];
    size_t n = (size_t)(colon - s);
    if (n >= sizeof eye) return -1;
    memcpy(eye, s, n);
    eye[n] = 0;
    if (parse_vec3(eye, rp->eye) != 0 || parse_vec3(colon + 1, rp->target) != 0) return -1;
    if (rp->eye[0] == rp->target[0] && rp->eye[1] == rp->target[1] && rp->eye[2] == rp->target[2])
        return -1;
    rp->view = VP_VIEW_CAMERA;
    return 0;
}

static int parse_cut(const char *s, vp_render_params *rp) {
    int axis = -1;
    char a = (char)tolower((unsigned char)s[0]);
    if (a == 'x') axis = 0;
    else if (a == 'y') axis = 1;
    else if (a == 'z') axis = 2;
    if (axis < 0 || s[1] != ':' || vp_cli_parse_double(s + 2, &rp->cut_value) != 0) return -1;
    rp->cut_axis = axis;
    return 0;
}

static int image_ext_ok(const char *path) {
    size_t n = strlen(path);
    if (n < 5) return 0;
    const char *e = path + n - 4;
    return !strcasecmp(e, ".exr") || !strcasecmp(e, ".png");
}

int vp_cli_preview_path_check(const char *opt, const char *path) {
    if (!image_ext_ok(path)) return vp_cli_die(2, "%s: '%s' must end in .exr or .png", opt, path);
    return 0;
}

int vp_cli_render_particles(vp_context *ctx, const vp_particles *p, const vp_render_params *rp,
                            const char *path) {
    vp_image *img = NULL;
    if (vp_render(ctx, p, rp, &img) != VP_OK) return 1;
    vp_result r = vp_image_write(ctx, img, path);
    vp_image_destroy(img);
    if (r != VP_OK) return 1;
    vp_cli_divert_stdout(path);
    return 0;
}

static int on_progress(void *user, double fraction, const char *stage) {
    (void)user, (void)fraction, (void)stage;
    return !vp_cli_interrupted();
}

int vp_cli_render(int argc, char **argv) {
    const char *file = NULL, *out = NULL, *shape_files[VP_MAX_SHAPES] = {NULL};
    int nshape_files = 0;
    int quiet = 0, view_set = 0, camera_set = 0;
    uint64_t threads = 0;
    vp_render_params rp;
    vp_render_params_init(&rp);
    vp_cli_seen seen = {0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED()                                                                                     \
    do {                                                                                           \
        if (!v) return vp_cli_die(2, "render: %s needs a value", a);                               \
        if (vp_cli_once(&seen, "render", a, v)) return 2;                                          \
        i++;                                                                                       \
    } while (0)
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(VP_RENDER_HELP, stdout);
            return 0;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            NEED();
            out = v;
        } else if (!strcmp(a, "--size")) {
            NEED();
            int rc = parse_size(v, &rp.width, &rp.height);
            if (rc == -1)
                return vp_cli_die(2, "render: --size must be WxH (e.g. 1920x1080), not '%s'", v);
            if (rc == -2)
                return vp_cli_die(2,
                                  "render: --size %s is out of range (each side 1..%d, at most "
                                  "%u pixels)",
                                  v, VP_RENDER_MAX_SIDE, VP_RENDER_MAX_PIXELS);
        } else if (!strcmp(a, "--view")) {
            NEED();
            if (!strcmp(v, "iso")) rp.view = VP_VIEW_ISO;
            else if (!strcmp(v, "front")) rp.view = VP_VIEW_FRONT;
            else if (!strcmp(v, "top")) rp.view = VP_VIEW_TOP;
            else return vp_cli_die(2, "render: unknown --view '%s' (iso, front, top)", v);
            view_set = 1;
        } else if (!strcmp(a, "--camera")) {
            NEED();
            if (parse_camera(v, &rp) != 0)
                return vp_cli_die(2,
                                  "render: --camera must be EX,EY,EZ:TX,TY,TZ with distinct "
                                  "finite points, not '%s'",
                                  v);
            camera_set = 1;
        } else if (!strcmp(a, "--fov")) {
            NEED();
            if (vp_cli_parse_double(v, &rp.fov_degrees) != 0 || !(rp.fov_degrees >= 1) ||
                !(rp.fov_degrees <= 170))
                return vp_cli_die(2,
                                  "render: --fov must be a number of degrees in 1..170, not "
                                  "'%s'",
                                  v);
        } else if (!strcmp(a, "--colour") || !strcmp(a, "--color")) {
            NEED();
            if (!strcmp(v, "pass")) rp.colour = VP_COLOUR_PASS;
            else if (!strcmp(v, "size")) rp.colour = VP_COLOUR_SIZE;
            else if (!strcmp(v, "contacts")) rp.colour = VP_COLOUR_CONTACTS;
            else if (!strcmp(v, "id")) rp.colour = VP_COLOUR_ID;
            else
                return vp_cli_die(2, "render: unknown --colour '%s' (pass, size, id, contacts)", v);
        } else if (!strcmp(a, "--cut")) {
            NEED();
            if (parse_cut(v, &rp) != 0)
                return vp_cli_die(2,
                                  "render: --cut must be AXIS:VALUE with AXIS x, y or z "
                                  "(e.g. x:0.5), not '%s'",
                                  v);
        } else if (!strcmp(a, "--shape")) { /* once per mesh shape of a mixed set */
            if (!v) return vp_cli_die(2, "render: %s needs a value", a);
            i++;
            if (nshape_files == VP_MAX_SHAPES)
                return vp_cli_die(2, "%s: at most %d --shape options", "render", VP_MAX_SHAPES);
            shape_files[nshape_files++] = v;
        } else if (!strcmp(a, "--ao")) {
            NEED();
            uint64_t n;
            if (vp_cli_parse_u64(v, &n) != 0 || n > 64)
                return vp_cli_die(2, "render: --ao must be a whole number in 0..64, not '%s'", v);
            rp.ao_samples = (int)n;
        } else if (!strcmp(a, "--threads")) {
            NEED();
            if (vp_cli_parse_u64(v, &threads) != 0 || threads == 0 || threads > 256)
                return vp_cli_die(2,
                                  "render: --threads must be a whole number in 1..256, not "
                                  "'%s'",
                                  v);
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (a[0] == '-' && a[1]) {
            return vp_cli_die(2, "render: unknown option '%s' (see vdbpack render --help)", a);
        } else if (!file) {
            file = a;
        } else {
            return vp_cli_die(2, "render: more than one file given ('%s')", a);
        }
#undef NEED
    }
    if (!file || !*file) return vp_cli_die(2, "render: no file given (see vdbpack render --help)");
    if (!out) return vp_cli_die(2, "render: no output given: use -o IMAGE.exr or IMAGE.png");
    if (view_set && camera_set) return vp_cli_die(2, "render: give either --view or --camera");
    int rc = vp_cli_preview_path_check("render: -o", out);
    if (rc) return rc;
    /* by the file each resolves to: a.png can be a link to the packing */
    if (vp_cli_same_file(out, file) || same_as_any(out, shape_files, nshape_files))
        return vp_cli_die(2, "render: -o %s is the %s itself: writing would replace it", out,
                          vp_cli_same_file(out, file) ? "packing it renders" : "--shape mesh");

    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return vp_cli_die(1, "out of memory");
    if (threads) vp_context_set_threads(ctx, (int)threads);
    /* SIGINT/SIGTERM cancel through the progress callback; past ulimit -f
     * the writers fail and clean up instead of the process dying */
    vp_cli_signals_install();
    vp_context_set_progress(ctx, on_progress, NULL);
    int status = 1;
    vp_particles *p = NULL;
    vp_mesh_shape *meshes[VP_MAX_SHAPES] = {NULL};
    if (vp_read_points(ctx, file, &p) != VP_OK) {
        status = vp_cli_die(1, "%s", vp_context_message(ctx));
        goto done;
    }
    if (p->count == 0) {
        status = vp_cli_die(1, "%s: the points grid holds no particles: nothing to render", file);
        goto done;
    }
    if ((status = vp_cli_attach_mesh(ctx, "render", file, "", shape_files, nshape_files, p,
                                     meshes)) != 0)
        goto done;
    status = 1;
    status = vp_cli_finish_output(ctx, vp_cli_render_particles(ctx, p, &rp, out) != 0, out);
    if (status) goto done;
    if (!quiet)
        printf("vdbpack: rendered %zu particle%s of %s into %s (%dx%d)\n", p->count,
               p->count == 1 ? "" : "s", file, out, rp.width, rp.height);
    /* the summary lost (stdout on a full disk): an error, which leaves no
     * output */
    if ((status = vp_cli_flush_stdout(0)) != 0) vp_remove_output(out);
done:
    vp_particles_destroy(p);
    for (int k = 0; k < VP_MAX_SHAPES; k++) vp_mesh_shape_destroy(meshes[k]);
    vp_context_destroy(ctx);
    return status;
}

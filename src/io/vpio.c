/* SPDX-License-Identifier: Apache-2.0 */
/* The helpers the writers and readers of src/io share (io_internal.h):
 * opening and closing files, checks of the particles to write and of the
 * values read, and the particles a reader fills. */
#include "io/io_internal.h"
#include "core/context.h"
#include "core/superball.h"
#include "os/input.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

vp_result vpio_open(vp_context *ctx, const char *path, vpio_out *o) {
    memset(o, 0, sizeof *o);
    o->path = path;
    vp_result r = vp_atomic_begin(ctx, path, &o->a);
    if (r != VP_OK) return r;
    o->f = fopen(o->a.tmp_path, "wb");
    if (!o->f) {
        int e = errno;
        vp_atomic_abort(&o->a);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write (%s)", path, strerror(e));
    }
    o->buf = malloc(1 << 20);
    if (o->buf) setvbuf(o->f, o->buf, _IOFBF, 1 << 20);
    return VP_OK;
}

vp_result vpio_open_read(vp_context *ctx, const char *path, FILE **f) {
    /* without blocking: fopen() of a FIFO waits for its writer */
    char msg[1024];
    int fd = vp_os_open_input(path, msg, sizeof msg);
    if (fd < 0) {
        *f = NULL;
        return vp_fail(ctx, VP_ERR_IO, "%s", msg);
    }
    *f = fdopen(fd, "rb");
    if (!*f) {
        int e = errno;
        close(fd);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot open (%s)", path, strerror(e));
    }
    return VP_OK;
}

vp_result vpio_close(vp_context *ctx, vpio_out *o, int bad) {
    int e = 0;
    if (ferror(o->f)) bad = 1, e = errno;
    if (fclose(o->f) != 0 && !bad) bad = 1, e = errno;
    o->f = NULL;
    free(o->buf);
    o->buf = NULL;
    if (bad) {
        vp_atomic_abort(&o->a);
        if (e) return vp_fail(ctx, VP_ERR_IO, "%s: writing failed (%s)", o->path, strerror(e));
        return vp_fail(ctx, VP_ERR_IO, "%s: writing failed", o->path);
    }
    return vp_atomic_commit(ctx, &o->a);
}

vp_result vpio_check_particles(vp_context *ctx, const char *path, const vp_particles *p) {
    if (p->group_count < 1 || p->group_count > VP_MAX_GROUPS)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: %u groups (1 to %d)", path,
                       p->group_count, VP_MAX_GROUPS);
    if (p->count && !p->positions)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: particles without positions", path);
    if (p->groups)
        for (size_t i = 0; i < p->count; i++)
            if (p->groups[i] >= p->group_count)
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: particle %zu is in group %u of %u", path, i,
                               (unsigned)p->groups[i], p->group_count);
    if (p->count > 2147483647u)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: %zu particles (ids are int32: at most "
                       "2147483647)",
                       path, p->count);
    return VP_OK;
}

vp_result vpio_check_writable(vp_context *ctx, const char *path, const vp_particles *p, int floats,
                              const char *format) {
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double r = (double)vpio_radius(p, i);
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "%s: particle %zu: its position (%g %g %g) is not finite; nothing "
                           "written",
                           path, i, x[0], x[1], x[2]);
        if (!isfinite(r) || !(r > 0))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "%s: particle %zu: its radius %g is not a positive number; nothing "
                           "written",
                           path, i, r);
        for (int k = 0; floats && k < 3; k++)
            if (!(fabs(x[k]) + (floats == 2 ? r : 0.0) <= FLT_MAX))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: particle %zu: its coordinate %g is beyond the 32-bit floats "
                               "%s holds (at most %.3g); nothing written (.csv keeps it)",
                               path, i, x[k], format, (double)FLT_MAX);
        if (p->has_orient) {
            const float *q = vpio_orient(p, i);
            double n = 0;
            for (int c = 0; c < 4; c++) n += (double)q[c] * (double)q[c];
            if (!(fabs(sqrt(n) - 1) <= 1e-3))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: particle %zu: its orient (%g %g %g %g) is not a finite unit "
                               "quaternion; nothing written",
                               path, i, (double)q[0], (double)q[1], (double)q[2], (double)q[3]);
        }
    }
    return VP_OK;
}

int vpio_valid_group_name(const char *s, size_t n) {
    if (n == 0 || n >= VP_GROUP_NAME_MAX) return 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '|' || c == ':'))
            return 0;
    }
    return 1;
}

vp_result vpio_check_values(vp_context *ctx, const char *path, const char *what, size_t k,
                            const double x[3], double pscale, const double *q) {
    if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: position is not finite (%g %g %g)", path,
                       what, k, x[0], x[1], x[2]);
    if (!isfinite(pscale) || !(pscale > 0))
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: pscale %g is not a positive number", path,
                       what, k, pscale);
    if (q) {
        double n = 0;
        for (int c = 0; c < 4; c++) {
            if (!isfinite(q[c]))
                return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: orient is not finite", path, what,
                               k);
            n += q[c] * q[c];
        }
        if (!(fabs(sqrt(n) - 1) <= 1e-3))
            return vp_fail(ctx, VP_ERR_FORMAT,
                           "%s: %s %zu: orient (%g %g %g %g) is not a unit "
                           "quaternion",
                           path, what, k, q[0], q[1], q[2], q[3]);
    }
    return VP_OK;
}

vp_particles *vpio_alloc(size_t n, int with_orient) {
    vp_particles *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    size_t m = n ? n : 1;
    p->positions = malloc(m * 3 * sizeof(double));
    p->radii = malloc(m * sizeof(float));
    p->groups = calloc(m, sizeof(uint16_t));
    if (with_orient) p->orients = malloc(m * 4 * sizeof(float));
    if (!p->positions || !p->radii || !p->groups || (with_orient && !p->orients)) {
        vp_particles_destroy(p);
        return NULL;
    }
    p->count = p->capacity = n;
    p->has_orient = with_orient;
    p->uniform_orient[3] = 1.0f;
    p->shape = VP_SHAPE_SPHERE;
    p->group_count = 1;
    strcpy(p->group_names[0], "pass1");
    return p;
}

vp_result vpio_place_id(vp_context *ctx, const char *path, const char *what, size_t k, long long id,
                        size_t n, unsigned char *seen) {
    if (id < 0 || (unsigned long long)id >= n)
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "%s: %s %zu: id %lld is not in 0..%zu (ids must be "
                       "0..N-1 once each)",
                       path, what, k, id, n ? n - 1 : 0);
    if (seen[id])
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: id %lld appears twice", path, what, k, id);
    seen[id] = 1;
    return VP_OK;
}

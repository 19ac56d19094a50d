/* SPDX-License-Identifier: Apache-2.0 */
/* OpenVDB's file reader in a throw-away child process first (see probe.c).
 * Internal to src/api. */
#ifndef VDBPACK_API_PROBE_H
#define VDBPACK_API_PROBE_H

#include "vdbpack/vdbpack.h"

/* A read to try: returns a vp_result code and writes a one-line message to
 * err on failure; frees whatever it read. */
typedef int (*vp_probe_fn)(const void *arg, char *err, size_t errlen);

/* Runs fn(arg) in a forked child with a deadline ($VDBPACK_READ_TIMEOUT
 * seconds, else 30 s + 1 s per MB of path's size). VP_OK: the child read
 * the file without error, the caller may now read it in-process. Otherwise
 * the child's own error, or one line saying that OpenVDB's reader crashed
 * (by signal) or hung on path; ctx holds the message. Returns VP_OK at once
 * in fuzz and ASan builds (see os/subproc.h), when $VDBPACK_VDB_PROBE
 * is 0, and when TBB cannot end its worker threads before the fork (another
 * thread is inside a TBB algorithm): a child forked beside them would hang. */
vp_result vp_probe_read(vp_context *ctx, const char *path, vp_probe_fn fn, const void *arg);
#endif

/* SPDX-License-Identifier: Apache-2.0 */
/* Opening input files without blocking: a FIFO (or a device, a socket, a
 * directory) given as a container, a mesh or a particle file is refused
 * with one line at once, instead of blocking in open() or read() until a
 * writer comes. Operating-system layer. */
#ifndef VDBPACK_OS_INPUT_H
#define VDBPACK_OS_INPUT_H

#include <stddef.h>

/* Opens path read-only (close-on-exec) with O_NONBLOCK, so that open()
 * itself does not wait for a FIFO's writer, and refuses anything fstat
 * does not call a regular file. Returns the descriptor (O_NONBLOCK cleared
 * again; the caller closes it), or -1 with one line in msg naming path:
 * "PATH: cannot open file (REASON)" or "PATH: not a regular file but a
 * FIFO (named pipe): ...". The line is shortened in the middle when path
 * is long (vp_os_format). */
int vp_os_open_input(const char *path, char *msg, size_t msglen);
/* The same check, closing the file again: 0, or -1 with msg. For inputs
 * that a third-party reader opens by name (Assimp, OpenVDB). */
int vp_os_check_input(const char *path, char *msg, size_t msglen);
#endif

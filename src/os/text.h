/* SPDX-License-Identifier: Apache-2.0 */
/* One-line messages into fixed buffers that keep their end: a message
 * longer than its buffer (a path of 4000 bytes in a 1024-byte context
 * message) loses bytes from its middle, shown as "...", so that the
 * reason at its end survives (vsnprintf alone cut it off). Operating-
 * system layer. */
#ifndef VDBPACK_OS_TEXT_H
#define VDBPACK_OS_TEXT_H

#include <stdarg.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* vsnprintf into out[len] (len >= 1), but when the whole text does not fit
 * it keeps about its first third and its last two thirds around "...",
 * never splitting a UTF-8 character. Returns out. */
char *vp_os_vformat(char *out, size_t len, const char *fmt, va_list ap);
char *vp_os_format(char *out, size_t len, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Shortens the text in buf (NUL-terminated) to fit len bytes as
 * vp_os_vformat does, in place when buf == out. */
void vp_os_shorten(char *out, size_t len, const char *text);

#ifdef __cplusplus
}
#endif
#endif

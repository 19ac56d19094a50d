/* SPDX-License-Identifier: Apache-2.0 */
/* See text.h. */
#include "os/text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A UTF-8 continuation byte (10xxxxxx). */
static int cont(unsigned char c) { return (c & 0xC0) == 0x80; }

void vp_os_shorten(char *out, size_t len, const char *text) {
    if (!out || !len) return;
    size_t n = strlen(text);
    if (n < len) {
        memmove(out, text, n + 1);
        return;
    }
    static const char dots[] = "...";
    if (len < sizeof dots + 2) { /* no room for the middle: cut */
        memmove(out, text, len - 1);
        out[len - 1] = 0;
        return;
    }
    size_t room = len - 1 - (sizeof dots - 1);
    size_t head = room / 3, tail = room - head;
    while (head > 0 && cont((unsigned char)text[head])) head--;
    size_t from = n - tail;
    while (from < n && cont((unsigned char)text[from])) from++;
    /* (out may be text: the tail moves first, to the right of the head) */
    memmove(out + head + (sizeof dots - 1), text + from, n - from + 1);
    if (out != text) memmove(out, text, head);
    memcpy(out + head, dots, sizeof dots - 1);
}

char *vp_os_vformat(char *out, size_t len, const char *fmt, va_list ap) {
    if (!out || !len) return out;
    va_list copy;
    va_copy(copy, ap);
    int n = vsnprintf(out, len, fmt, ap);
    if (n >= 0 && (size_t)n >= len) {
        char *full = malloc((size_t)n + 1);
        if (full) {
            vsnprintf(full, (size_t)n + 1, fmt, copy);
            vp_os_shorten(out, len, full);
            free(full);
        }
    }
    va_end(copy);
    return out;
}

char *vp_os_format(char *out, size_t len, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vp_os_vformat(out, len, fmt, ap);
    va_end(ap);
    return out;
}

/* SPDX-License-Identifier: Apache-2.0 */
/* Memory hints for large arrays read at random. Internal to the core. */
#ifndef VDBPACK_CORE_BIGMEM_H
#define VDBPACK_CORE_BIGMEM_H

#include <stddef.h>

/* Asks the kernel to back [p, p + bytes) with huge pages where it can
 * (Linux transparent huge pages in "madvise" mode, Debian's default). The
 * random packers read particle positions and the neighbour grid at
 * random in arrays of tens of MB: with 4 KiB pages nearly every such read
 * also misses the TLB. (Their active cells are read at random too, but
 * not advised: whole resident pages cost 3 B/particle there.) Only whole 2 MiB pages inside the
 * range are advised; smaller arrays, other systems and refusals are left
 * alone (a hint: nothing depends on it). Call again after a realloc. */
void vp_mem_advise_random(void *p, size_t bytes);
#endif

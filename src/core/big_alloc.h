/* Allocation of large arrays that a computation reads many times (the
 * equilibrium solver's matrices and vectors on webs of 100k-1M particles;
 * scratch written once stays on malloc): see big_alloc.c for why. Internal
 * to the library; memory from either function is released with free(). */
#ifndef SPN_BIG_ALLOC_H
#define SPN_BIG_ALLOC_H

#include <stddef.h>

/* With SPN_HUGE_PAGES=1 in the environment, requests of at least this many
 * bytes are placed on huge pages where the system has them (big_alloc.c
 * says why it is opt-in); otherwise, and for smaller ones, plain malloc. */
#define SPN__BIG_MIN ((size_t)4 << 20)

/* Like malloc (never NULL for 0 bytes: one byte is given). NULL when the
 * memory is not there or bytes exceeds PTRDIFF_MAX. */
void *spn__big_alloc(size_t bytes);
/* Like calloc: count * size bytes, zeroed; NULL also when the product
 * overflows. */
void *spn__big_calloc(size_t count, size_t size);

#endif

/* Large arrays on transparent huge pages.
 *
 * Why: the equilibrium solve of a 1M-particle web allocates about 4 GB in
 * ~100 arrays of 10-400 MB. Each first touch of a 4 KiB page is a page
 * fault that clears the page; in a virtual machine the host backs the page
 * too. Measured on a 2-core KVM guest: 1.06 million faults in one solve,
 * 14% of its 28.5 s in the kernel's page clearing and ~2% more in fault
 * handling (docs/physics-equilibrium.md). A 2 MiB huge page is one fault
 * instead of 512, and one TLB entry instead of 512 for the sparse
 * products' scattered reads.
 *
 * How: on Linux a request of at least SPN__BIG_MIN bytes is allocated
 * 2 MiB-aligned (so the whole range can be huge pages) and advised
 * MADV_HUGEPAGE. That asks for huge pages under the kernel's default THP
 * setting ("madvise"); under "never" the advice is ignored and the memory is
 * ordinary. Elsewhere, and for smaller requests, plain malloc. The memory
 * comes from the C library's allocator either way, so free() releases it.
 * The advice only changes how pages are backed, never their contents. */
#define _DEFAULT_SOURCE /* madvise and MADV_HUGEPAGE under -std=c11 */
#include "core/big_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#if defined(__linux__) && defined(MADV_HUGEPAGE)
#define HUGE_PAGE ((size_t)2 << 20)

static void *huge_alloc(size_t bytes)
{
    void *p = NULL;
    if (posix_memalign(&p, HUGE_PAGE, bytes) != 0) return NULL;
    /* advice only: if the kernel refuses it the memory is still good */
    (void)madvise(p, bytes, MADV_HUGEPAGE);
    return p;
}
#endif

void *spn__big_alloc(size_t bytes)
{
    if (bytes > PTRDIFF_MAX) return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= SPN__BIG_MIN) return huge_alloc(bytes);
#endif
    return malloc(bytes ? bytes : 1);
}

void *spn__big_calloc(size_t count, size_t size)
{
    if (size && count > PTRDIFF_MAX / size) return NULL;
    size_t bytes = count * size;
    if (!bytes) return calloc(1, 1);
    /* calloc, not huge_alloc and memset: fresh pages from the kernel are
     * zero already, and calloc knows when it has them, so pages the caller
     * never writes are never touched (a memset made 130 MB more resident on
     * the 1M web). The advice covers the 2 MiB-aligned middle of the block. */
    unsigned char *p = calloc(count, size);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (p && bytes >= SPN__BIG_MIN) {
        uintptr_t lo = ((uintptr_t)p + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
        uintptr_t hi = ((uintptr_t)p + bytes) & ~(uintptr_t)(HUGE_PAGE - 1);
        if (hi > lo) (void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
    }
#endif
    return p;
}

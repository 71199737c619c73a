/* Large arrays on transparent huge pages.
 *
 * Why: the equilibrium solve of a 1M-particle web keeps about 2.5 GB in
 * arrays of 10-400 MB that every CG iteration reads again, in gathers
 * through index arrays. On 4 KiB pages that was 1.06 million page faults
 * per solve and a TLB miss (a two-level page walk in a virtual machine)
 * wherever a gather leaves its page. A 2 MiB huge page is one fault
 * instead of 512 and one TLB entry instead of 512: the level-0 product
 * of the 1M solve ran in 3.3 s instead of 4.0-4.1 s
 * (docs/physics-equilibrium.md, "Memory").
 *
 * How: on Linux a request of at least SPN__BIG_MIN bytes is allocated
 * 2 MiB-aligned (so the whole range can be huge pages) and advised
 * MADV_HUGEPAGE. That asks for huge pages under the kernel's default THP
 * setting ("madvise"); under "never" the advice is ignored and the memory is
 * ordinary. Elsewhere, and for smaller requests, plain malloc. The memory
 * comes from the C library's allocator either way, so free() releases it.
 * The advice only changes how pages are backed, never their contents.
 *
 * For arrays that are read again and again, not for scratch written once:
 * where free memory is handed back to the host (a VM with page reporting,
 * as the one measured), a huge page comes back fresh from the host and
 * its first touch costs about four times that of small pages.
 *
 * Opt-in: only with the environment variable SPN_HUGE_PAGES=1. On the
 * machine measured (a KVM guest) the balance moved with the host's state:
 * one afternoon the 1M solve's kernel time fell from 2.3 s to 1.7-2.1 s
 * with the advice; an hour later, on an idle machine, it rose from 2.0-2.3 s
 * to 4.4-5.0 s while the user time fell 1.3 s, 24.9-25.3 s against
 * 23.6-24.4 s without it (four and five runs). On bare metal, where a fresh
 * huge page costs what its 512 small pages cost, it should pay; there it
 * is one variable away. Without it these are malloc and calloc. */
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

/* SPN_HUGE_PAGES=1 in the environment (read at each large request, so a
 * program may set it before its first solve) */
static int huge_wanted(void)
{
    const char *e = getenv("SPN_HUGE_PAGES");
    return e && strcmp(e, "1") == 0;
}

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
    if (bytes >= SPN__BIG_MIN && huge_wanted()) return huge_alloc(bytes);
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
    if (p && bytes >= SPN__BIG_MIN && huge_wanted()) {
        uintptr_t lo = ((uintptr_t)p + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
        uintptr_t hi = ((uintptr_t)p + bytes) & ~(uintptr_t)(HUGE_PAGE - 1);
        if (hi > lo) (void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
    }
#endif
    return p;
}

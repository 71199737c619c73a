/* spn__big_alloc / spn__big_calloc (src/core/big_alloc.c): the memory is
 * usable end to end, the calloc form is zeroed even where freed dirty memory
 * could come back, large blocks are 2 MiB-aligned where huge pages are
 * asked for (SPN_HUGE_PAGES=1), and impossible requests give NULL instead
 * of aborting, with huge pages asked for or not. */
#define _DEFAULT_SOURCE /* MADV_HUGEPAGE, as big_alloc.c sees it */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "core/big_alloc.h"

/* AddressSanitizer stops the program on a request it cannot serve instead
 * of returning NULL (unless told allocator_may_return_null=1): there only
 * the requests big_alloc refuses itself are tried. */
#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANITIZED 1
#endif
#endif
#ifndef SANITIZED
#define SANITIZED 0
#endif

static void fill_and_check(unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i++) p[i] = (unsigned char)(i * 31u + seed);
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) bad += p[i] != (unsigned char)(i * 31u + seed);
    assert_int_equal(bad, 0);
}

static void test_usable(void **state)
{
    (void)state;
    assert_int_equal(setenv("SPN_HUGE_PAGES", "1", 1), 0);
    const size_t sizes[] = {0, 1, 4096, SPN__BIG_MIN - 1, SPN__BIG_MIN, 3 * SPN__BIG_MIN + 12345};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        unsigned char *p = spn__big_alloc(sizes[k]);
        assert_non_null(p);
        fill_and_check(p, sizes[k], (unsigned)k);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        if (sizes[k] >= SPN__BIG_MIN) assert_int_equal((uintptr_t)p % ((uintptr_t)2 << 20), 0);
#endif
        free(p);
    }
    /* without the variable: plain malloc, usable all the same */
    assert_int_equal(unsetenv("SPN_HUGE_PAGES"), 0);
    unsigned char *q = spn__big_alloc(SPN__BIG_MIN + 1);
    assert_non_null(q);
    fill_and_check(q, SPN__BIG_MIN + 1, 3);
    free(q);
}

static bool all_zero(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i]) return false;
    return true;
}

static void test_calloc_zeroed(void **state)
{
    (void)state;
    assert_int_equal(setenv("SPN_HUGE_PAGES", "1", 1), 0);
    const size_t counts[] = {0, 1, 1000, SPN__BIG_MIN / 8, 5 * SPN__BIG_MIN / 8 + 3};
    for (size_t k = 0; k < sizeof counts / sizeof *counts; k++) {
        size_t bytes = counts[k] * sizeof(double);
        /* dirty a block of the same size and free it, so the allocator may hand it back */
        unsigned char *dirty = spn__big_alloc(bytes);
        assert_non_null(dirty);
        memset(dirty, 0xA5, bytes);
        free(dirty);
        double *p = spn__big_calloc(counts[k], sizeof *p);
        assert_non_null(p);
        assert_true(all_zero((const unsigned char *)p, bytes));
        fill_and_check((unsigned char *)p, bytes, 7);
        free(p);
    }
}

static void test_impossible_requests_fail_cleanly(void **state)
{
    (void)state;
    assert_int_equal(setenv("SPN_HUGE_PAGES", "1", 1), 0);
    assert_null(spn__big_alloc(SIZE_MAX));
    assert_null(spn__big_alloc((size_t)PTRDIFF_MAX + 1));
    assert_null(spn__big_calloc(SIZE_MAX / 2, 4)); /* the product overflows */
    assert_null(spn__big_calloc(4, SIZE_MAX / 2));
    if (!SANITIZED) { /* within range, but no machine has it */
        assert_null(spn__big_alloc((size_t)PTRDIFF_MAX / 2));
        assert_null(spn__big_calloc((size_t)PTRDIFF_MAX / 16, 8));
    }
    /* and the allocator still works afterwards */
    void *p = spn__big_alloc(SPN__BIG_MIN);
    assert_non_null(p);
    free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_usable),
        cmocka_unit_test(test_calloc_zeroed),
        cmocka_unit_test(test_impossible_requests_fail_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The batched complex FFT (physics/fft.h): against a direct DFT in long
 * double for every length to 64 and some larger ones (powers of 2, 3, 5 and
 * 7, mixed factors, a prime) in both directions, the round trip, the same
 * bits whichever column range a call covers with the other columns left
 * alone, and the refused length 0; each for the
 * mixed-radix and the chirp (Bluestein) plans, and which one auto takes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "physics/fft.h"

static const uint32_t big_sizes[] = {100, 125, 128, 243, 343, 1000, 1001, 997};

/* Pseudo-random numbers in [-1, 1) (xorshift64, a fixed seed per caller). */
static double uniform(uint64_t *x)
{
    *x ^= *x << 13;
    *x ^= *x >> 7;
    *x ^= *x << 17;
    return (double)(*x >> 11) / 4503599627370496.0 - 1.0;
}

static double *alloc_random(size_t count, uint64_t seed)
{
    double *a = malloc(count * sizeof *a);
    assert_non_null(a);
    for (size_t i = 0; i < count; i++) a[i] = uniform(&seed);
    return a;
}

/* The DFT of every column of (re, im) (n rows, stride columns) by its
 * definition in long double, into (xr, xi); the roots from a table indexed
 * by j k mod n. */
static void direct_dft(uint32_t n, int sign, const double *re, const double *im, size_t stride, double *xr,
                       double *xi)
{
    const long double two_pi = 6.283185307179586476925286766559005768L;
    long double *c = malloc(n * sizeof *c), *s = malloc(n * sizeof *s);
    assert_true(c && s);
    for (uint32_t k = 0; k < n; k++) {
        c[k] = cosl(two_pi * (long double)k / (long double)n);
        s[k] = (long double)sign * sinl(two_pi * (long double)k / (long double)n);
    }
    for (size_t b = 0; b < stride; b++)
        for (uint32_t j = 0; j < n; j++) {
            long double ar = 0, ai = 0;
            for (uint32_t k = 0; k < n; k++) {
                const uint32_t e = (uint32_t)((uint64_t)j * k % n);
                const long double x = re[k * stride + b], y = im[k * stride + b];
                ar += x * c[e] - y * s[e];
                ai += x * s[e] + y * c[e];
            }
            xr[j * stride + b] = (double)ar, xi[j * stride + b] = (double)ai;
        }
    free(c), free(s);
}

/* max |a - b| / max |b| over complex entries */
static double rel_error(const double *ar, const double *ai, const double *br, const double *bi, size_t count)
{
    double err = 0, size = 0;
    for (size_t i = 0; i < count; i++) {
        err = fmax(err, hypot(ar[i] - br[i], ai[i] - bi[i]));
        size = fmax(size, hypot(br[i], bi[i]));
    }
    return err / size;
}

/* Every length 1..64 and the big sizes, 5 columns, both signs, against the
 * direct DFT; then back again. Measured (GCC 12, x86-64): max |error| / max |X|
 * at most 3.2e-16 for n <= 64, 3.5e-16 for the big composite sizes, 1.4e-15
 * for the prime 997 (a direct DFT of length 997 inside); round trip 7.1e-16,
 * 2.0e-15 for 997. */
static void against_direct(spn__fft_kind kind)
{
    const size_t stride = 5;
    double worst = 0, worst_trip = 0;
    uint32_t worst_n = 0;
    for (uint32_t i = 0; i < 64 + sizeof big_sizes / sizeof *big_sizes; i++) {
        const uint32_t n = i < 64 ? i + 1 : big_sizes[i - 64];
        const size_t count = (size_t)n * stride;
        spn__fft *p = spn__fft_plan_kind(n, kind);
        assert_non_null(p);
        assert_int_equal(spn__fft_length(p), n);
        assert_int_equal(spn__fft_is_chirp(p), kind == SPN__FFT_CHIRP);
        const size_t scratch = spn__fft_scratch_rows(p) * stride;
        double *re0 = alloc_random(count, 0x9e3779b97f4a7c15u + n), *im0 = alloc_random(count, 0x2545f4914f6cdd1du + n);
        double *re = malloc(count * sizeof *re), *im = malloc(count * sizeof *im), *tre = malloc(scratch * sizeof *tre),
               *tim = malloc(scratch * sizeof *tim), *xr = malloc(count * sizeof *xr), *xi = malloc(count * sizeof *xi);
        assert_true(re && im && tre && tim && xr && xi);
        for (int sign = -1; sign <= 1; sign += 2) {
            memcpy(re, re0, count * sizeof *re);
            memcpy(im, im0, count * sizeof *im);
            spn__fft_run(p, sign, re, im, stride, 0, stride, tre, tim);
            direct_dft(n, sign, re0, im0, stride, xr, xi);
            const double err = rel_error(re, im, xr, xi, count);
            if (err > worst) worst = err, worst_n = n;
            assert_true(err < 1e-12);
            /* back again, divided by n */
            spn__fft_run(p, -sign, re, im, stride, 0, stride, tre, tim);
            for (size_t k = 0; k < count; k++) re[k] /= n, im[k] /= n;
            const double trip = rel_error(re, im, re0, im0, count);
            worst_trip = fmax(worst_trip, trip);
            assert_true(trip < 1e-13);
        }
        free(re0), free(im0), free(re), free(im), free(tre), free(tim), free(xr), free(xi);
        spn__fft_free(p);
    }
    print_message("%s: worst error %.2g (n = %u), round trip %.2g\n", kind == SPN__FFT_CHIRP ? "chirp" : "radix", worst,
                  (unsigned)worst_n, worst_trip);
}

/* Measured (GCC 12, x86-64), chirp plans: at most 6.1e-16 (n = 1001), round trip 1.4e-15. */
static void test_against_direct(void **state)
{
    (void)state;
    against_direct(SPN__FFT_RADIX);
    against_direct(SPN__FFT_CHIRP);
}

/* Transform the columns [b0, b1) of copies of (re0, im0) with the scratch
 * filled with a marker; every column outside stays as it was in all four
 * arrays. The calls are given as a list of column boundaries. */
static void run_ranges(const spn__fft *p, int sign, const double *re0, const double *im0, size_t stride,
                       const size_t *cut, size_t ncut, double *re, double *im, double *tre, double *tim)
{
    const size_t count = (size_t)spn__fft_length(p) * stride, scratch = spn__fft_scratch_rows(p) * stride;
    memcpy(re, re0, count * sizeof *re);
    memcpy(im, im0, count * sizeof *im);
    for (size_t k = 0; k < scratch; k++)
        tre[k] = tim[k] = 12345.0;
    for (size_t c = 0; c + 1 < ncut; c++) spn__fft_run(p, sign, re, im, stride, cut[c], cut[c + 1], tre, tim);
    for (size_t k = 0; k < scratch; k++) {
        const size_t b = k % stride;
        if (b >= cut[0] && b < cut[ncut - 1]) continue;
        if (k < count) {
            assert_memory_equal(&re[k], &re0[k], sizeof *re);
            assert_memory_equal(&im[k], &im0[k], sizeof *im);
        }
        assert_true(tre[k] == 12345.0 && tim[k] == 12345.0);
    }
}

/* One call over [1, 6) of 9 columns, two over [1, 4) and [4, 6), one per
 * column, and one over [1, 3) then [3, 6): the same bits, and columns 0,
 * 6, 7, 8 untouched; with 300 columns (several chunks of the transform's
 * inner loops) one call against [0, 137) + [137, 300) and one per column. */
static void test_column_ranges(void **state)
{
    (void)state;
    const uint32_t sizes[] = {1, 2, 8, 16, 30, 64, 100, 343, 997, 1000};
    for (size_t i = 0; i < 2 * sizeof sizes / sizeof *sizes; i++) {
        const bool chirp = i >= sizeof sizes / sizeof *sizes;
        const uint32_t n = sizes[chirp ? i - sizeof sizes / sizeof *sizes : i];
        spn__fft *p = spn__fft_plan_kind(n, chirp ? SPN__FFT_CHIRP : SPN__FFT_RADIX);
        assert_non_null(p);
        for (int wide = 0; wide < 2; wide++) {
            const size_t stride = wide ? 300 : 9, count = (size_t)n * stride;
            const size_t scratch = spn__fft_scratch_rows(p) * stride;
            double *re0 = alloc_random(count, 77u + n), *im0 = alloc_random(count, 1234567u + n);
            double *a[4], *b[4];
            for (int k = 0; k < 4; k++) {
                a[k] = malloc((k < 2 ? count : scratch) * sizeof *a[k]);
                b[k] = malloc((k < 2 ? count : scratch) * sizeof *b[k]);
                assert_true(a[k] && b[k]);
            }
            size_t whole[2] = {1, 6}, each[301];
            const size_t halves[][3] = {{1, 4, 6}, {1, 3, 6}, {0, 137, 300}};
            if (wide) whole[0] = 0, whole[1] = 300;
            const size_t nc = whole[1] - whole[0] + 1;
            for (size_t c = 0; c < nc; c++) each[c] = whole[0] + c;
            for (int sign = -1; sign <= 1; sign += 2) {
                run_ranges(p, sign, re0, im0, stride, whole, 2, a[0], a[1], a[2], a[3]);
                for (int h = 0; h < 3; h++) {
                    if ((h == 2) != wide) continue;
                    run_ranges(p, sign, re0, im0, stride, halves[h], 3, b[0], b[1], b[2], b[3]);
                    assert_memory_equal(a[0], b[0], count * sizeof *a[0]);
                    assert_memory_equal(a[1], b[1], count * sizeof *a[1]);
                }
                run_ranges(p, sign, re0, im0, stride, each, nc, b[0], b[1], b[2], b[3]);
                assert_memory_equal(a[0], b[0], count * sizeof *a[0]);
                assert_memory_equal(a[1], b[1], count * sizeof *a[1]);
            }
            free(re0), free(im0);
            for (int k = 0; k < 4; k++) free(a[k]), free(b[k]);
        }
        spn__fft_free(p);
    }
}

/* Auto: the mixed-radix plan for lengths of small factors, the chirp one for
 * a large prime factor (the crossover measured near 50: Zen 1, 150 columns,
 * ns an element radix / chirp: 47 19.2 / 19.2, 61 23.8 / 21.5, 127 48.6 /
 * 19.8, 997 412 / 50.6); its scratch is two transforms of length m >= 2 n - 1. */
static void test_auto_kind(void **state)
{
    (void)state;
    const uint32_t radix[] = {1, 2, 7, 31, 47, 316, 1000, 1024, 4096}, chirp[] = {61, 79, 127, 251, 997, 1009, 2003};
    for (size_t i = 0; i < sizeof radix / sizeof *radix; i++) {
        spn__fft *p = spn__fft_plan(radix[i]);
        assert_non_null(p);
        assert_false(spn__fft_is_chirp(p));
        assert_int_equal(spn__fft_scratch_rows(p), radix[i]);
        spn__fft_free(p);
    }
    for (size_t i = 0; i < sizeof chirp / sizeof *chirp; i++) {
        spn__fft *p = spn__fft_plan(chirp[i]);
        assert_non_null(p);
        assert_true(spn__fft_is_chirp(p));
        assert_true(spn__fft_scratch_rows(p) >= 2 * (2 * (size_t)chirp[i] - 1));
        spn__fft_free(p);
    }
}

static void test_plan_zero(void **state)
{
    (void)state;
    assert_null(spn__fft_plan(0));
    assert_null(spn__fft_plan_kind(0, SPN__FFT_CHIRP));
    spn__fft_free(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_direct),
        cmocka_unit_test(test_column_ranges),
        cmocka_unit_test(test_auto_kind),
        cmocka_unit_test(test_plan_zero),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

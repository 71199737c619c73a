/* The dense Cholesky of the equilibrium solver (equilibrium_bsr.c): the
 * matrix of thread slides and the multigrid's coarsest level. It is
 * factored in panels of four columns, two rows at a time, and claims the
 * bits of the plain column-by-column method with four running sums per dot
 * product; this test holds it to that against a reference written here,
 * over sizes that end panels and row pairs at every remainder, checks
 * L L^T = A and the solve (the same bits on a team), and that an
 * indefinite matrix is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/equilibrium_bsr.h"

/* The column-by-column method the panels must reproduce: entry (i, k) from
 * the dot product of rows i and k over their first k numbers, summed in
 * four running sums (q mod 4), the remainder into the first. */
static double ref_dot(const double *a, const double *b, size_t n)
{
    double s[4] = {0, 0, 0, 0};
    size_t q = 0;
    for (; q + 4 <= n; q += 4)
        for (int l = 0; l < 4; l++) s[l] += a[q + l] * b[q + l];
    for (; q < n; q++) s[0] += a[q] * b[q];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

static int ref_cholesky(double *f, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        double d = f[k * n + k] - ref_dot(f + k * n, f + k * n, k);
        if (!(d > 0)) return 0;
        d = sqrt(d);
        f[k * n + k] = d;
        for (size_t i = k + 1; i < n; i++) f[i * n + k] = (f[i * n + k] - ref_dot(f + i * n, f + k * n, k)) / d;
    }
    return 1;
}

/* A symmetric positive definite n x n matrix: random entries in
 * [-0.5, 0.5], n added on the diagonal (a fixed linear congruential
 * sequence, so every run tests the same matrices). */
static double *spd(size_t n, unsigned seed)
{
    double *a = malloc(n * n * sizeof *a);
    assert_non_null(a);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j <= i; j++) {
            seed = seed * 1103515245u + 12345u;
            a[i * n + j] = a[j * n + i] = (double)(seed >> 8) / 16777216.0 - 0.5;
        }
    for (size_t i = 0; i < n; i++) a[i * n + i] += (double)n;
    return a;
}

static void test_same_bits_as_columns(void **state)
{
    (void)state;
    /* from 512 rows the rows below a panel are shared among threads: one and
     * two threads must give the reference's bits alike */
    const size_t sizes[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 31, 64, 65, 130, 257, 515, 522};
    for (size_t s = 0; s < 2 * sizeof sizes / sizeof *sizes; s++) {
        const size_t n = sizes[s / 2];
        const int threads = 1 + (int)(s % 2);
        double *a = spd(n, 7u + (unsigned)n), *f = malloc(n * n * sizeof *f), *g = malloc(n * n * sizeof *g);
        assert_non_null(f);
        assert_non_null(g);
        memcpy(f, a, n * n * sizeof *f);
        memcpy(g, a, n * n * sizeof *g);
        assert_true(spn__dense_cholesky(f, n, threads));
        assert_true(ref_cholesky(g, n));
        double worst = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j <= i; j++) {
                assert_memory_equal(&f[i * n + j], &g[i * n + j], sizeof(double));
                double lt = 0; /* (L L^T)_ij against A_ij */
                for (size_t q = 0; q <= j; q++) lt += f[i * n + q] * f[j * n + q];
                worst = fmax(worst, fabs(lt - a[i * n + j]) / (double)n);
            }
        assert_true(worst < 1e-13);
        free(a), free(f), free(g);
    }
}

static void test_solve(void **state)
{
    (void)state;
    const size_t n = 37;
    double *a = spd(n, 99u), *f = malloc(n * n * sizeof *f), b[37], x[37];
    assert_non_null(f);
    memcpy(f, a, n * n * sizeof *f);
    for (size_t i = 0; i < n; i++) b[i] = sin((double)i);
    assert_true(spn__dense_cholesky(f, n, 1));
    spn__dense_cholesky_solve(f, n, b, x, 1);
    for (size_t i = 0; i < n; i++) {
        double r = b[i];
        for (size_t j = 0; j < n; j++) r -= a[i * n + j] * x[j];
        assert_true(fabs(r) < 1e-12);
    }
    free(a), free(f);
}

/* Large enough for the team (and ending blocks and lanes off their
 * multiples): the same bits on one, two and three threads, in place as
 * well, and a small residual. */
static void test_solve_on_a_team(void **state)
{
    (void)state;
    const size_t sizes[] = {515, 1031};
    for (size_t k = 0; k < 2; k++) {
        const size_t n = sizes[k];
        double *a = spd(n, 7u + (unsigned)n), *f = malloc(n * n * sizeof *f), *b = malloc(n * sizeof *b),
               *x[4];
        assert_true(f && b);
        memcpy(f, a, n * n * sizeof *f);
        for (size_t i = 0; i < n; i++) b[i] = cos(0.3 * (double)i);
        assert_true(spn__dense_cholesky(f, n, 2));
        for (int t = 0; t < 4; t++) {
            x[t] = malloc(n * sizeof *x[t]);
            assert_non_null(x[t]);
        }
        spn__dense_cholesky_solve(f, n, b, x[0], 1);
        spn__dense_cholesky_solve(f, n, b, x[1], 2);
        spn__dense_cholesky_solve(f, n, b, x[2], 3);
        memcpy(x[3], b, n * sizeof *b);
        spn__dense_cholesky_solve(f, n, x[3], x[3], 2);
        for (int t = 1; t < 4; t++) assert_memory_equal(x[0], x[t], n * sizeof *x[0]);
        for (size_t i = 0; i < n; i++) {
            double r = b[i];
            for (size_t j = 0; j < n; j++) r -= a[i * n + j] * x[0][j];
            assert_true(fabs(r) < 1e-11);
        }
        for (int t = 0; t < 4; t++) free(x[t]);
        free(a), free(f), free(b);
    }
}

/* A matrix with a negative eigenvalue: refused, whether the failing pivot
 * falls in the first panel or a later one. */
static void test_indefinite(void **state)
{
    (void)state;
    const size_t sizes[] = {3, 9, 40};
    for (size_t s = 0; s < 3; s++) {
        const size_t n = sizes[s];
        double *a = spd(n, 5u);
        a[(n - 1) * n + (n - 1)] = -1; /* the last pivot goes negative */
        assert_false(spn__dense_cholesky(a, n, 2));
        free(a);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_bits_as_columns),
        cmocka_unit_test(test_solve),
        cmocka_unit_test(test_solve_on_a_team),
        cmocka_unit_test(test_indefinite),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

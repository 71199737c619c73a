/* The sparse Cholesky factorisation (src/physics/sparse_chol.c):
 * 1. on a net of 3x3 blocks (a grid with doubled springs, fixed neighbours
 *    and a few long threads), A x = b is solved to round-off, checked by an
 *    independent block product;
 * 2. the minimum-degree order keeps the factor small: a 60 x 60 grid's L holds
 *    under a third of what the grid's natural (banded) order would need;
 * 3. a factorisation of new values in the same pattern solves the new
 *    system, and the same values give the same bits;
 * 4. a matrix that is not positive definite is refused;
 * 5. a limit on the factor's size is kept. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/sparse_chol.h"

typedef struct net {
    uint32_t n;
    uint32_t *start;
    int32_t *adj;
    double *xyz, *diag, *offd;
} net;

static uint64_t rng = 88172645463325252u;
static double unit(void) /* xorshift, in [0, 1) */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* A side x side grid in the plane z = 0 (positions jittered), each particle
 * joined to its right and upper neighbours (the right one twice), every
 * tenth to a fixed particle (-1), and `longs` threads between far particles.
 * Off-diagonal blocks -(t I + s u u^T) of random t, s > 0 with the pair's
 * direction u, the diagonal the sum of its blocks' magnitudes plus a mass:
 * symmetric positive definite. */
static net make_net(uint32_t side, uint32_t longs, double mass)
{
    net g;
    const uint32_t n = side * side;
    g.n = n;
    /* neighbour lists: up to 4 grid + 2 (doubled) + 1 fixed + long ones */
    uint32_t cap = 8 + 2 * longs;
    uint32_t *cnt = calloc(n, sizeof *cnt);
    int32_t *tmp = malloc((size_t)n * cap * sizeof *tmp);
    g.xyz = malloc(3 * (size_t)n * sizeof *g.xyz);
    for (uint32_t i = 0; i < n; i++) {
        g.xyz[3 * i] = (i % side) + 0.3 * unit(), g.xyz[3 * i + 1] = (i / side) + 0.3 * unit();
        g.xyz[3 * i + 2] = 0.01 * unit();
    }
#define LINK(a, b) (tmp[(size_t)(a)*cap + cnt[a]++] = (int32_t)(b), tmp[(size_t)(b)*cap + cnt[b]++] = (int32_t)(a))
    for (uint32_t i = 0; i < n; i++) {
        if (i % side + 1 < side) LINK(i, i + 1), LINK(i, i + 1);
        if (i + side < n) LINK(i, i + side);
        if (i % 10 == 0) tmp[(size_t)i * cap + cnt[i]++] = -1;
    }
    for (uint32_t l = 0; l < longs; l++) {
        uint32_t a = (uint32_t)(unit() * n), b = (uint32_t)(unit() * n);
        if (a != b) LINK(a, b);
    }
#undef LINK
    g.start = malloc(((size_t)n + 1) * sizeof *g.start);
    g.start[0] = 0;
    for (uint32_t i = 0; i < n; i++)
        g.start[i + 1] = g.start[i] + cnt[i];
    const uint32_t m = g.start[n];
    g.adj = malloc(m * sizeof *g.adj);
    g.offd = calloc(6 * (size_t)m, sizeof *g.offd);
    g.diag = calloc(6 * (size_t)n, sizeof *g.diag);
    for (uint32_t i = 0; i < n; i++)
        memcpy(g.adj + g.start[i], tmp + (size_t)i * cap, cnt[i] * sizeof *g.adj);
    /* each pair's entries: the k-th entry of i to j matches the k-th of j to i */
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t e = g.start[i]; e < g.start[i + 1]; e++) {
            const int32_t j = g.adj[e];
            if (j >= 0 && (uint32_t)j < i) continue; /* filled from j's side */
            double u[3] = {1, 0, 0};
            if (j >= 0) {
                double len = 0;
                for (int c = 0; c < 3; c++)
                    u[c] = g.xyz[3 * j + c] - g.xyz[3 * i + c], len += u[c] * u[c];
                for (int c = 0; c < 3; c++)
                    u[c] /= sqrt(len);
            }
            const double t = 0.02 + unit(), s = 5 + 50 * unit();
            const double h[6] = {t + s * u[0] * u[0], t + s * u[1] * u[1], t + s * u[2] * u[2],
                                 s * u[0] * u[1],     s * u[0] * u[2],     s * u[1] * u[2]};
            for (int c = 0; c < 6; c++)
                g.offd[6 * (size_t)e + c] = -h[c], g.diag[6 * (size_t)i + c] += h[c];
            if (j < 0) continue;
            /* the matching entry of j: the first of its entries to i not yet given a block */
            for (uint32_t f = g.start[j]; f < g.start[j + 1]; f++)
                if (g.adj[f] == (int32_t)i && g.offd[6 * (size_t)f] == 0) {
                    for (int c = 0; c < 6; c++)
                        g.offd[6 * (size_t)f + c] = -h[c], g.diag[6 * (size_t)j + c] += h[c];
                    break;
                }
        }
    for (uint32_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            g.diag[6 * (size_t)i + c] += mass;
    free(cnt), free(tmp);
    return g;
}

static void free_net(net *g) { free(g->start), free(g->adj), free(g->xyz), free(g->diag), free(g->offd); }

/* y = A x from the blocks, independently of the factor's own assembly. */
static void product(const net *g, const double *x, double *y)
{
    for (uint32_t i = 0; i < g->n; i++) {
        const double *d = g->diag + 6 * (size_t)i;
        const double *xi = x + 3 * (size_t)i;
        double *yi = y + 3 * (size_t)i;
        yi[0] = d[0] * xi[0] + d[3] * xi[1] + d[4] * xi[2];
        yi[1] = d[3] * xi[0] + d[1] * xi[1] + d[5] * xi[2];
        yi[2] = d[4] * xi[0] + d[5] * xi[1] + d[2] * xi[2];
        for (uint32_t e = g->start[i]; e < g->start[i + 1]; e++) {
            if (g->adj[e] < 0) continue;
            const double *o = g->offd + 6 * (size_t)e, *xj = x + 3 * (size_t)g->adj[e];
            yi[0] += o[0] * xj[0] + o[3] * xj[1] + o[4] * xj[2];
            yi[1] += o[3] * xj[0] + o[1] * xj[1] + o[5] * xj[2];
            yi[2] += o[4] * xj[0] + o[5] * xj[1] + o[2] * xj[2];
        }
    }
}

/* |A x - b| / |b| for a random b solved through the factor. */
static double solve_error(const net *g, const spn__chol *c)
{
    const size_t N = 3 * (size_t)g->n;
    double *b = calloc(N, sizeof *b), *x = calloc(N, sizeof *x), *y = calloc(N, sizeof *y);
    assert_true(b && x && y);
    for (size_t k = 0; k < N; k++)
        b[k] = unit() - 0.5;
    spn__chol_solve(c, b, x);
    product(g, x, y);
    double r2 = 0, b2 = 0;
    for (size_t k = 0; k < N; k++)
        r2 += (y[k] - b[k]) * (y[k] - b[k]), b2 += b[k] * b[k];
    free(b), free(x), free(y);
    return sqrt(r2 / b2);
}

/* g analysed without a size limit. */
static spn__chol *analysed(const net *g)
{
    spn__chol *c = spn__chol_analyze(g->n, g->start, g->adj, SIZE_MAX);
    assert_non_null(c);
    return c;
}

static void test_solves(void **state)
{
    (void)state;
    net g = make_net(23, 40, 1e-3);
    spn__chol *c = analysed(&g);
    assert_true(spn__chol_factor(c, g.diag, g.offd));
    const double err = solve_error(&g, c);
    print_message("529 particles, 40 long threads: |Ax - b| / |b| = %.2e, L %zu numbers\n", err, spn__chol_entries(c));
    assert_true(err < 1e-11);
    /* x may be b */
    const size_t N = 3 * (size_t)g.n;
    double *b = calloc(N, sizeof *b), *x = calloc(N, sizeof *x);
    assert_true(b && x);
    for (size_t k = 0; k < N; k++)
        b[k] = unit();
    spn__chol_solve(c, b, x);
    spn__chol_solve(c, b, b);
    assert_memory_equal(b, x, N * sizeof *x);
    free(b), free(x);
    spn__chol_free(c);
    free_net(&g);
}

static void test_fill(void **state)
{
    (void)state;
    const uint32_t side = 60;
    net g = make_net(side, 0, 1e-3);
    spn__chol *c = analysed(&g);
    /* the natural order: a band of side particles, 3 side + 3 numbers a column */
    const double banded = 3.0 * g.n * (3.0 * side + 2);
    print_message("60 x 60 grid: L %zu numbers, %.0f in the natural order\n", spn__chol_entries(c), banded);
    assert_true((double)spn__chol_entries(c) < banded / 3);
    assert_true(spn__chol_factor(c, g.diag, g.offd));
    assert_true(solve_error(&g, c) < 1e-11);
    spn__chol_free(c);
    free_net(&g);
}

static void test_refactor(void **state)
{
    (void)state;
    net g = make_net(17, 10, 1e-2);
    spn__chol *c = analysed(&g);
    assert_true(spn__chol_factor(c, g.diag, g.offd));
    const size_t N = 3 * (size_t)g.n;
    double *b = calloc(N, sizeof *b), *x1 = calloc(N, sizeof *x1), *x2 = calloc(N, sizeof *x2);
    assert_true(b && x1 && x2);
    for (size_t k = 0; k < N; k++)
        b[k] = unit();
    spn__chol_solve(c, b, x1);
    /* new values in the same pattern: stiffer blocks, a heavier diagonal */
    for (size_t k = 0; k < 6 * (size_t)g.start[g.n]; k++)
        g.offd[k] *= 3;
    for (size_t k = 0; k < 6 * (size_t)g.n; k++)
        g.diag[k] *= 3;
    for (uint32_t i = 0; i < g.n; i++)
        g.diag[6 * (size_t)i] += 0.5;
    assert_true(spn__chol_factor(c, g.diag, g.offd));
    assert_true(solve_error(&g, c) < 1e-11);
    spn__chol_solve(c, b, x1);
    assert_true(spn__chol_factor(c, g.diag, g.offd));
    spn__chol_solve(c, b, x2);
    assert_memory_equal(x1, x2, N * sizeof *x1);
    free(b), free(x1), free(x2);
    spn__chol_free(c);
    free_net(&g);
}

static void test_not_definite(void **state)
{
    (void)state;
    net g = make_net(9, 0, 1e-3);
    spn__chol *c = analysed(&g);
    g.diag[6 * 40 + 2] = -1; /* particle 40's zz */
    assert_false(spn__chol_factor(c, g.diag, g.offd));
    spn__chol_free(c);
    free_net(&g);
}

static void test_size_limit(void **state)
{
    (void)state;
    net g = make_net(20, 0, 1e-3);
    spn__chol *c = analysed(&g);
    const size_t entries = spn__chol_entries(c);
    spn__chol_free(c);
    assert_null(spn__chol_analyze(g.n, g.start, g.adj, entries - 1));
    assert_non_null(c = spn__chol_analyze(g.n, g.start, g.adj, entries));
    spn__chol_free(c);
    free_net(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_solves),       cmocka_unit_test(test_fill),       cmocka_unit_test(test_refactor),
        cmocka_unit_test(test_not_definite), cmocka_unit_test(test_size_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The block sparse kernels of the multigrid's setup and coarse levels
 * (equilibrium_bsr.c).
 *
 * The block Gauss-Seidel sweep (spn__bsr_gauss_seidel): a large matrix is
 * swept in parts, in parallel, each part reading the others' values from
 * the start of the sweep. Held to a reference written here (rows in order
 * inside a part, the other parts' values from a copy), the parts depend on
 * the matrix alone (the same bits on one, two and three threads), a small
 * matrix is swept whole, and symmetric sweeps still solve a positive
 * definite system.
 *
 * The Galerkin product from A and P in chunks (spn__bsr_galerkin_ap): the
 * same bits as forming A P whole and multiplying by R = P^T, with chunks
 * whose windows of A P are local and with a numbering that makes it fall
 * back to A P whole, on one and two threads.
 *
 * The Galerkin product formed again into a kept pattern
 * (spn__bsr_galerkin_refresh), with P and R in float32 as the built
 * hierarchy holds them: the same floats as rounding the product above of
 * the same P, on one and two threads, both numberings, and after A's values
 * change (what it is for), with its scratch made afresh and kept from the
 * call before (as the hierarchy keeps it between Newton steps). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/equilibrium_bsr.h"
#include "physics/equilibrium_internal.h"

/* A grid of side x side nodes, a 3x3 block each, coupled to its four
 * neighbours by -I - E (E a small symmetric perturbation from a fixed
 * sequence), the diagonal 4.5 I plus the sum of the couplings' |E|: symmetric,
 * block diagonally dominant, so positive definite. Rows numbered row by row,
 * the diagonal block first in each row. */
typedef struct {
    spn__bsr a;
    double *dinv;
} grid;

static double next(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return (double)(*seed >> 8) / 16777216.0 - 0.5;
}

/* entry q (xx, yy, zz, xy, xz, yz) of the perturbation of the edge {i, j}, i < j */
static double edge_entry(uint32_t i, uint32_t j, int q)
{
    unsigned seed = i * 2654435761u ^ j * 40503u ^ (unsigned)q * 97u;
    next(&seed);
    return 0.2 * next(&seed);
}

static grid make_grid(uint32_t side)
{
    grid g;
    const uint32_t n = side * side;
    g.a.rows = g.a.cols = n;
    g.a.start = malloc(((size_t)n + 1) * sizeof *g.a.start);
    g.a.col = malloc(5 * (size_t)n * sizeof *g.a.col);
    g.a.val = calloc(45 * (size_t)n, sizeof *g.a.val);
    g.a.fval = NULL;
    g.dinv = malloc(6 * (size_t)n * sizeof *g.dinv);
    assert_true(g.a.start && g.a.col && g.a.val && g.dinv);
    uint32_t p = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t r = i / side, c = i % side;
        g.a.start[i] = p;
        g.a.col[p] = i;
        double *d = g.a.val + 9 * (size_t)p++;
        d[0] = d[4] = d[8] = 4.5;
        const int64_t nb[4] = {r > 0 ? (int64_t)i - side : -1, c > 0 ? (int64_t)i - 1 : -1,
                               c + 1 < side ? (int64_t)i + 1 : -1, r + 1 < side ? (int64_t)i + side : -1};
        for (int k = 0; k < 4; k++) {
            if (nb[k] < 0) continue;
            uint32_t j = (uint32_t)nb[k], lo = i < j ? i : j, hi = i < j ? j : i;
            double e[6];
            for (int q = 0; q < 6; q++) e[q] = edge_entry(lo, hi, q);
            const double full[9] = {e[0], e[3], e[4], e[3], e[1], e[5], e[4], e[5], e[2]};
            g.a.col[p] = j;
            double *o = g.a.val + 9 * (size_t)p++;
            for (int q = 0; q < 9; q++) {
                o[q] = -full[q] - (q % 4 == 0 ? 1.0 : 0.0);
                d[4 * (q / 3)] += fabs(full[q]); /* row q / 3 stays dominant */
            }
        }
        const double h[6] = {d[0], d[4], d[8], d[1], d[2], d[5]};
        assert_true(spn__sym_inverse(h, g.dinv + 6 * (size_t)i));
    }
    g.a.start[n] = p;
    return g;
}

static void free_grid(grid *g)
{
    spn__bsr_free(&g->a);
    free(g->dinv);
}

/* entry q of block p, float64 or (rounded) float32 */
static double entry(const spn__bsr *a, uint32_t p, int q)
{
    return a->val ? a->val[9 * (size_t)p + q] : (double)a->fval[9 * (size_t)p + q];
}

/* The sweep as its comment defines it, written plainly: within part q
 * (rows [n q / parts, n (q + 1) / parts)) rows in order (or reverse), each
 * x_i = D_i^-1 (b_i - sum_j A_ij y_j), y = x inside the part and the copy
 * taken before the sweep outside it. */
static void ref_sweep(const grid *g, uint32_t parts, const double *b, double *x, bool forward)
{
    const uint32_t n = g->a.rows;
    double *old = malloc(3 * (size_t)n * sizeof *old);
    assert_non_null(old);
    memcpy(old, x, 3 * (size_t)n * sizeof *x);
    for (uint32_t q = 0; q < parts; q++) {
        uint32_t lo = (uint32_t)((uint64_t)n * q / parts), hi = (uint32_t)((uint64_t)n * (q + 1) / parts);
        for (uint32_t k = lo; k < hi; k++) {
            uint32_t i = forward ? k : hi - 1 - (k - lo);
            double s[3] = {b[3 * i], b[3 * i + 1], b[3 * i + 2]};
            for (uint32_t p = g->a.start[i] + 1; p < g->a.start[i + 1]; p++) {
                uint32_t j = g->a.col[p];
                const double *y = (j >= lo && j < hi ? x : old) + 3 * (size_t)j;
                for (int r = 0; r < 3; r++)
                    s[r] -= entry(&g->a, p, 3 * r) * y[0] + entry(&g->a, p, 3 * r + 1) * y[1] +
                            entry(&g->a, p, 3 * r + 2) * y[2];
            }
            spn__sym_mul(g->dinv + 6 * (size_t)i, s, x + 3 * (size_t)i);
        }
    }
    free(old);
}

static double *vec(uint32_t n, unsigned seed)
{
    double *v = malloc(3 * (size_t)n * sizeof *v);
    assert_non_null(v);
    for (size_t k = 0; k < 3 * (size_t)n; k++) v[k] = next(&seed);
    return v;
}

static void test_parts_follow_the_rows(void **state)
{
    (void)state;
    const uint32_t rows[] = {1, 2 * SPN__BSR_GS_PART_ROWS - 1, 2 * SPN__BSR_GS_PART_ROWS,
                             4 * SPN__BSR_GS_PART_ROWS - 1, 4 * SPN__BSR_GS_PART_ROWS, 1000000};
    const uint32_t want[] = {1, 1, 2, 2, 4, SPN__BSR_GS_MAX_PARTS};
    for (size_t t = 0; t < sizeof rows / sizeof *rows; t++) {
        spn__bsr a = {.rows = rows[t]};
        assert_int_equal(spn__bsr_gs_parts(&a), want[t]);
    }
}

/* The same bits on any team; the reference's values to rounding. The
 * matrix in float64, or rounded to float32 as the coarse levels are. */
static void check_sweeps(uint32_t side, uint32_t parts, bool rounded)
{
    grid g = make_grid(side);
    if (rounded) spn__bsr_round(&g.a);
    const uint32_t n = g.a.rows;
    assert_int_equal(spn__bsr_gs_parts(&g.a), parts);
    double *b = vec(n, 3), *x0 = vec(n, 5), *ref = malloc(3 * (size_t)n * sizeof *ref),
           *scratch = malloc(3 * (size_t)n * sizeof *scratch), *got[3];
    assert_true(ref && scratch);
    memcpy(ref, x0, 3 * (size_t)n * sizeof *ref);
    ref_sweep(&g, parts, b, ref, true);
    ref_sweep(&g, parts, b, ref, false);
    for (int t = 0; t < 3; t++) {
        got[t] = malloc(3 * (size_t)n * sizeof *got[t]);
        assert_non_null(got[t]);
        memcpy(got[t], x0, 3 * (size_t)n * sizeof *x0);
        spn__bsr_gauss_seidel(&g.a, g.dinv, b, got[t], true, scratch, t + 1);
        spn__bsr_gauss_seidel(&g.a, g.dinv, b, got[t], false, scratch, t + 1);
    }
    for (size_t k = 0; k < 3 * (size_t)n; k++) {
        assert_memory_equal(&got[0][k], &got[1][k], sizeof(double));
        assert_memory_equal(&got[0][k], &got[2][k], sizeof(double));
        assert_true(fabs(got[0][k] - ref[k]) <= 1e-13 * (1 + fabs(ref[k])));
    }
    for (int t = 0; t < 3; t++) free(got[t]);
    free(b), free(x0), free(ref), free(scratch);
    free_grid(&g);
}

static void test_small_matrix_swept_whole(void **state)
{
    (void)state;
    check_sweeps(60, 1, false); /* 3,600 rows */
    check_sweeps(60, 1, true);
}

static void test_large_matrix_swept_in_parts(void **state)
{
    (void)state;
    check_sweeps(100, 4, false); /* 10,000 rows */
    check_sweeps(100, 4, true);
    check_sweeps(181, SPN__BSR_GS_MAX_PARTS, true); /* 32,761 rows, as level 2 of the 1M web */
}

/* Symmetric sweeps in parts still converge to A x = b on a definite system,
 * from zero, as the coarse solve uses them. */
static void test_parted_sweeps_solve(void **state)
{
    (void)state;
    grid g = make_grid(100);
    const uint32_t n = g.a.rows;
    assert_true(spn__bsr_gs_parts(&g.a) > 1);
    double *b = vec(n, 13), *x = calloc(3 * (size_t)n, sizeof *x), *r = malloc(3 * (size_t)n * sizeof *r),
           *scratch = malloc(3 * (size_t)n * sizeof *scratch);
    assert_true(x && r && scratch);
    double b2 = 0, r2 = 0;
    for (size_t k = 0; k < 3 * (size_t)n; k++) b2 += b[k] * b[k];
    for (int it = 0; it < 30; it++) {
        spn__bsr_gauss_seidel(&g.a, g.dinv, b, x, true, scratch, 2);
        spn__bsr_gauss_seidel(&g.a, g.dinv, b, x, false, scratch, 2);
    }
    spn__bsr_residual(&g.a, b, x, r, 1);
    for (size_t k = 0; k < 3 * (size_t)n; k++) r2 += r[k] * r[k];
    assert_true(sqrt(r2 / b2) < 1e-10);
    free(b), free(x), free(r), free(scratch);
    free_grid(&g);
}

/* P for the grid: particle i's 2 x 2 aggregate (numbered row by row of
 * aggregates, or scrambled by a fixed permutation) with the identity, and
 * its right neighbour's aggregate, when another, with 0.25 I + 0.01 E. */
static spn__bsr make_p(uint32_t side, bool scrambled)
{
    const uint32_t n = side * side, ac = (side + 1) / 2, nc = ac * ac;
    uint32_t *id = malloc(nc * sizeof *id);
    assert_non_null(id);
    for (uint32_t k = 0; k < nc; k++) id[k] = k;
    if (scrambled) {
        unsigned seed = 17;
        for (uint32_t k = nc - 1; k > 0; k--) {
            next(&seed);
            uint32_t j = (seed >> 8) % (k + 1), t = id[k];
            id[k] = id[j], id[j] = t;
        }
    }
    spn__bsr p = {.rows = n, .cols = nc};
    p.start = malloc(((size_t)n + 1) * sizeof *p.start);
    p.col = malloc(2 * (size_t)n * sizeof *p.col);
    p.val = calloc(18 * (size_t)n, sizeof *p.val);
    assert_true(p.start && p.col && p.val);
    uint32_t q = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t r = i / side, c = i % side, own = id[(r / 2) * ac + c / 2];
        p.start[i] = q;
        p.col[q] = own;
        p.val[9 * (size_t)q] = p.val[9 * (size_t)q + 4] = p.val[9 * (size_t)q + 8] = 1;
        q++;
        if (c + 1 < side && (c + 1) / 2 != c / 2) {
            p.col[q] = id[(r / 2) * ac + (c + 1) / 2];
            for (int k = 0; k < 9; k++) p.val[9 * (size_t)q + k] = (k % 4 == 0 ? 0.25 : 0) + 0.01 * edge_entry(i, i + 1, k % 6);
            q++;
        }
    }
    p.start[n] = q;
    free(id);
    return p;
}

static void check_galerkin(uint32_t side, bool scrambled)
{
    grid g = make_grid(side);
    spn__bsr p = make_p(side, scrambled), r, ap, ref;
    uint32_t *perm;
    assert_true(spn__bsr_transpose(&p, &r, &perm));
    assert_true(spn__bsr_mul(&g.a, &p, &ap, false, 1));
    assert_true(spn__bsr_galerkin(&r, &ap, &ref, 1));
    for (int t = 1; t <= 2; t++) {
        spn__bsr c;
        assert_true(spn__bsr_galerkin_ap(&g.a, &p, &r, &c, t));
        assert_int_equal(c.rows, ref.rows);
        assert_memory_equal(c.start, ref.start, ((size_t)ref.rows + 1) * sizeof *c.start);
        assert_memory_equal(c.col, ref.col, ref.start[ref.rows] * sizeof *c.col);
        assert_memory_equal(c.val, ref.val, 9 * (size_t)ref.start[ref.rows] * sizeof *c.val);
        spn__bsr_free(&c);
    }
    spn__bsr_free(&ref), spn__bsr_free(&ap), spn__bsr_free(&r), spn__bsr_free(&p);
    free(perm);
    free_grid(&g);
}

static void check_refresh(uint32_t side, bool scrambled)
{
    grid g = make_grid(side);
    spn__bsr p = make_p(side, scrambled), r;
    const size_t np = 9 * (size_t)p.start[p.rows];
    for (size_t k = 0; k < np; k++) p.val[k] = (float)p.val[k]; /* P as its float32 copy will read */
    uint32_t *perm;
    assert_true(spn__bsr_transpose(&p, &r, &perm));
    spn__bsr_refresh *kept[2] = {NULL, NULL}; /* each team's scratch, kept as a Newton step keeps it for the next */
    for (int change = 0; change < 2; change++) {
        if (change) /* new values in A's pattern: every third diagonal block stiffer (still symmetric) */
            for (uint32_t i = 0; i < g.a.rows; i += 3)
                for (int d = 0; d < 3; d++) g.a.val[9 * (size_t)g.a.start[i] + 4 * d] += 0.5;
        spn__bsr ref;
        assert_true(spn__bsr_galerkin_ap(&g.a, &p, &r, &ref, 1));
        const size_t nc = 9 * (size_t)ref.start[ref.rows];
        spn__bsr c = {.rows = ref.rows, .cols = ref.cols, .start = ref.start, .col = ref.col};
        c.fval = malloc((nc + 1) * sizeof *c.fval);
        assert_non_null(c.fval);
        /* the hierarchy's forms: R and P in float32 (R's rounded from P while P is float64) */
        if (change == 0) assert_true(spn__bsr_transpose_round(&r, 1));
        spn__bsr pf = p;
        pf.val = NULL;
        pf.fval = malloc((np + 1) * sizeof *pf.fval);
        assert_non_null(pf.fval);
        for (size_t k = 0; k < np; k++) pf.fval[k] = (float)p.val[k];
        pf.fval[np] = 0;
        for (int t = 1; t <= 2; t++)
            for (int use = 0; use < 2; use++) { /* without scratch kept, and with it (from the first values on) */
                memset(c.fval, 0xff, (nc + 1) * sizeof *c.fval); /* NaN: every block must be written */
                assert_true(spn__bsr_galerkin_refresh(&g.a, &pf, &r, &c, t, use ? &kept[t - 1] : NULL));
                for (size_t k = 0; k < nc; k++) assert_true(c.fval[k] == (float)ref.val[k]);
            }
        free(pf.fval);
        free(c.fval);
        spn__bsr_free(&ref);
    }
    spn__bsr_refresh_free(kept[0]), spn__bsr_refresh_free(kept[1]);
    spn__bsr_free(&r), spn__bsr_free(&p);
    free(perm);
    free_grid(&g);
}

static void test_galerkin_refresh(void **state)
{
    (void)state;
    check_refresh(400, false); /* chunks with their own windows */
    check_refresh(400, true);  /* each chunk's rows of A P scattered across the whole matrix */
    check_refresh(40, false);
}

static void test_galerkin_in_chunks(void **state)
{
    (void)state;
    check_galerkin(400, false); /* 40,000 coarse rows: ten chunks on one thread, sixteen on two (enough block products for a team) */
    check_galerkin(40, false);  /* one chunk */
}

static void test_galerkin_scrambled_falls_back(void **state)
{
    (void)state;
    check_galerkin(400, true);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parts_follow_the_rows),
        cmocka_unit_test(test_small_matrix_swept_whole),
        cmocka_unit_test(test_large_matrix_swept_in_parts),
        cmocka_unit_test(test_parted_sweeps_solve),
        cmocka_unit_test(test_galerkin_in_chunks),
        cmocka_unit_test(test_galerkin_scrambled_falls_back),
        cmocka_unit_test(test_galerkin_refresh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

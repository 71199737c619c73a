/* Aggregation multigrid preconditioner for the equilibrium solver's Newton
 * systems (a symmetric V-cycle, so CG can use it).
 *
 * Coarsening: particles are grouped into aggregates over the spring graph
 * (greedy: a particle whose strong neighbours are all free starts an aggregate
 * with them, the rest join the neighbour aggregate they are most strongly
 * tied to; "strong" = a spring of at least THETA times the particle's stiffest
 * spring, so near the hub, where ring segments are short and stiff, aggregates
 * follow the rings). The coarse operator is the Galerkin product P^T A P with
 * P piecewise constant per aggregate and per axis (unsmoothed aggregation:
 * the coarse 3x3 blocks are sums of fine ones). Levels continue until a level
 * has at most COARSEST particles, solved there by dense Cholesky.
 *
 * Smoothing: block Gauss-Seidel on the finest level (forward before the coarse
 * correction, backward after) and damped block Jacobi on the coarse ones (the
 * 3x3 diagonal blocks inverted), as many sweeps after as before, so the cycle
 * is symmetric.
 *
 * The aggregates and the coarse sparsity depend only on the graph and the
 * stiffness k, so they are built once per solve; each Newton iteration only
 * refills the values, one coarse row at a time from its own aggregate's rows,
 * in a fixed order (the same bits for any thread count). */
#include "equilibrium_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define THETA 0.25     /* strong coupling: a spring of at least this fraction of the stiffest */
#define COARSEST 96u    /* particles on the level solved by dense Cholesky */
#define MAX_LEVELS 24
#define SWEEPS 1        /* smoothing sweeps each way (2: fewer CG iterations, more time; measured) */
#define OMEGA 0.6       /* block-Jacobi damping on the coarse levels */
#define FINE_GS 1       /* Gauss-Seidel (forward before, backward after) on the finest level */
#define PAR_MIN 32768u

typedef struct mg_level {
    uint32_t n;                 /* rows (particles or aggregates) */
    uint32_t *row_start, *col;  /* explicit levels (>= 1): block CSR */
    double *val;                /* 9 per block, row-major */
    double *inv;                /* 6 per row: inverted diagonal block (level 0: the preconditioner's own) */
    double *x, *b, *r;          /* 3 n each (level 0: b, x given; r scratch) */
    /* to the next coarser level */
    uint32_t *agg;              /* n: coarse row of each row */
    uint32_t *mem_start, *mem;  /* coarse row -> its rows, in order */
    uint32_t *map;              /* per block (level 0: per adjacency entry): coarse block index */
    uint32_t *mapd;             /* per row: the coarse block its diagonal adds to */
} mg_level;

struct spn__mg {
    int nlevels;
    mg_level lv[MAX_LEVELS];
    double *dense;              /* coarsest level, Cholesky factor, (3n)^2 */
    int threads;
};

static inline int team(const spn__mg *mg, uint32_t n) { return n < PAR_MIN ? 1 : mg->threads; }

/* ---- graph views: level 0 is the implicit spring system ------------------ */

static uint32_t row_begin(const spn__eq *e, const mg_level *L, int l, uint32_t i)
{
    return l == 0 ? e->adj_start[i] : L->row_start[i];
}
static uint32_t row_end(const spn__eq *e, const mg_level *L, int l, uint32_t i)
{
    return l == 0 ? e->adj_start[i + 1] : L->row_start[i + 1];
}
/* Column of entry j, or -1 for a fixed end (level 0) or the diagonal (coarse levels). */
static int64_t entry_col(const spn__eq *e, const mg_level *L, int l, uint32_t i, uint32_t j)
{
    if (l == 0) return e->adj_other[j];
    return L->col[j] == i ? -1 : (int64_t)L->col[j];
}
/* Coupling strength of entry j (level 0: spring k; coarse: trace of the block). */
static double entry_strength(const spn__eq *e, const mg_level *L, int l, uint32_t j)
{
    if (l == 0) return e->k[e->adj[j] >> 1];
    const double *v = L->val + 9 * (size_t)j;
    return fabs(v[0] + v[4] + v[8]);
}

/* ---- aggregation ------------------------------------------------------------ */

static double strongest(const spn__eq *e, const mg_level *L, int l, uint32_t i)
{
    double s = 0;
    for (uint32_t j = row_begin(e, L, l, i); j < row_end(e, L, l, i); j++)
        if (entry_col(e, L, l, i, j) >= 0) s = fmax(s, entry_strength(e, L, l, j));
    return s;
}

/* Fills L->agg; returns the number of aggregates. */
static uint32_t aggregate(const spn__eq *e, mg_level *L, int l)
{
    const uint32_t n = L->n, NONE = UINT32_MAX;
    uint32_t na = 0;
    double *smax = malloc((n ? n : 1) * sizeof *smax);
    if (!smax) return 0;
    for (uint32_t i = 0; i < n; i++) {
        L->agg[i] = NONE;
        smax[i] = strongest(e, L, l, i);
    }
    for (uint32_t i = 0; i < n; i++) { /* phase 1: roots with all strong neighbours free */
        if (L->agg[i] != NONE) continue;
        bool free_all = true;
        for (uint32_t j = row_begin(e, L, l, i); j < row_end(e, L, l, i) && free_all; j++) {
            int64_t c = entry_col(e, L, l, i, j);
            if (c >= 0 && entry_strength(e, L, l, j) >= THETA * smax[i] && L->agg[c] != NONE) free_all = false;
        }
        if (!free_all) continue;
        L->agg[i] = na;
        for (uint32_t j = row_begin(e, L, l, i); j < row_end(e, L, l, i); j++) {
            int64_t c = entry_col(e, L, l, i, j);
            if (c >= 0 && entry_strength(e, L, l, j) >= THETA * smax[i]) L->agg[c] = na;
        }
        na++;
    }
    uint32_t *join = malloc((n ? n : 1) * sizeof *join);
    for (uint32_t i = 0; join && i < n; i++) { /* phase 2: join the most strongly tied aggregate */
        join[i] = L->agg[i];
        if (L->agg[i] != NONE) continue;
        double best = -1;
        for (uint32_t j = row_begin(e, L, l, i); j < row_end(e, L, l, i); j++) {
            int64_t c = entry_col(e, L, l, i, j);
            if (c >= 0 && L->agg[c] != NONE && entry_strength(e, L, l, j) > best) {
                best = entry_strength(e, L, l, j);
                join[i] = L->agg[c];
            }
        }
    }
    for (uint32_t i = 0; join && i < n; i++) /* phase 3: the isolated keep their own */
        L->agg[i] = join[i] != NONE ? join[i] : na++;
    free(join);
    free(smax);
    return na;
}

/* Member lists of the coarse rows, in fine order. */
static bool members(mg_level *L, uint32_t nc)
{
    L->mem_start = calloc((size_t)nc + 1, sizeof *L->mem_start);
    L->mem = malloc((L->n ? L->n : 1) * sizeof *L->mem);
    if (!L->mem_start || !L->mem) return false;
    for (uint32_t i = 0; i < L->n; i++) L->mem_start[L->agg[i] + 1]++;
    for (uint32_t c = 0; c < nc; c++) L->mem_start[c + 1] += L->mem_start[c];
    uint32_t *fill = calloc(nc ? nc : 1, sizeof *fill);
    if (!fill) return false;
    for (uint32_t i = 0; i < L->n; i++) L->mem[L->mem_start[L->agg[i]] + fill[L->agg[i]]++] = i;
    free(fill);
    return true;
}

/* Sparsity of the coarse level C from level L, and the maps of L's entries into it. */
static bool coarse_pattern(const spn__eq *e, mg_level *L, int l, mg_level *C)
{
    uint32_t nc = C->n, nent = l == 0 ? e->adj_start[L->n] : L->row_start[L->n];
    uint32_t *mark = malloc((nc ? nc : 1) * sizeof *mark), *pos = malloc((nc ? nc : 1) * sizeof *pos);
    L->map = malloc((nent ? nent : 1) * sizeof *L->map);
    L->mapd = malloc((L->n ? L->n : 1) * sizeof *L->mapd);
    C->row_start = calloc((size_t)nc + 1, sizeof *C->row_start);
    if (!mark || !pos || !L->map || !L->mapd || !C->row_start) goto fail;
    for (int pass = 0; pass < 2; pass++) {
        uint32_t nnz = 0;
        for (uint32_t c = 0; c < nc; c++) mark[c] = UINT32_MAX;
        for (uint32_t I = 0; I < nc; I++) {
            /* the diagonal first, so it is found at row_start[I] */
            mark[I] = I;
            pos[I] = nnz;
            if (pass) C->col[nnz] = I;
            nnz++;
            for (uint32_t m = L->mem_start[I]; m < L->mem_start[I + 1]; m++) {
                uint32_t i = L->mem[m];
                if (pass) L->mapd[i] = pos[I];
                for (uint32_t j = row_begin(e, L, l, i); j < row_end(e, L, l, i); j++) {
                    int64_t c = l == 0 ? e->adj_other[j] : (int64_t)L->col[j];
                    if (c < 0) continue;
                    uint32_t J = L->agg[c];
                    if (mark[J] != I) {
                        mark[J] = I;
                        pos[J] = nnz;
                        if (pass) C->col[nnz] = J;
                        nnz++;
                    }
                    if (pass) L->map[j] = pos[J];
                }
            }
            if (!pass) C->row_start[I + 1] = nnz;
        }
        if (!pass) {
            C->col = malloc((nnz ? nnz : 1) * sizeof *C->col);
            C->val = malloc(9 * (size_t)(nnz ? nnz : 1) * sizeof *C->val);
            if (!C->col || !C->val) goto fail;
        }
    }
    free(mark);
    free(pos);
    return true;
fail:
    free(mark);
    free(pos);
    return false;
}

/* ---- values --------------------------------------------------------------- */

static void add_sym(double *dst, const double *h, double sign)
{
    dst[0] += sign * h[0], dst[1] += sign * h[3], dst[2] += sign * h[4];
    dst[3] += sign * h[3], dst[4] += sign * h[1], dst[5] += sign * h[5];
    dst[6] += sign * h[4], dst[7] += sign * h[5], dst[8] += sign * h[2];
}

/* C's values from L's (Galerkin sums), one coarse row per aggregate. */
static void coarse_values(const spn__mg *mg, const spn__eq *e, const mg_level *L, int l, mg_level *C)
{
    (void)mg; /* only its thread count, unused without OpenMP */
    const uint32_t nc = C->n;
#pragma omp parallel for schedule(static) num_threads(team(mg, nc))
    for (uint32_t I = 0; I < nc; I++) {
        memset(C->val + 9 * (size_t)C->row_start[I], 0,
               9 * (size_t)(C->row_start[I + 1] - C->row_start[I]) * sizeof *C->val);
        for (uint32_t m = L->mem_start[I]; m < L->mem_start[I + 1]; m++) {
            uint32_t i = L->mem[m];
            if (l == 0) {
                add_sym(C->val + 9 * (size_t)L->mapd[i], e->diag + 6 * (size_t)i, 1);
                for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++)
                    if (e->adj_other[j] >= 0)
                        add_sym(C->val + 9 * (size_t)L->map[j], e->hs + 6 * (size_t)(e->adj[j] >> 1), -1);
            } else {
                for (uint32_t j = L->row_start[i]; j < L->row_start[i + 1]; j++) {
                    double *dst = C->val + 9 * (size_t)L->map[j];
                    const double *src = L->val + 9 * (size_t)j;
                    for (int k = 0; k < 9; k++) dst[k] += src[k];
                }
            }
        }
    }
}

/* Inverted diagonal blocks of an explicit level; false if one is singular. */
static bool level_inverse(const spn__mg *mg, mg_level *C)
{
    (void)mg;
    int bad = 0;
#pragma omp parallel for schedule(static) num_threads(team(mg, C->n)) reduction(+ : bad)
    for (uint32_t I = 0; I < C->n; I++) {
        const double *v = C->val + 9 * (size_t)C->row_start[I];
        double h[6] = {v[0], v[4], v[8], 0.5 * (v[1] + v[3]), 0.5 * (v[2] + v[6]), 0.5 * (v[5] + v[7])};
        if (!spn__sym_inverse(h, C->inv + 6 * (size_t)I)) bad++;
    }
    return bad == 0;
}

/* Dense Cholesky of the coarsest level (lower triangle, row-major). */
static bool dense_factor(spn__mg *mg, const mg_level *C)
{
    size_t N = 3 * (size_t)C->n;
    double *a = mg->dense;
    memset(a, 0, N * N * sizeof *a);
    for (uint32_t I = 0; I < C->n; I++)
        for (uint32_t j = C->row_start[I]; j < C->row_start[I + 1]; j++)
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) a[(3 * I + r) * N + 3 * C->col[j] + c] += C->val[9 * (size_t)j + 3 * r + c];
    for (size_t k = 0; k < N; k++) {
        double d = a[k * N + k];
        for (size_t p = 0; p < k; p++) d -= a[k * N + p] * a[k * N + p];
        if (!(d > 0)) return false;
        d = sqrt(d);
        a[k * N + k] = d;
        for (size_t i = k + 1; i < N; i++) {
            double s = a[i * N + k];
            for (size_t p = 0; p < k; p++) s -= a[i * N + p] * a[k * N + p];
            a[i * N + k] = s / d;
        }
    }
    return true;
}

static void dense_solve(const spn__mg *mg, const mg_level *C, const double *b, double *x)
{
    size_t N = 3 * (size_t)C->n;
    const double *a = mg->dense;
    for (size_t i = 0; i < N; i++) {
        double s = b[i];
        for (size_t p = 0; p < i; p++) s -= a[i * N + p] * x[p];
        x[i] = s / a[i * N + i];
    }
    for (size_t i = N; i-- > 0;) {
        double s = x[i];
        for (size_t p = i + 1; p < N; p++) s -= a[p * N + i] * x[p];
        x[i] = s / a[i * N + i];
    }
}

/* ---- setup ---------------------------------------------------------------- */

void spn__mg_free(spn__mg *mg)
{
    if (!mg) return;
    for (int l = 0; l < MAX_LEVELS; l++) {
        mg_level *L = &mg->lv[l];
        free(L->row_start), free(L->col), free(L->val), free(L->r);
        free(L->agg), free(L->mem_start), free(L->mem), free(L->map), free(L->mapd);
        if (l > 0) free(L->inv), free(L->x), free(L->b);
    }
    free(mg->dense);
    free(mg);
}

/* Aggregate level l and build level l + 1's pattern and work arrays. */
static bool add_level(spn__mg *mg, const spn__eq *e, int l)
{
    mg_level *L = &mg->lv[l], *C = &mg->lv[l + 1];
    L->agg = malloc((L->n ? L->n : 1) * sizeof *L->agg);
    if (!L->agg) return false;
    C->n = aggregate(e, L, l);
    if (C->n == 0 || !members(L, C->n) || !coarse_pattern(e, L, l, C)) return false;
    size_t n3 = 3 * (size_t)(C->n ? C->n : 1);
    C->inv = malloc(2 * n3 * sizeof *C->inv);
    C->x = malloc(n3 * sizeof *C->x);
    C->b = malloc(n3 * sizeof *C->b);
    C->r = malloc(n3 * sizeof *C->r);
    return C->inv && C->x && C->b && C->r;
}

/* Refill every coarse level from the current Newton system. */
static bool refresh(spn__mg *mg, const spn__eq *e)
{
    for (int l = 0; l + 1 < mg->nlevels; l++) {
        coarse_values(mg, e, &mg->lv[l], l, &mg->lv[l + 1]);
        if (!level_inverse(mg, &mg->lv[l + 1])) return false;
    }
    return dense_factor(mg, &mg->lv[mg->nlevels - 1]);
}

spn_status spn__mg_setup(spn__mg **out, const spn__eq *e, const double *inv0)
{
    spn__mg *mg = *out;
    if (!mg) {
        mg = calloc(1, sizeof *mg);
        if (!mg) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
        *out = mg;
        mg->threads = e->threads;
        mg->lv[0].n = e->n;
        mg->lv[0].r = malloc(3 * (size_t)(e->n ? e->n : 1) * sizeof *mg->lv[0].r);
        if (!mg->lv[0].r) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
        int l = 0;
        while (mg->lv[l].n > COARSEST && l + 1 < MAX_LEVELS) {
            if (!add_level(mg, e, l)) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory (multigrid)");
            mg->nlevels = l + 2;
            /* the next level's strength needs its values */
            coarse_values(mg, e, &mg->lv[l], l, &mg->lv[l + 1]);
            if (mg->lv[l + 1].n * 10 > mg->lv[l].n * 9) break; /* coarsening stalled */
            l++;
        }
        if (mg->nlevels == 0) mg->nlevels = 1;
        size_t N = 3 * (size_t)mg->lv[mg->nlevels - 1].n;
        mg->dense = malloc((N ? N * N : 1) * sizeof *mg->dense);
        if (!mg->dense) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory (multigrid)");
    }
    mg->lv[0].inv = (double *)inv0;
    if (mg->nlevels == 1) return SPN_OK; /* small: block Jacobi alone (see apply) */
    return refresh(mg, e) ? SPN_OK : SPN_ERR_UNSTABLE;
}

/* ---- the cycle ------------------------------------------------------------ */

/* r = b - A x on level l. */
static void residual(const spn__mg *mg, const spn__eq *e, int l, const double *b, const double *x, double *r)
{
    const mg_level *L = &mg->lv[l];
    if (l == 0) {
        spn__eq_matvec(e, x, r);
        const uint32_t n3 = 3 * L->n;
#pragma omp parallel for schedule(static) num_threads(team(mg, L->n))
        for (uint32_t i = 0; i < n3; i++) r[i] = b[i] - r[i];
        return;
    }
#pragma omp parallel for schedule(static) num_threads(team(mg, L->n))
    for (uint32_t i = 0; i < L->n; i++) {
        double acc[3] = {b[3 * i], b[3 * i + 1], b[3 * i + 2]};
        for (uint32_t j = L->row_start[i]; j < L->row_start[i + 1]; j++) {
            const double *v = L->val + 9 * (size_t)j, *xc = x + 3 * (size_t)L->col[j];
            acc[0] -= v[0] * xc[0] + v[1] * xc[1] + v[2] * xc[2];
            acc[1] -= v[3] * xc[0] + v[4] * xc[1] + v[5] * xc[2];
            acc[2] -= v[6] * xc[0] + v[7] * xc[1] + v[8] * xc[2];
        }
        memcpy(r + 3 * (size_t)i, acc, sizeof acc);
    }
}

/* x = omega D^-1 r (first) or x += omega D^-1 r. */
static void jacobi(const spn__mg *mg, const mg_level *L, const double *r, double *x, bool first)
{
    (void)mg;
#pragma omp parallel for schedule(static) num_threads(team(mg, L->n))
    for (uint32_t i = 0; i < L->n; i++) {
        double t[3];
        spn__sym_mul(L->inv + 6 * (size_t)i, r + 3 * (size_t)i, t);
        for (int c = 0; c < 3; c++) x[3 * i + c] = (first ? 0 : x[3 * i + c]) + OMEGA * t[c];
    }
}

/* One block Gauss-Seidel sweep on level 0 (forward or backward), in place. */
static void gauss_seidel(const spn__eq *e, const double *inv, const double *b, double *x, bool forward)
{
    const uint32_t n = e->n;
    for (uint32_t k = 0; k < n; k++) {
        uint32_t i = forward ? k : n - 1 - k;
        double acc[3] = {b[3 * i], b[3 * i + 1], b[3 * i + 2]};
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
            uint32_t c = (uint32_t)e->adj_col[j];
            if (c == i) continue;
            double t[3];
            spn__sym_mul(e->offd + 6 * (size_t)j, x + 3 * (size_t)c, t);
            acc[0] -= t[0], acc[1] -= t[1], acc[2] -= t[2];
        }
        spn__sym_mul(inv + 6 * (size_t)i, acc, x + 3 * (size_t)i);
    }
}

static void vcycle(const spn__mg *mg, const spn__eq *e, int l, const double *b, double *x)
{
    const mg_level *L = &mg->lv[l];
    if (l == mg->nlevels - 1) {
        dense_solve(mg, L, b, x);
        return;
    }
    if (l == 0 && FINE_GS) {
        memset(x, 0, 3 * (size_t)L->n * sizeof *x);
        for (int s = 0; s < SWEEPS; s++) gauss_seidel(e, L->inv, b, x, true);
    } else {
        jacobi(mg, L, b, x, true);
        for (int s = 1; s < SWEEPS; s++) {
            residual(mg, e, l, b, x, L->r);
            jacobi(mg, L, L->r, x, false);
        }
    }
    residual(mg, e, l, b, x, L->r);
    const mg_level *C = &mg->lv[l + 1];
#pragma omp parallel for schedule(static) num_threads(team(mg, C->n))
    for (uint32_t I = 0; I < C->n; I++) {
        double s[3] = {0, 0, 0};
        for (uint32_t m = L->mem_start[I]; m < L->mem_start[I + 1]; m++)
            for (int c = 0; c < 3; c++) s[c] += L->r[3 * (size_t)L->mem[m] + c];
        memcpy(C->b + 3 * (size_t)I, s, sizeof s);
    }
    vcycle(mg, e, l + 1, C->b, C->x);
#pragma omp parallel for schedule(static) num_threads(team(mg, L->n))
    for (uint32_t i = 0; i < L->n; i++)
        for (int c = 0; c < 3; c++) x[3 * i + c] += C->x[3 * (size_t)L->agg[i] + c];
    if (l == 0 && FINE_GS) {
        for (int s = 0; s < SWEEPS; s++) gauss_seidel(e, L->inv, b, x, false);
        return;
    }
    for (int s = 0; s < SWEEPS; s++) {
        residual(mg, e, l, b, x, L->r);
        jacobi(mg, L, L->r, x, false);
    }
}

void spn__mg_apply(const spn__mg *mg, const spn__eq *e, const double *r, double *z)
{
    if (mg->nlevels == 1) {
        for (uint32_t i = 0; i < e->n; i++) spn__sym_mul(mg->lv[0].inv + 6 * (size_t)i, r + 3 * (size_t)i, z + 3 * (size_t)i);
        return;
    }
    vcycle(mg, e, 0, r, z);
}

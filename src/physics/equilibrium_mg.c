/* Smoothed-aggregation multigrid preconditioner for the equilibrium solver's
 * Newton systems (Vanek, Mandel & Brezina 1996, "Algebraic multigrid by
 * smoothed aggregation"), a symmetric V-cycle so CG can use it. It works on
 * the spring graph of any web; nothing assumes rings and radials.
 *
 * Hierarchy: particles are grouped into aggregates over the strong couplings
 * (a block A_ij is strong when |A_ij|_F >= THETA sqrt(|A_ii|_F |A_jj|_F):
 * a root whose strong neighbours are all free takes them, the rest join the
 * aggregate they are most strongly tied to; a level whose aggregates
 * come out thin is aggregated again at a lower THETA_THIN, and if still
 * thin its aggregates are aggregated: THIN_AGGREGATES). The tentative
 * prolongator P0
 * copies an aggregate's three translations to its members: rigid
 * translations are the near-kernel of a taut web (out of plane its operator
 * is a weighted Laplacian, in plane two of them, 50:1 anisotropic). P0 is
 * smoothed by one damped block-Jacobi step, P = (I - omega D^-1 A) P0 with
 * omega = 4 / (3 rho(D^-1 A)), so the coarse functions decay smoothly across
 * an aggregate instead of stepping at its edge. The coarse operator is the
 * Galerkin product R A P, R = P^T (equilibrium_bsr.c). Smoothing widens the
 * stencil a level at a time; a level denser than MAX_SMOOTHED_ROW blocks a
 * row keeps P0, a guard against a runaway stencil (the densest level of the
 * 1M web has 145 blocks a row). Levels stop at COARSEST particles, solved by
 * dense Cholesky.
 *
 * Smoothing: on the finest level one sweep of thread-line relaxation
 * (equilibrium_lines.c: exact solves along every thread, for the 50:1
 * anisotropy of silk) forward before the coarse correction and backward
 * after; on the coarse levels block Gauss-Seidel the same way.
 *
 * Thread slides: on spring systems, the finest level also gets the
 * correction of equilibrium_slide.c (one unknown per thread line: the line
 * sliding along itself) after the pre-smoothing and again before the
 * post-smoothing, which keeps the cycle symmetric. Those are the soft modes
 * of a net without diagonals (a ring sliding along itself is a rotation;
 * rings rotating by different amounts twist the web) that translating
 * aggregates cannot follow.
 *
 * Measured on the 5k web (CG iterations to 1e-6 T0): plain aggregation with
 * Gauss-Seidel 168 (the code this replaced); smoothed aggregation with
 * Gauss-Seidel 47; plain aggregation with lines 36; both 23 (25 with the
 * Newton path of today); with the thread slides 12 (100k web: 54 -> 24).
 *
 * Newton steps: the hierarchy is built from the first Newton system and
 * kept; each later step refreshes the finest level and the line factors
 * (and, on webs above SLIDE_REFRESH_N, the slide matrix; from
 * GALERKIN_REFRESH_N, the coarse levels' values: refresh()). The Hessian of
 * a taut web changes little between steps, and a stale coarse operator is
 * still symmetric positive definite (measured: 22 CG instead of 23 at 5k,
 * 65 instead of 60 at 100k, for a setup a quarter the cost; on the 1M web
 * the stale coarse levels cost 6 of 34 CG, see refresh()). If the first
 * system cannot be factored (a singular web), the hierarchy is dropped and
 * built again from the next, shifted, system.
 * Every product writes its own rows in a fixed order: the same bits for any
 * thread count. */
#include "core/big_alloc.h"
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define THETA 0.08      /* strong coupling (block norms, scaled by the diagonals) */
/* A level whose aggregates average fewer than THIN_AGGREGATES rows is
 * aggregated again with the coupling threshold THETA_THIN. Why: threads of
 * many particles whose ties to the threads they cross fall under THETA
 * (a species web's form finding, where the capture spiral pulls with a
 * fraction of the radii's tension) aggregate along each thread alone, three
 * particles at a time; the next level is then a looser net of the same
 * kind, and the smoothed stencils densify level after level instead of
 * shrinking. Zilla webs' form finding, levels' rows (blocks a row) and
 * setup: 185k particles, 67k (8.6), 26k (54), 5.4k (175) with THETA alone,
 * 50k (6.0), 6.4k (19), 0.9k (57) with this, CG 39 both ways, 5.2 -> 3.4 s
 * and 626 -> 423 MB; 406k particles 77 -> 19 s, 2.0 -> 1.0 GB. THETA / 4
 * was not enough (5.3 s); THETA / 16 and 0 were alike (0: 43 CG). The
 * standard web coarsens by 5-6 a level and never meets the rule: THETA
 * itself at 0.005 took its 20k web from 25 to 33 CG.
 * Where the aggregates are still thin, every tie was strong already: a web
 * whose threads are chains of many particles (a species web at rest, where
 * the settle solves it) aggregates three to a chain at any threshold. Then
 * the aggregates themselves are aggregated (aggregate_again). Zilla 2 m at
 * rest (185k particles), the settle's solve: levels 67k, 26k (54 blocks a
 * row), 5.3k (176) -> 11.7k (10.5), 1.1k, 272; CG 22 -> 34, but
 * `spinneret settle --method equilibrium` 4.5 -> 2.0-2.5 s and 615 -> 380
 * MB; `build --settle` 2 m 9.1 -> 6.0 s, 3 m 24.5 -> 15.7 s, 5 m (1.1M)
 * 106 s and 5.9 GB -> 57 s and 2.6 GB. */
#define THIN_AGGREGATES 3.2
#define THETA_THIN (THETA / 16)
#define COARSEST 40u    /* particles on the level solved by dense Cholesky */
#define DENSE_MAX 300u  /* a coarsest level larger than this (coarsening stalled) gets Gauss-Seidel sweeps instead */
#define COARSE_SWEEPS 4
#define MAX_LEVELS 24
/* Blocks a row above which a level's prolongator is not smoothed. It was 64
 * until 2026-11-22, which left level 3 of the 1M web (5,326 rows, 145 blocks
 * a row) with P0: CG 62 -> 45 and the solve about 7 s faster with it
 * smoothed, the first setup no dearer (its level 4 has 656 rows); the 5k and
 * 100k webs keep 12 and 24 CG. */
#define MAX_SMOOTHED_ROW 256.0
/* A row longer than LONG_ROW_FACTOR times its level's mean and than
 * LONG_ROW_MIN blocks (the hub, where every radial meets) keeps its
 * tentative prolongator row: see smoothed_prolongator. */
#define LONG_ROW_FACTOR 8.0
#define LONG_ROW_MIN 64.0
#define POWER_STEPS 10  /* power iterations for rho(D^-1 A) on coarse levels */
/* Free particles above which the slide matrix is factored again at every
 * Newton step instead of kept from the first (see spn__mg_setup). */
#define SLIDE_REFRESH_N 50000u
/* Free particles from which a later Newton step forms the coarse levels
 * again from its own system (spn__bsr_galerkin_refresh: the aggregates and
 * prolongators kept, only R A P's values). */
#define GALERKIN_REFRESH_N 200000u
static uint32_t galerkin_refresh_n = GALERKIN_REFRESH_N;

uint32_t spn__mg_set_refresh_min(uint32_t free_particles)
{
    const uint32_t old = galerkin_refresh_n;
    galerkin_refresh_n = free_particles;
    return old;
}

typedef struct mg_level {
    spn__bsr A;         /* the level's matrix, diagonal block first in each row; level 0 of a
                         * spring system keeps only its pattern once the hierarchy is built */
    double *dinv;       /* 6 per row: inverted diagonal blocks */
    double *x, *b, *r;  /* 3 per row */
    /* to the next coarser level */
    uint32_t *agg;      /* coarse row of each row */
    double omega;       /* prolongator smoothing damping */
    spn__bsr P, R;      /* P = (I - omega D^-1 A) P0 (or P0), R = P^T */
    spn__lines *lines;  /* NULL: point Gauss-Seidel */
    spn__bsr_refresh *keep; /* the scratch of forming the next level again (refresh), kept between Newton steps */
} mg_level;

struct spn__mg {
    int nlevels;
    mg_level lv[MAX_LEVELS];
    uint32_t *map0;     /* per adjacency entry of the spring system: its level-0 block, or UINT32_MAX */
    /* per level-0 block of a spring system while the hierarchy is built
     * (and after, when later systems refresh it): its spring, or SRC_DIAG |
     * its row (level0_block); NULL where level 0 keeps its values (see
     * level0_pattern) */
    uint32_t *src0;
    const spn__eq *eq0; /* the system src0 reads */
    spn__slide *slide;  /* thread-slide correction on level 0 (spring systems only), or NULL */
    bool slide_ok;      /* its matrix factored (from the first system that allowed it; kept on small webs) */
    double *dense;      /* coarsest level's Cholesky factor */
    int threads;
    bool refresh;       /* later systems form the coarse levels again (GALERKIN_REFRESH_N); src0 kept */
};

/* ---- level 0 from the spring system --------------------------------------- */

/* m += the full 3x3 of a symmetric block (several springs between one pair
 * of particles sum into one block). */
static void sym_full_add(const double *h, double *m)
{
    m[0] += h[0], m[1] += h[3], m[2] += h[4];
    m[3] += h[3], m[4] += h[1], m[5] += h[5];
    m[6] += h[4], m[7] += h[5], m[8] += h[2];
}

#define SRC_DIAG 0x80000000u

/* Level-0 block p from the springs, summed as level0_values sums it (from
 * zero): the same bits. */
static const double *level0_block(const void *ctx, size_t p, double *tmp)
{
    const spn__mg *mg = ctx;
    const spn__eq *e = mg->eq0;
    const uint32_t s = mg->src0[p];
    /* the diagonal block, or -H_s as spn__eq_offd gives it for two free ends */
    const double *h = s & SRC_DIAG ? e->diag + 6 * (size_t)(s & ~SRC_DIAG) : e->hs + 6 * (size_t)s;
    const double sign = s & SRC_DIAG ? 1 : -1;
    double o[6];
    for (int c = 0; c < 6; c++) o[c] = 0.0 + sign * h[c];
    spn__sym_full(o, tmp);
    return tmp;
}

/* Pattern: per particle its diagonal, then each free neighbour once (parallel springs merged). */
static bool level0_pattern(spn__mg *mg, const spn__eq *e)
{
    spn__bsr *a = &mg->lv[0].A;
    uint32_t n = e->n, nadj = e->adj_start[n];
    a->rows = a->cols = n;
    a->start = spn__big_alloc(((size_t)n + 1) * sizeof *a->start);
    a->col = spn__big_alloc(((size_t)n + nadj + 1) * sizeof *a->col);
    mg->map0 = spn__big_alloc((nadj ? nadj : 1) * sizeof *mg->map0);
    uint32_t *src = e->hs && !e->offd ? malloc(((size_t)n + nadj + 1) * sizeof *src) : NULL; /* offd: spn__eq_offd's blocks */
    if (!a->start || !a->col || !mg->map0 || (e->hs && !e->offd && !src)) {
        free(src);
        return false;
    }
    uint32_t nnz = 0;
    bool merged = false;
    a->start[0] = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (src) src[nnz] = SRC_DIAG | i;
        a->col[nnz++] = i;
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
            mg->map0[j] = UINT32_MAX;
            if (e->adj_other[j] < 0) continue;
            uint32_t c = (uint32_t)e->adj_other[j], p = a->start[i] + 1;
            while (p < nnz && a->col[p] != c) p++;
            if (p == nnz) {
                if (src) src[nnz] = e->adj[j] >> 1;
                a->col[nnz++] = c;
            } else {
                merged = true;
            }
            mg->map0[j] = p;
        }
        a->start[i + 1] = nnz;
    }
    /* A spring system's level 0 serves only to build the hierarchy (the
     * cycle multiplies from the springs, spn__eq_matvec_mg): its blocks are
     * read from the springs as the setup meets them (level0_block) instead of
     * stored (360 MB on the 1M web, a tenth of the solve's page faults). A
     * pair of particles joined by several springs sums them: such a web, and
     * the implicit step's system (no spring blocks), keep the values. */
    if (src && !merged && n < SRC_DIAG && e->m < SRC_DIAG) {
        mg->src0 = src;
        mg->eq0 = e;
        a->blk = level0_block;
        a->blk_ctx = mg;
        return true;
    }
    free(src);
    a->val = spn__big_alloc(9 * (size_t)(nnz ? nnz : 1) * sizeof *a->val);
    return a->val != NULL;
}

static void level0_values(spn__mg *mg, const spn__eq *e)
{
    spn__bsr *a = &mg->lv[0].A;
    const uint32_t n = e->n;
#pragma omp parallel for schedule(static) num_threads(n < 16384u ? 1 : mg->threads)
    for (uint32_t i = 0; i < n; i++) {
        double *row = a->val + 9 * (size_t)a->start[i];
        memset(row, 0, 9 * (size_t)(a->start[i + 1] - a->start[i]) * sizeof *row);
        sym_full_add(e->diag + 6 * (size_t)i, row);
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
            double o[6];
            if (mg->map0[j] != UINT32_MAX) sym_full_add(spn__eq_offd(e, j, o), a->val + 9 * (size_t)mg->map0[j]);
        }
    }
}

/* ---- aggregation ------------------------------------------------------------ */

static double fro(const double *m)
{
    double s = 0;
    for (int k = 0; k < 9; k++) s += m[k] * m[k];
    return sqrt(s);
}

/* Strength: bn[p] = |A_p|_F, dn[i] = |A_ii|_F. */
static bool strong(const spn__bsr *a, const double *bn, const double *dn, uint32_t i, uint32_t p, double theta)
{
    uint32_t c = a->col[p];
    return c != i && bn[p] >= theta * sqrt(dn[i] * dn[c]);
}

/* Fills agg; returns the number of aggregates (0: out of memory). The
 * blocks' norms are formed once, on the team (level 0 of a spring system
 * forms its blocks from the springs; the greedy passes below meet most
 * blocks two or three times). */
static uint32_t aggregate(const spn__bsr *a, uint32_t *agg, double theta, int threads)
{
    (void)threads; /* (used by OpenMP pragmas only) */
    const uint32_t n = a->rows, NONE = UINT32_MAX;
    const size_t nnz = a->start[n];
    double *dn = malloc((n ? n : 1) * sizeof *dn), *bn = malloc((nnz ? nnz : 1) * sizeof *bn);
    uint32_t *join = malloc((n ? n : 1) * sizeof *join), na = 0;
    if (!dn || !bn || !join) {
        free(dn), free(bn), free(join);
        return 0;
    }
#pragma omp parallel for schedule(static) num_threads(spn__bsr_team(a, threads))
    for (uint32_t i = 0; i < n; i++) {
        double tmp[9];
        for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) bn[p] = fro(spn__bsr_block(a, p, tmp));
        agg[i] = NONE;
        dn[i] = bn[a->start[i]];
    }
    for (uint32_t i = 0; i < n; i++) { /* roots whose strong neighbours are all free */
        bool free_all = agg[i] == NONE, any = false;
        for (uint32_t p = a->start[i]; p < a->start[i + 1] && free_all; p++)
            if (strong(a, bn, dn, i, p, theta)) {
                any = true;
                if (agg[a->col[p]] != NONE) free_all = false;
            }
        /* a particle tied only weakly (slack threads) joins a neighbour below
         * instead of rooting an aggregate of one: on a species web those
         * stalled the coarsening and left a dense coarsest level of 1,000+ rows */
        if (!free_all || !any) continue;
        agg[i] = na;
        for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++)
            if (strong(a, bn, dn, i, p, theta)) agg[a->col[p]] = na;
        na++;
    }
    for (uint32_t i = 0; i < n; i++) { /* the rest join their most strongly tied neighbour's aggregate */
        join[i] = agg[i];
        if (agg[i] != NONE) continue;
        double best = -1;
        for (uint32_t p = a->start[i] + 1; p < a->start[i + 1]; p++) {
            uint32_t c = a->col[p];
            double s = bn[p] / sqrt(dn[c]);
            if (agg[c] != NONE && s > best) best = s, join[i] = agg[c];
        }
    }
    for (uint32_t i = 0; i < n; i++) agg[i] = join[i] != NONE ? join[i] : na++; /* isolated: alone */
    free(dn), free(bn), free(join);
    return na;
}

/* Aggregates of the aggregates in agg (nc of them): two aggregates are
 * neighbours when a block of A joins their members, tied as strongly as the
 * sum of those blocks' norms; they are grouped by aggregate()'s rule with
 * every tie strong (a root whose neighbours are all free takes them, the
 * rest join their most strongly tied neighbour's group, an isolated one
 * stays alone), in the order of the aggregates. agg is rewritten to the
 * groups; returns their number (0: out of memory). */
static uint32_t aggregate_again(const spn__bsr *a, uint32_t *agg, uint32_t nc)
{
    const uint32_t n = a->rows, NONE = UINT32_MAX;
    uint32_t *first = calloc((size_t)nc + 1, sizeof *first), *member = malloc((n ? n : 1) * sizeof *member);
    uint32_t *group = malloc((nc ? nc : 1) * sizeof *group), *seen = malloc((nc ? nc : 1) * sizeof *seen);
    double *tie = malloc((nc ? nc : 1) * sizeof *tie);
    uint32_t ng = 0, stamp = 0;
    if (!first || !member || !group || !seen || !tie) goto done;
    for (uint32_t i = 0; i < n; i++) first[agg[i] + 1]++;
    for (uint32_t k = 0; k < nc; k++) first[k + 1] += first[k];
    for (uint32_t i = 0; i < n; i++) member[first[agg[i]]++] = i;
    for (uint32_t k = nc; k > 0; k--) first[k] = first[k - 1];
    first[0] = 0;
    for (uint32_t k = 0; k < nc; k++) group[k] = NONE, seen[k] = 0;
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t K = 0; K < nc; K++) {
            if (group[K] != NONE) continue;
            /* K's neighbours, each once (seen), with the sum of their ties */
            bool free_all = true, any = false;
            uint32_t best = NONE;
            stamp++;
            for (uint32_t m = first[K]; m < first[K + 1]; m++)
                for (uint32_t q = a->start[member[m]]; q < a->start[member[m] + 1]; q++) {
                    const uint32_t J = agg[a->col[q]];
                    if (J == K) continue;
                    double tmp[9];
                    const double t = fro(spn__bsr_block(a, q, tmp));
                    if (seen[J] != stamp) seen[J] = stamp, tie[J] = 0;
                    tie[J] += t;
                    any = true;
                    free_all = free_all && group[J] == NONE;
                }
            if (pass == 0 && any && free_all) { /* a root: takes its neighbours */
                for (uint32_t m = first[K]; m < first[K + 1]; m++)
                    for (uint32_t q = a->start[member[m]]; q < a->start[member[m] + 1]; q++)
                        if (agg[a->col[q]] != K) group[agg[a->col[q]]] = ng;
                group[K] = ng++;
            } else if (pass == 1) { /* joins its most strongly tied neighbour's group, or stays alone */
                for (uint32_t m = first[K]; m < first[K + 1]; m++)
                    for (uint32_t q = a->start[member[m]]; q < a->start[member[m] + 1]; q++) {
                        const uint32_t J = agg[a->col[q]];
                        if (J != K && group[J] != NONE && (best == NONE || tie[J] > tie[best])) best = J;
                    }
                group[K] = best != NONE ? group[best] : ng++;
            }
        }
    for (uint32_t i = 0; i < n; i++) agg[i] = group[agg[i]];
done:
    free(first), free(member), free(group), free(seen), free(tie);
    return ng;
}

/* ---- prolongator and coarse operator ------------------------------------- */

static bool level_inverse(const mg_level *L)
{
    int bad = 0;
    for (uint32_t i = 0; i < L->A.rows; i++) {
        double t[9];
        const double *v = spn__bsr_block(&L->A, L->A.start[i], t);
        double h[6] = {v[0], v[4], v[8], 0.5 * (v[1] + v[3]), 0.5 * (v[2] + v[6]), 0.5 * (v[5] + v[7])};
        if (!spn__sym_inverse(h, L->dinv + 6 * (size_t)i)) bad++;
    }
    return bad == 0;
}

/* rho(D^-1 A) by power iteration from a fixed start (a bound of 2 holds on
 * level 0, where A is a sum of positive semi-definite spring blocks). */
static double spectral_radius(const mg_level *L, int threads)
{
    size_t n3 = 3 * (size_t)L->A.rows;
    double *v = L->x, *w = L->r, rho = 2;
    for (size_t k = 0; k < n3; k++) v[k] = 1 + 0.37 * (double)(k % 7) - 0.11 * (double)(k % 3);
    for (int it = 0; it < POWER_STEPS; it++) {
        spn__bsr_apply(&L->A, v, w, false, threads);
        double num = 0, den = 0;
        for (uint32_t i = 0; i < L->A.rows; i++) {
            double t[3];
            spn__sym_mul(L->dinv + 6 * (size_t)i, w + 3 * (size_t)i, t);
            for (int c = 0; c < 3; c++) {
                num += t[c] * t[c];
                den += v[3 * i + c] * v[3 * i + c];
                w[3 * i + c] = t[c];
            }
        }
        rho = den > 0 ? sqrt(num / den) : 1;
        double scale = num > 0 ? 1 / sqrt(num) : 0;
        for (size_t k = 0; k < n3; k++) v[k] = w[k] * scale;
    }
    return 1.1 * rho; /* power iteration approaches from below */
}

/* P = (I - omega D^-1 A) P0, straight from A and the aggregates: row i of
 * P has a block for each aggregate among row i's columns, the sum of
 * -omega D_i^-1 A_ic over its columns c (plus I for c = i). Forming the
 * smoother matrix and multiplying it by P0 (whose blocks are identities)
 * did the same with three times the arithmetic and a matrix more memory.
 * (Keeping only the strong blocks, the weak ones lumped on the diagonal,
 * made the coarse levels sparser but the method weaker: 80 CG iterations
 * instead of 53 at 100k; measured.)
 *
 * Long rows (long_row) keep P0's row, one identity block. Smoothed, the
 * hub's row of P would have a block for each aggregate among its 1,000
 * radials, and the Galerkin product R A P puts the outer product of that
 * row with itself into the next level: a dense 333 x 333 block there, and
 * again below. On the 1M web that one row made 88% of level 1's block
 * products (72M instead of 8.4M) and a third of the coarse levels' blocks
 * (levels 1-3: 4.1M instead of 2.9M); kept tentative, the first setup
 * took 2.5-3.0 s instead of 4.6 s (two threads) and the solve 45 -> 47 CG.
 * Measured 2026-11-22; the 5k and 100k webs keep 12 and 24 CG, the species
 * webs (hubs below the limit) their bits. */
static bool long_row(const spn__bsr *A, uint32_t i, double limit)
{
    return A->start[i + 1] - A->start[i] > limit;
}

static bool smoothed_prolongator(mg_level *L, uint32_t nc, int threads)
{
    const spn__bsr *A = &L->A;
    const uint32_t n = A->rows, per = nc ? nc : 1;
    const double mean = n ? (double)A->start[n] / n : 0,
                 limit = LONG_ROW_FACTOR * mean > LONG_ROW_MIN ? LONG_ROW_FACTOR * mean : LONG_ROW_MIN;
    /* rows are independent: each thread marks its rows' aggregates in its
     * own arrays (the same bits on any team) */
    const int nt = spn__bsr_team(A, threads);
    uint32_t *marks = malloc(2 * (size_t)nt * per * sizeof *marks);
    spn__bsr *P = &L->P;
    P->rows = n, P->cols = nc;
    P->start = spn__big_alloc(((size_t)n + 1) * sizeof *P->start);
    if (!marks || !P->start) {
        free(marks);
        return false;
    }
    for (size_t c = 0; c < (size_t)nt * per; c++) marks[c] = UINT32_MAX;
    P->start[0] = 0;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (uint32_t i = 0; i < n; i++) {
        uint32_t *mark = marks + (size_t)spn__thread_num() * per, cnt = 0;
        if (long_row(A, i, limit)) {
            P->start[i + 1] = 1;
            continue;
        }
        for (uint32_t p = A->start[i]; p < A->start[i + 1]; p++) {
            uint32_t g = L->agg[A->col[p]];
            if (mark[g] != i) mark[g] = i, cnt++;
        }
        P->start[i + 1] = cnt;
    }
    for (uint32_t i = 0; i < n; i++) P->start[i + 1] += P->start[i];
    size_t nnz = P->start[n];
    P->col = spn__big_alloc((nnz ? nnz : 1) * sizeof *P->col);
    /* not calloc: the blocks are summed into, and a first read of a calloc'd
     * page maps the shared zero page, which the first write must then copy
     * (two faults a page; 0.6 s of CPU on the 1M web). Each row is zeroed
     * just before its sums instead, a write first. */
    P->val = spn__big_alloc(9 * (nnz ? nnz : 1) * sizeof *P->val);
    if (!P->col || !P->val) {
        free(marks);
        return false;
    }
    for (size_t c = 0; c < (size_t)nt * per; c++) marks[c] = UINT32_MAX;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (uint32_t i = 0; i < n; i++) {
        uint32_t *mark = marks + (size_t)spn__thread_num() * per, *pos = marks + ((size_t)nt + spn__thread_num()) * per;
        const double *d = L->dinv + 6 * (size_t)i;
        double di[9] = {-L->omega * d[0], -L->omega * d[3], -L->omega * d[4], -L->omega * d[3], -L->omega * d[1],
                        -L->omega * d[5], -L->omega * d[4], -L->omega * d[5], -L->omega * d[2]};
        uint32_t cnt = P->start[i];
        memset(P->val + 9 * (size_t)cnt, 0, 9 * (size_t)(P->start[i + 1] - cnt) * sizeof *P->val);
        if (long_row(A, i, limit)) { /* P0's row */
            double *pv = P->val + 9 * (size_t)cnt;
            P->col[cnt] = L->agg[i];
            pv[0] = pv[4] = pv[8] = 1;
            continue;
        }
        for (uint32_t p = A->start[i]; p < A->start[i + 1]; p++) {
            uint32_t c = A->col[p], g = L->agg[c];
            if (mark[g] != i) mark[g] = i, pos[g] = cnt, P->col[cnt++] = g;
            double *pv = P->val + 9 * (size_t)pos[g];
            double tb[9];
            spn__blk_mul_add(di, spn__bsr_block(A, p, tb), pv);
            if (c == i) pv[0] += 1, pv[4] += 1, pv[8] += 1;
        }
    }
    free(marks);
    return true;
}

/* Aggregate level l; build P (smoothed, or P0 on a dense level), R = P^T
 * and level l + 1 = R (A P). */
static bool add_level(spn__mg *mg, int l)
{
    mg_level *L = &mg->lv[l], *C = &mg->lv[l + 1];
    uint32_t n = L->A.rows;
    uint32_t *rperm = NULL;
    L->agg = spn__big_alloc((n ? n : 1) * sizeof *L->agg);
    if (!L->agg) return false;
    uint32_t nc = aggregate(&L->A, L->agg, THETA, mg->threads);
    if (nc > 0 && (double)n < THIN_AGGREGATES * nc) nc = aggregate(&L->A, L->agg, THETA_THIN, mg->threads);
    if (nc > 0 && (double)n < THIN_AGGREGATES * nc) nc = aggregate_again(&L->A, L->agg, nc);
    bool ok = nc > 0;
    /* smoothing widens the stencil a level at a time (5, 10, 22, 45 blocks a
     * row on the 100k web, 5, 10, 27, 63 on the 1M web): dense levels keep P0 */
    if (ok && (double)L->A.start[n] <= MAX_SMOOTHED_ROW * n) {
        L->omega = 4.0 / (3.0 * (l == 0 ? 2.0 : spectral_radius(L, mg->threads)));
        ok = smoothed_prolongator(L, nc, mg->threads);
    } else if (ok) { /* P0: an aggregate's three translations copied to its members */
        spn__bsr *P = &L->P;
        P->rows = n, P->cols = nc;
        P->start = spn__big_alloc(((size_t)n + 1) * sizeof *P->start);
        P->col = spn__big_alloc((n ? n : 1) * sizeof *P->col);
        P->val = spn__big_calloc(9 * (size_t)(n ? n : 1), sizeof *P->val);
        ok = P->start && P->col && P->val;
        for (uint32_t i = 0; ok && i <= n; i++) P->start[i] = i;
        for (uint32_t i = 0; ok && i < n; i++) {
            P->col[i] = L->agg[i];
            P->val[9 * (size_t)i] = P->val[9 * (size_t)i + 4] = P->val[9 * (size_t)i + 8] = 1;
        }
    }
    ok = ok && spn__bsr_transpose(&L->P, &L->R, &rperm) &&
         spn__bsr_galerkin_ap(&L->A, &L->P, &L->R, &C->A, mg->threads);
    /* R's float32 blocks from P (R in float64 was never made) */
    ok = ok && spn__bsr_transpose_round(&L->R, mg->threads);
    free(rperm);
    if (!ok) return false;
    size_t n3 = 3 * (size_t)(nc ? nc : 1);
    C->dinv = spn__big_alloc(2 * n3 * sizeof *C->dinv);
    C->x = spn__big_alloc(n3 * sizeof *C->x);
    C->b = spn__big_alloc(n3 * sizeof *C->b);
    C->r = spn__big_alloc(n3 * sizeof *C->r);
    return C->dinv && C->x && C->b && C->r;
}

/* Dense Cholesky of the coarsest level (lower triangle, row-major). */
static bool dense_factor(spn__mg *mg)
{
    const spn__bsr *a = &mg->lv[mg->nlevels - 1].A;
    size_t N = 3 * (size_t)a->rows;
    double *f = mg->dense;
    memset(f, 0, N * N * sizeof *f);
    for (uint32_t I = 0; I < a->rows; I++)
        for (uint32_t p = a->start[I]; p < a->start[I + 1]; p++) {
            double t[9];
            const double *v = spn__bsr_block(a, p, t);
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) f[(3 * I + r) * N + 3 * a->col[p] + c] += v[3 * r + c];
        }
    return spn__dense_cholesky(f, N, 1);
}

static void dense_solve(const spn__mg *mg, const double *b, double *x)
{
    spn__dense_cholesky_solve(mg->dense, 3 * (size_t)mg->lv[mg->nlevels - 1].A.rows, b, x, mg->threads);
}

/* ---- setup ---------------------------------------------------------------- */

void spn__mg_free(spn__mg *mg)
{
    if (!mg) return;
    for (int l = 0; l < MAX_LEVELS; l++) {
        mg_level *L = &mg->lv[l];
        spn__bsr_free(&L->A), spn__bsr_free(&L->P), spn__bsr_free(&L->R);
        free(L->agg), free(L->x), free(L->b), free(L->r);
        spn__lines_free(L->lines);
        spn__bsr_refresh_free(L->keep);
        if (l > 0) free(L->dinv);
    }
    free(mg->map0);
    free(mg->src0);
    spn__slide_free(mg->slide);
    free(mg->dense);
    free(mg);
}

bool spn__mg_level(const spn__mg *mg, int l, uint32_t *rows, uint32_t *blocks, uint32_t *longest)
{
    if (!mg || l < 0 || l >= mg->nlevels) return false;
    const spn__bsr *A = &mg->lv[l].A;
    uint32_t widest = 0;
    for (uint32_t i = 0; i < A->rows; i++)
        if (A->start[i + 1] - A->start[i] > widest) widest = A->start[i + 1] - A->start[i];
    *rows = A->rows, *blocks = A->start[A->rows], *longest = widest;
    return true;
}

static spn_status build(spn__mg *mg, const spn__eq *e, const double *inv0)
{
    mg->threads = e->threads;
    mg_level *L0 = &mg->lv[0];
    L0->dinv = (double *)inv0;
    L0->r = spn__big_alloc(3 * (size_t)(e->n ? e->n : 1) * sizeof *L0->r);
    L0->x = spn__big_alloc(3 * (size_t)(e->n ? e->n : 1) * sizeof *L0->x);
    if (!L0->r || !L0->x || !level0_pattern(mg, e)) return SPN_ERR_NOMEM;
    if (L0->A.val) level0_values(mg, e);
    mg->nlevels = 1;
    while (mg->nlevels < MAX_LEVELS && mg->lv[mg->nlevels - 1].A.rows > COARSEST) {
        int l = mg->nlevels - 1;
        if (!add_level(mg, l)) return SPN_ERR_NOMEM;
        mg->nlevels++;
        if (!level_inverse(&mg->lv[l + 1])) return SPN_ERR_UNSTABLE;
        if ((uint64_t)mg->lv[l + 1].A.rows * 10 > (uint64_t)mg->lv[l].A.rows * 9) break; /* stalled */
    }
    size_t N = 3 * (size_t)mg->lv[mg->nlevels - 1].A.rows;
    if (mg->nlevels > 1 && N <= 3 * DENSE_MAX) {
        mg->dense = spn__big_alloc((N ? N * N : 1) * sizeof *mg->dense);
        if (!mg->dense) return SPN_ERR_NOMEM;
        if (!dense_factor(mg)) return SPN_ERR_UNSTABLE;
    }
    /* Built: from here the coarse levels and the transfers are only
     * multiplied by vectors (the finest level stays float64, below): float32
     * copies halve the bytes those products read. */
    for (int l = 0; l < mg->nlevels; l++) {
        mg_level *L = &mg->lv[l];
        if (l > 0) spn__bsr_round(&L->A);
        if (L->P.val) spn__bsr_round(&L->P);
        if (L->R.val) spn__bsr_round(&L->R);
    }
    /* A spring system's level 0 is multiplied from its springs
     * (spn__eq_matvec_mg) and the line factors read their blocks from there
     * too: its values (360 MB on the 1M web) served the hierarchy only */
    mg->refresh = e->hs && mg->src0 && e->n >= galerkin_refresh_n;
    if (e->hs && !mg->refresh) {
        free(L0->A.val);
        free(mg->src0);
        L0->A.val = NULL, mg->src0 = NULL, L0->A.blk = NULL;
    }
    /* The line smoother and the slides last: their arrays then take the
     * pages the setup's temporaries (each level's A P) and the rounding have
     * just given back, which the host still backs, instead of fresh ones
     * (a fresh page costs the VM measured about 7 us, one given back
     * moments ago about 1.5: docs/physics-equilibrium.md) */
    if (!(L0->lines = spn__lines_build(e, &L0->A))) return SPN_ERR_NOMEM;
    /* NULL: too many lines, or no memory; the cycle goes without */
    if (e->hs) mg->slide = spn__slide_build(e, L0->lines);
    return SPN_OK;
}

/* The coarse levels formed again from the current finest level, top down,
 * with the aggregates, prolongators and patterns of the first system.
 * Why: the hierarchy fits the system it was built from, and a web's thread
 * tensions move between Newton steps (the standard web starts at T0 in
 * every thread; at rest its radials carry 0.43-1.75 T0, and a thread's
 * out-of-plane stiffness is its tension over its length). Measured on the
 * 1M web (2026-11-23): the second Newton solve took 23 CG with the first
 * system's coarse levels, 17 with them formed again (16 with the whole
 * hierarchy built again, aggregates and all, at three times the cost; the
 * same 17 with the prolongators smoothed again too); 34 -> 28 CG in all, 67
 * -> 51 to 1e-9 T0. The largest Ritz values of the preconditioned system
 * fell from 1.52 to 1.0: the stale levels over-corrected. Forming them
 * again costs 0.55-0.65 s there (two threads) against about 0.85 s of CG
 * saved; on the 100k web (22 -> 20 CG) the two balance, hence the
 * threshold. Every level down to the coarsest is needed: only level 1
 * formed again gave 32 CG, levels 1-2 30, 1-3 28. */
static spn_status refresh(spn__mg *mg)
{
    for (int l = 0; l + 1 < mg->nlevels; l++) {
        mg_level *L = &mg->lv[l], *C = &mg->lv[l + 1];
        if (!spn__bsr_galerkin_refresh(&L->A, &L->P, &L->R, &C->A, mg->threads, &L->keep)) return SPN_ERR_NOMEM;
        if (!level_inverse(C)) return SPN_ERR_UNSTABLE;
    }
    if (mg->dense && !dense_factor(mg)) return SPN_ERR_UNSTABLE;
    return SPN_OK;
}

spn_status spn__mg_setup(spn__mg **out, const spn__eq *e, const double *inv0)
{
    spn__mg *mg = *out;
    if (!mg) {
        mg = calloc(1, sizeof *mg);
        spn_status st = mg ? build(mg, e, inv0) : SPN_ERR_NOMEM;
        if (st != SPN_OK) { /* built again from the next (shifted) system */
            spn__mg_free(mg);
            if (st == SPN_ERR_NOMEM) return spn_error(st, "equilibrium: out of memory (multigrid, %u particles)", e->n);
            return st;
        }
        *out = mg;
    } else {
        mg->lv[0].dinv = (double *)inv0;
        if (!e->hs) level0_values(mg, e);
        spn_status st = mg->refresh ? refresh(mg) : SPN_OK;
        if (st != SPN_OK) return st == SPN_ERR_NOMEM ? spn_error(st, "equilibrium: out of memory (multigrid)") : st;
    }
    /* Like the hierarchy, the slide matrix of the first system is kept on a
     * small web: the later ones needed the same CG iterations (5k: 12, 100k:
     * 24) and refactoring costs 0.7 ms a step at 5k. On a large web it is
     * factored again every step: with the first system's matrix the 1M web's
     * Newton stalled (the residual stuck near 1e-4 T0 after 19 steps, each
     * CG stopping at its forcing term 0.1 in 4 iterations while the energy
     * fell exactly as predicted: a preconditioner that no longer fits the
     * soft modes, not a poor Newton model); refactored, it converged in 4
     * steps and 62 CG. Why the first matrix fits at 100k and not at 1M was
     * not found out. */
    if (mg->slide && (!mg->slide_ok || e->n > SLIDE_REFRESH_N)) mg->slide_ok = spn__slide_factor(mg->slide, e);
    return spn__lines_factor(mg->lv[0].lines, e, mg->threads) ? SPN_OK : SPN_ERR_UNSTABLE;
}

/* ---- the cycle ------------------------------------------------------------ */

static void smooth(const spn__mg *mg, int l, const double *b, double *x, bool forward)
{
    const mg_level *L = &mg->lv[l];
    if (L->lines) spn__lines_sweep(L->lines, b, x, forward, mg->threads);
    else spn__bsr_gauss_seidel(&L->A, L->dinv, b, x, forward, L->r, mg->threads); /* r is free while smoothing */
}

/* x += Z C^-1 Z^T (b - A x) on level 0 (equilibrium_slide.c). */
static void slide_correct(const spn__mg *mg, const spn__eq *e, const double *b, double *x)
{
    spn__slide_correct(mg->slide, e, b, x, mg->lv[0].r);
}

static void vcycle(const spn__mg *mg, const spn__eq *e, int l, const double *b, double *x)
{
    const mg_level *L = &mg->lv[l], *C = &mg->lv[l + 1];
    if (l == mg->nlevels - 1 && mg->dense) {
        dense_solve(mg, b, x);
        return;
    }
    if (l == mg->nlevels - 1) { /* symmetric: as many sweeps back as forth */
        memset(x, 0, 3 * (size_t)L->A.rows * sizeof *x);
        for (int k = 0; k < COARSE_SWEEPS; k++) spn__bsr_gauss_seidel(&L->A, L->dinv, b, x, true, L->r, mg->threads);
        for (int k = 0; k < COARSE_SWEEPS; k++) spn__bsr_gauss_seidel(&L->A, L->dinv, b, x, false, L->r, mg->threads);
        return;
    }
    memset(x, 0, 3 * (size_t)L->A.rows * sizeof *x);
    smooth(mg, l, b, x, true);
    bool slide = l == 0 && e->hs && mg->slide_ok;
    if (slide) slide_correct(mg, e, b, x);
    if (l == 0 && e->hs) { /* the spring system's own product reads each spring's 6 numbers once, not 2 x 9,
                            * float32 on large webs (the implicit step's system has no spring blocks:
                            * implicit_mg.c) */
        spn__eq_matvec_mg(e, x, L->r);
        const uint32_t n3 = 3 * L->A.rows;
        for (uint32_t k = 0; k < n3; k++) L->r[k] = b[k] - L->r[k];
    } else {
        spn__bsr_residual(&L->A, b, x, L->r, mg->threads);
    }
    spn__bsr_apply(&L->R, L->r, C->b, false, mg->threads);
    vcycle(mg, e, l + 1, C->b, C->x);
    spn__bsr_apply(&L->P, C->x, x, true, mg->threads);
    if (slide) slide_correct(mg, e, b, x);
    smooth(mg, l, b, x, false);
}

void spn__mg_apply(const spn__mg *mg, const spn__eq *e, const double *r, double *z)
{
    if (mg->nlevels == 1) {
        for (uint32_t i = 0; i < e->n; i++) spn__sym_mul(mg->lv[0].dinv + 6 * (size_t)i, r + 3 * (size_t)i, z + 3 * (size_t)i);
        return;
    }
    vcycle(mg, e, 0, r, z);
}

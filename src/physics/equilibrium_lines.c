/* Thread-line smoother for the equilibrium multigrid's finest level.
 *
 * Why: a taut silk thread is about 1/prestrain (~50) times stiffer along
 * itself (EA/l) than across (T/l), and a rings-by-radials web has no
 * diagonals, so in its plane the displacement along a radial is coupled
 * strongly along the radial and weakly across, and the displacement along a
 * ring the other way round: two anisotropic problems whose strong directions
 * cross. A point smoother (block Jacobi or Gauss-Seidel) cannot smooth an
 * error that is smooth along the threads but rough across them, and a
 * coarsening that mixes both directions cannot represent it; CG then needs
 * hundreds of iterations (measured: docs/physics-equilibrium.md). Solving
 * exactly along every thread (line relaxation, the classical cure for
 * anisotropy) removes those errors in one sweep.
 *
 * Lines are found from the geometry of any web, not from the lattice: at
 * each particle the incident springs are paired greedily by straightness (a
 * thread runs through a junction nearly straight: cos < -COLLINEAR), and the
 * chains of paired springs are the lines (a ring closes on itself; it is cut
 * where it started). Each spring between free particles lies on exactly one
 * line; a particle lies on one line per thread through it; particles on no
 * line are relaxed as one-particle lines. A line never visits a particle
 * twice, and never passes through a junction (a particle with more than
 * JUNCTION springs, such as the hub): every line through it would share it.
 *
 * Lines are coloured (greedily) so that no two lines of a colour share or
 * couple a particle: the lines of one colour are then independent, and a
 * sweep over them gives the same bits in any order or on any number of
 * threads. A sweep runs over the colours in order (forward) or reverse order
 * (backward: the adjoint, so a V-cycle with one of each is symmetric). Each
 * line's particles get new values from T x_line = b - (A - T) x: T the
 * block-tridiagonal part of the matrix on the line (the 3x3 blocks of the
 * line's springs), solved by the block Thomas algorithm, factored once per
 * Newton step; A - T the couplings off the line (on a web, the crossing
 * thread's two springs), read with the current values. This is the same as
 * adding T^-1 times the residual to x, but reads two blocks a particle
 * instead of five (the 5k web: the sweeps 97M -> 67M instructions). Lines
 * of a colour go in groups of GROUP, a step along all of them at a time: a radial of a ring-major web strides through memory,
 * but neighbouring radials step through neighbouring memory together.
 *
 * Layout: the sweep reads its blocks in the order it uses them, copied per
 * line node when the line is factored (the couplings off the line with
 * their columns, and the line's own U blocks), not through indices into the
 * level-0 matrix: on the 1M web those indirect loads missed the cache and
 * were about 40% of the sweep's time (perf).
 *
 * Precision: the sweep reads float32 copies of the level-0 blocks (6 numbers
 * each: every block of a spring system is symmetric) and of the factors,
 * factored in float64 and rounded once; the sums and the vectors stay
 * float64. The smoother only preconditions (CG and its residuals are
 * float64), and a 1e-7 relative change of it does not change the iteration
 * counts (5k and 100k webs: 25 and 54 CG either way). It reads 40% of the
 * bytes: the 100k web's solve went from 4.2 to 3.3 s CPU. (Since the sweep
 * computes a line's new values rather than a correction, the rounding of the
 * factors touches the whole value; the counts stayed the same: 12 and 24.)*/
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define COLLINEAR 0.9    /* springs at a junction continue one line when cos(angle) < -this */
#define JUNCTION 8u      /* particles with more springs end every line through them */
#define GROUP 8u         /* lines of a colour stepped together */
#define PAR_MIN 4096u    /* particles in a colour below which it stays on one thread */

struct spn__lines {
    uint32_t count;      /* lines */
    uint32_t *start;     /* count + 1: into node */
    uint32_t *node;      /* particles of each line, in order */
    uint32_t *upos;      /* per line node k (not the last): the BSR entry (node[k], node[k+1]) */
    uint32_t *off_start; /* per line node k: its row's entries off the line's tridiagonal part are */
    uint32_t *off;       /* ... off[off_start[k] .. off_start[k + 1]) (BSR entries of level 0) */
    uint32_t *offcol;    /* per off entry: its column (the particle coupled) */
    /* float32 copies (see the file comment): the sweep's operands */
    float *offval;       /* 6 per off entry: its symmetric block, in line order */
    float *uval;         /* 6 per line node k (not the last): the block U_k = A(node[k], node[k+1]) */
    float *dinv;         /* 6 per line node: inverted pivots of the factorisation */
    float *cu;           /* 9 per line node (not the last): Dinv_k U_k by columns, for the back substitution */
    double *work;        /* 3 per line node */
    uint32_t colours, *colour_start; /* lines [colour_start[c], colour_start[c + 1]) have colour c */
};

void spn__lines_free(spn__lines *L)
{
    if (!L) return;
    free(L->start);
    free(L->node);
    free(L->upos);
    free(L->off_start);
    free(L->off);
    free(L->offcol);
    free(L->offval);
    free(L->uval);
    free(L->dinv);
    free(L->cu);
    free(L->work);
    free(L->colour_start);
    free(L);
}

void spn__lines_nodes(const spn__lines *L, uint32_t *count, const uint32_t **start, const uint32_t **node)
{
    *count = L->count;
    *start = L->start;
    *node = L->node;
}

typedef struct pair_cand {
    double c;
    uint32_t a, b;
} pair_cand;

static int by_cos(const void *x, const void *y)
{
    const pair_cand *p = x, *q = y;
    if (p->c != q->c) return p->c < q->c ? -1 : 1;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : (p->b > q->b);
}

static inline bool junction(const spn__eq *e, uint32_t i) { return e->adj_start[i + 1] - e->adj_start[i] > JUNCTION; }

/* A line may run from particle i along its adjacency entry j: both ends
 * free, neither a junction. */
static bool linkable(const spn__eq *e, uint32_t i, uint32_t j)
{
    int32_t o = e->adj_other[j];
    return o >= 0 && !junction(e, i) && !junction(e, (uint32_t)o);
}

/* partner[j] for each adjacency entry: the entry at the same particle its
 * thread continues through, or UINT32_MAX. */
static bool pair_springs(const spn__eq *e, uint32_t *partner)
{
    uint32_t nadj = e->adj_start[e->n];
    for (uint32_t j = 0; j < nadj; j++) partner[j] = UINT32_MAX;
    pair_cand cand[JUNCTION * JUNCTION / 2 + 1];
    double dir[3 * JUNCTION];
    for (uint32_t i = 0; i < e->n; i++) {
        uint32_t j0 = e->adj_start[i], deg = e->adj_start[i + 1] - j0, nc = 0;
        if (deg < 2 || junction(e, i)) continue;
        for (uint32_t a = 0; a < deg; a++) {
            bool ok = linkable(e, i, j0 + a);
            int32_t o = e->adj_other[j0 + a];
            double *d = dir + 3 * a, len = 0;
            for (int c = 0; c < 3; c++) {
                d[c] = ok ? e->x[3 * (size_t)o + c] - e->x[3 * (size_t)i + c] : 0;
                len += d[c] * d[c];
            }
            len = sqrt(len);
            for (int c = 0; c < 3; c++) d[c] = len > 0 ? d[c] / len : 0;
        }
        for (uint32_t a = 0; a < deg; a++)
            for (uint32_t b = a + 1; b < deg; b++) {
                const double *da = dir + 3 * a, *db = dir + 3 * b;
                double c = da[0] * db[0] + da[1] * db[1] + da[2] * db[2];
                if (c < -COLLINEAR) cand[nc++] = (pair_cand){c, a, b};
            }
        qsort(cand, nc, sizeof *cand, by_cos);
        for (uint32_t k = 0; k < nc; k++) {
            uint32_t a = j0 + cand[k].a, b = j0 + cand[k].b;
            if (partner[a] != UINT32_MAX || partner[b] != UINT32_MAX) continue;
            partner[a] = b;
            partner[b] = a;
        }
    }
    return true;
}

/* The BSR entry of (i, c) in row i (the merged block of every spring between them). */
static uint32_t find_entry(const spn__bsr *a, uint32_t i, uint32_t c)
{
    for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++)
        if (a->col[p] == c) return p;
    return UINT32_MAX;
}

typedef struct walker {
    const spn__eq *e;
    const uint32_t *partner, *end_entry; /* end_entry[2 s + end]: the adjacency entry of spring s at that end */
    uint8_t *used;                       /* per spring */
    uint32_t *seen;                      /* per particle: the last line that visited it, + 1 */
    spn__lines *L;
    uint32_t nodes;
} walker;

/* Follow the thread from particle u out along adjacency entry j; appends one line. */
static void walk(walker *w, uint32_t u, uint32_t j)
{
    const spn__eq *e = w->e;
    spn__lines *L = w->L;
    uint32_t id = L->count + 1;
    L->node[w->nodes++] = u;
    w->seen[u] = id;
    for (;;) {
        uint32_t s = e->adj[j] >> 1, v = (uint32_t)e->adj_other[j];
        if (w->used[s]) break;
        w->used[s] = 1; /* a spring closing a loop stays off every line (it is in the residual) */
        if (w->seen[v] == id) break;
        L->node[w->nodes++] = v;
        w->seen[v] = id;
        uint32_t jv = w->end_entry[2 * (size_t)s + !(e->adj[j] & 1u)];
        if (w->partner[jv] == UINT32_MAX) break;
        j = w->partner[jv];
    }
    L->start[++L->count] = w->nodes;
}

static bool find_lines(spn__lines *L, const spn__eq *e, const uint32_t *partner)
{
    uint32_t nadj = e->adj_start[e->n];
    walker w = {e, partner, NULL, NULL, NULL, L, 0};
    uint32_t *end_entry = malloc(2 * (size_t)(e->m ? e->m : 1) * sizeof *end_entry);
    w.used = calloc(e->m ? e->m : 1, 1);
    w.seen = calloc(e->n ? e->n : 1, sizeof *w.seen);
    if (!end_entry || !w.used || !w.seen) {
        free(end_entry), free(w.used), free(w.seen);
        return false;
    }
    for (uint32_t j = 0; j < nadj; j++) end_entry[2 * (size_t)(e->adj[j] >> 1) + (e->adj[j] & 1u)] = j;
    w.end_entry = end_entry;
    L->start[0] = 0;
    /* threads with an end first (started there), then the closed loops */
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t i = 0; i < e->n; i++)
            for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++)
                if (linkable(e, i, j) && !w.used[e->adj[j] >> 1] && (pass == 1 || partner[j] == UINT32_MAX))
                    walk(&w, i, j);
    for (uint32_t i = 0; i < e->n; i++) /* on no line: relaxed alone */
        if (!w.seen[i]) {
            L->node[w.nodes++] = i;
            L->start[++L->count] = w.nodes;
        }
    free(end_entry), free(w.used), free(w.seen);
    return true;
}

/* Greedy colours: a line takes the first colour that no line sharing or
 * coupled to one of its particles has. Then the lines are reordered by
 * colour (stable). */
static bool colour_lines(spn__lines *L, const spn__bsr *a)
{
    uint32_t n = a->rows, total = L->start[L->count];
    uint32_t *ns = calloc((size_t)n + 1, sizeof *ns), *nl = malloc((total ? total : 1) * sizeof *nl);
    uint32_t *colour = malloc((L->count ? L->count : 1) * sizeof *colour);
    uint32_t *stamp = malloc(((size_t)L->count + 1) * sizeof *stamp), *fill = calloc((n > L->count ? n : L->count) + 1, sizeof *fill);
    bool ok = ns && nl && colour && stamp && fill;
    if (ok) { /* particle -> the lines through it */
        for (uint32_t k = 0; k < total; k++) ns[L->node[k] + 1]++;
        for (uint32_t i = 0; i < n; i++) ns[i + 1] += ns[i];
        for (uint32_t l = 0; l < L->count; l++)
            for (uint32_t k = L->start[l]; k < L->start[l + 1]; k++) nl[ns[L->node[k]] + fill[L->node[k]]++] = l;
        for (uint32_t c = 0; c <= L->count; c++) stamp[c] = UINT32_MAX;
        L->colours = 0;
        for (uint32_t l = 0; l < L->count; l++) {
            for (uint32_t k = L->start[l]; k < L->start[l + 1]; k++)
                for (uint32_t p = a->start[L->node[k]]; p < a->start[L->node[k] + 1]; p++)
                    for (uint32_t q = ns[a->col[p]]; q < ns[a->col[p] + 1]; q++)
                        if (nl[q] < l) stamp[colour[nl[q]]] = l;
            uint32_t c = 0;
            while (stamp[c] == l) c++;
            colour[l] = c;
            if (c + 1 > L->colours) L->colours = c + 1;
        }
    }
    uint32_t *start = NULL, *node = NULL;
    if (ok) {
        L->colour_start = calloc((size_t)L->colours + 1, sizeof *L->colour_start);
        start = malloc(((size_t)L->count + 1) * sizeof *start);
        node = malloc((total ? total : 1) * sizeof *node);
        ok = L->colour_start && start && node;
    }
    if (ok) {
        for (uint32_t l = 0; l < L->count; l++) L->colour_start[colour[l] + 1]++;
        for (uint32_t c = 0; c < L->colours; c++) L->colour_start[c + 1] += L->colour_start[c];
        memset(fill, 0, ((n > L->count ? n : L->count) + 1) * sizeof *fill);
        uint32_t *order = nl; /* reuse: new position -> old line */
        for (uint32_t l = 0; l < L->count; l++) {
            uint32_t c = colour[l];
            order[L->colour_start[c] + fill[c]++] = l;
        }
        start[0] = 0;
        for (uint32_t k = 0; k < L->count; k++) {
            uint32_t l = order[k], len = L->start[l + 1] - L->start[l];
            memcpy(node + start[k], L->node + L->start[l], len * sizeof *node);
            start[k + 1] = start[k] + len;
        }
        free(L->start), free(L->node);
        L->start = start, L->node = node;
        start = node = NULL;
    }
    free(start), free(node), free(ns), free(nl), free(colour), free(stamp), free(fill);
    return ok;
}

/* Per line node, the entries of its row outside the line's block
 * tridiagonal part T (not the diagonal, not the previous or next node): the
 * sweep solves T x_line = b - (A - T) x over those alone. */
static bool off_entries(spn__lines *L, const spn__bsr *a0)
{
    uint32_t total = L->start[L->count];
    L->off_start = malloc(((size_t)total + 1) * sizeof *L->off_start);
    if (!L->off_start) return false;
    for (int pass = 0; pass < 2; pass++) {
        uint32_t cnt = 0;
        for (uint32_t l = 0; l < L->count; l++)
            for (uint32_t k = L->start[l]; k < L->start[l + 1]; k++) {
                uint32_t i = L->node[k], prev = k > L->start[l] ? L->node[k - 1] : i;
                uint32_t next = k + 1 < L->start[l + 1] ? L->node[k + 1] : i;
                if (pass == 0) L->off_start[k] = cnt;
                for (uint32_t p = a0->start[i]; p < a0->start[i + 1]; p++) {
                    uint32_t c = a0->col[p];
                    if (c == i || c == prev || c == next) continue;
                    if (pass == 1) L->off[cnt] = p, L->offcol[cnt] = c;
                    cnt++;
                }
            }
        if (pass == 0) {
            L->off_start[total] = cnt;
            L->off = malloc((cnt ? cnt : 1) * sizeof *L->off);
            L->offcol = malloc((cnt ? cnt : 1) * sizeof *L->offcol);
            L->offval = malloc(6 * (size_t)(cnt ? cnt : 1) * sizeof *L->offval);
            if (!L->off || !L->offcol || !L->offval) return false;
        }
    }
    return true;
}

spn__lines *spn__lines_build(const spn__eq *e, const spn__bsr *a0)
{
    spn__lines *L = calloc(1, sizeof *L);
    uint32_t nadj = e->adj_start[e->n];
    /* every line has one more particle than springs: at most m + n particles on at most m + n lines */
    size_t cap = (size_t)e->m + e->n + 1;
    uint32_t *partner = malloc((nadj ? nadj : 1) * sizeof *partner);
    if (!L || !partner) goto fail;
    L->start = malloc((cap + 1) * sizeof *L->start);
    L->node = malloc(cap * sizeof *L->node);
    if (!L->start || !L->node || !pair_springs(e, partner) || !find_lines(L, e, partner)) goto fail;
    free(partner);
    partner = NULL;
    if (!colour_lines(L, a0)) goto fail;
    uint32_t total = L->start[L->count];
    L->upos = malloc((total ? total : 1) * sizeof *L->upos);
    L->uval = malloc(6 * (size_t)(total ? total : 1) * sizeof *L->uval);
    L->dinv = malloc(6 * (size_t)(total ? total : 1) * sizeof *L->dinv);
    L->cu = malloc(9 * (size_t)(total ? total : 1) * sizeof *L->cu);
    L->work = malloc(3 * (size_t)(total ? total : 1) * sizeof *L->work);
    if (!L->upos || !L->uval || !L->dinv || !L->cu || !L->work) goto fail;
    for (uint32_t l = 0; l < L->count; l++)
        for (uint32_t k = L->start[l]; k + 1 < L->start[l + 1]; k++) L->upos[k] = find_entry(a0, L->node[k], L->node[k + 1]);
    if (!off_entries(L, a0)) goto fail;
    return L;
fail:
    free(partner);
    spn__lines_free(L);
    return NULL;
}


/* The pivot after step k - 1: out = D - U^T M U with M = Dinv_{k-1} (6),
 * U = U_{k-1} and D = D_k (9 each); w = M U, the factor the back
 * substitution needs. Level-0 blocks are symmetric (sums of H_s or -H_s), so
 * U^T M U = U w is too and only its six distinct entries are formed. */
static void schur(const double *d, const double *m, const double *u, double *w, double *out)
{
    double mm[9] = {m[0], m[3], m[4], m[3], m[1], m[5], m[4], m[5], m[2]};
    memset(w, 0, 9 * sizeof *w);
    spn__blk_mul_add(mm, u, w);
    static const int R[6] = {0, 1, 2, 0, 0, 1}, C[6] = {0, 1, 2, 1, 2, 2};
    for (int q = 0; q < 6; q++) {
        const double *ur = u + 3 * R[q];
        out[q] = d[3 * R[q] + C[q]] - (ur[0] * w[C[q]] + ur[1] * w[3 + C[q]] + ur[2] * w[6 + C[q]]);
    }
}

static void to_float6(const double *v, float *f)
{
    f[0] = (float)v[0], f[1] = (float)v[4], f[2] = (float)v[8];
    f[3] = (float)v[1], f[4] = (float)v[2], f[5] = (float)v[5];
}

bool spn__lines_factor(spn__lines *L, const spn__bsr *a0)
{
    /* float copies of the blocks the sweep reads, in the order it reads them
     * (level-0 blocks are symmetric: sums of -H_s or of H_s) */
    const uint32_t noff = L->off_start[L->start[L->count]];
    for (uint32_t q = 0; q < noff; q++) to_float6(a0->val + 9 * (size_t)L->off[q], L->offval + 6 * (size_t)q);
    for (uint32_t l = 0; l < L->count; l++)
        for (uint32_t k = L->start[l]; k + 1 < L->start[l + 1]; k++)
            to_float6(a0->val + 9 * (size_t)L->upos[k], L->uval + 6 * (size_t)k);
    for (uint32_t l = 0; l < L->count; l++) {
        double prev[6] = {0, 0, 0, 0, 0, 0}; /* the last pivot's inverse, in float64 */
        for (uint32_t k = L->start[l]; k < L->start[l + 1]; k++) {
            const double *d = a0->val + 9 * (size_t)a0->start[L->node[k]];
            double piv[6], inv[6], w[9];
            if (k == L->start[l]) { /* the plain diagonal */
                piv[0] = d[0], piv[1] = d[4], piv[2] = d[8], piv[3] = d[1], piv[4] = d[2], piv[5] = d[5];
            } else {
                schur(d, prev, a0->val + 9 * (size_t)L->upos[k - 1], w, piv);
                for (int q = 0; q < 9; q++) /* Dinv_{k-1} U_{k-1}, by columns */
                    L->cu[9 * (size_t)(k - 1) + 3 * (q % 3) + q / 3] = (float)w[q];
            }
            if (!spn__sym_inverse(piv, inv)) return false;
            for (int q = 0; q < 6; q++) L->dinv[6 * (size_t)k + q] = (float)inv[q];
            memcpy(prev, inv, sizeof prev);
        }
    }
    return true;
}

/* Symmetric float block times a double vector, in double. */
static inline void fsym_mul(const float *h, double v0, double v1, double v2, double *o)
{
    o[0] = (double)h[0] * v0 + (double)h[3] * v1 + (double)h[4] * v2;
    o[1] = (double)h[3] * v0 + (double)h[1] * v1 + (double)h[5] * v2;
    o[2] = (double)h[4] * v0 + (double)h[5] * v1 + (double)h[2] * v2;
}

/* Step t of line l forward: the right-hand side of its particle t, b minus
 * the couplings off the line (with the current x), minus the eliminated part
 * of step t - 1, times the inverted pivot, into g_t. */
static inline void forward_step(const spn__lines *L, uint32_t l, uint32_t t, const double *b, const double *x)
{
    uint32_t k = L->start[l] + t, i = L->node[k];
    double r0 = b[3 * i], r1 = b[3 * i + 1], r2 = b[3 * i + 2];
    for (uint32_t q = L->off_start[k]; q < L->off_start[k + 1]; q++) {
        const float *m = L->offval + 6 * (size_t)q;
        const double *v = x + 3 * (size_t)L->offcol[q];
        double o[3];
        fsym_mul(m, v[0], v[1], v[2], o);
        r0 -= o[0], r1 -= o[1], r2 -= o[2];
    }
    if (t > 0) { /* r -= U_{t-1}^T g_{t-1}; U is symmetric */
        const double *gp = L->work + 3 * (size_t)(k - 1);
        double o[3];
        fsym_mul(L->uval + 6 * (size_t)(k - 1), gp[0], gp[1], gp[2], o);
        r0 -= o[0], r1 -= o[1], r2 -= o[2];
    }
    fsym_mul(L->dinv + 6 * (size_t)k, r0, r1, r2, L->work + 3 * (size_t)k);
}

/* Step t of line l backward: x_t = g_t - (Dinv_t U_t) x_{t+1}. */
static inline void backward_step(const spn__lines *L, uint32_t l, uint32_t t, double *x)
{
    uint32_t k = L->start[l] + t;
    double *g = L->work + 3 * (size_t)k;
    if (k + 1 < L->start[l + 1]) {
        const float *m = L->cu + 9 * (size_t)k; /* by columns */
        const double *n = g + 3;
        g[0] -= (double)m[0] * n[0] + (double)m[3] * n[1] + (double)m[6] * n[2];
        g[1] -= (double)m[1] * n[0] + (double)m[4] * n[1] + (double)m[7] * n[2];
        g[2] -= (double)m[2] * n[0] + (double)m[5] * n[1] + (double)m[8] * n[2];
    }
    double *xi = x + 3 * (size_t)L->node[k];
    xi[0] = g[0], xi[1] = g[1], xi[2] = g[2];
}

#if SPN__AVX
/* fsym_mul on 256-bit vectors: o = (c0 v0 + c1 v1) + c2 v2 by lanes, c_j
 * the block's columns (three lanes and a spare), which is fsym_mul's order
 * in each lane: the same bits. The six floats are read as h[0..3] and
 * h[2..5] and the columns shuffled out of them. */
__attribute__((target("avx"))) static inline __m256d fsym_avx(const float *h, __m256d v0, __m256d v1, __m256d v2)
{
    __m128 a = _mm_loadu_ps(h), b = _mm_loadu_ps(h + 2);
    __m256d c0 = _mm256_cvtps_pd(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 2, 3, 0))); /* h0 h3 h4 */
    __m256d c1 = _mm256_cvtps_pd(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 3, 1, 3))); /* h3 h1 h5 */
    __m256d c2 = _mm256_cvtps_pd(_mm_shuffle_ps(b, a, _MM_SHUFFLE(0, 2, 3, 2))); /* h4 h5 h2 */
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(c0, v0), _mm256_mul_pd(c1, v1)), _mm256_mul_pd(c2, v2));
}

/* forward_step with fsym_avx for the couplings and U; the pivot's inverse
 * stays scalar (the right-hand side's lanes would need moving across). */
__attribute__((target("avx"))) static inline void forward_step_avx(const spn__lines *L, uint32_t l, uint32_t t,
                                                                    const double *b, const double *x)
{
    uint32_t k = L->start[l] + t, i = L->node[k];
    __m256d r = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(b + 3 * (size_t)i)),
                                     _mm_load_sd(b + 3 * (size_t)i + 2), 1);
    for (uint32_t q = L->off_start[k]; q < L->off_start[k + 1]; q++) {
        const double *v = x + 3 * (size_t)L->offcol[q];
        r = _mm256_sub_pd(r, fsym_avx(L->offval + 6 * (size_t)q, _mm256_broadcast_sd(v), _mm256_broadcast_sd(v + 1),
                                      _mm256_broadcast_sd(v + 2)));
    }
    if (t > 0) { /* r -= U_{t-1}^T g_{t-1}; U is symmetric */
        const double *gp = L->work + 3 * (size_t)(k - 1);
        r = _mm256_sub_pd(r, fsym_avx(L->uval + 6 * (size_t)(k - 1), _mm256_broadcast_sd(gp),
                                      _mm256_broadcast_sd(gp + 1), _mm256_broadcast_sd(gp + 2)));
    }
    double rr[4];
    _mm256_storeu_pd(rr, r);
    fsym_mul(L->dinv + 6 * (size_t)k, rr[0], rr[1], rr[2], L->work + 3 * (size_t)k);
}

/* backward_step on 256-bit vectors: g -= (c0 n0 + c1 n1) + c2 n2 by lanes,
 * c_j the columns of Dinv U (stored by columns): backward_step's order. */
__attribute__((target("avx"))) static inline void backward_step_avx(const spn__lines *L, uint32_t l, uint32_t t,
                                                                     double *x)
{
    uint32_t k = L->start[l] + t;
    double *g = L->work + 3 * (size_t)k, *xi = x + 3 * (size_t)L->node[k];
    if (k + 1 < L->start[l + 1]) {
        const float *m = L->cu + 9 * (size_t)k;
        const double *n = g + 3;
        __m128 c = _mm_loadu_ps(m + 5);
        __m256d c0 = _mm256_cvtps_pd(_mm_loadu_ps(m)), c1 = _mm256_cvtps_pd(_mm_loadu_ps(m + 3));
        __m256d c2 = _mm256_cvtps_pd(_mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 2, 1)));
        __m256d o = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(c0, _mm256_broadcast_sd(n)),
                                                _mm256_mul_pd(c1, _mm256_broadcast_sd(n + 1))),
                                  _mm256_mul_pd(c2, _mm256_broadcast_sd(n + 2)));
        __m256d gv = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(g)), _mm_load_sd(g + 2), 1);
        gv = _mm256_sub_pd(gv, o);
        _mm_storeu_pd(g, _mm256_castpd256_pd128(gv));
        _mm_store_sd(g + 2, _mm256_extractf128_pd(gv, 1));
    }
    xi[0] = g[0], xi[1] = g[1], xi[2] = g[2];
}

/* solve_group with forward_step_avx and backward_step_avx. */
__attribute__((target("avx"))) static void solve_group_avx(const spn__lines *L, uint32_t l0, uint32_t l1,
                                                           const double *b, double *x)
{
    uint32_t longest = 0;
    for (uint32_t l = l0; l < l1; l++)
        if (L->start[l + 1] - L->start[l] > longest) longest = L->start[l + 1] - L->start[l];
    for (uint32_t t = 0; t < longest; t++)
        for (uint32_t l = l0; l < l1; l++)
            if (t < L->start[l + 1] - L->start[l]) forward_step_avx(L, l, t, b, x);
    for (uint32_t t = longest; t-- > 0;)
        for (uint32_t l = l0; l < l1; l++)
            if (t < L->start[l + 1] - L->start[l]) backward_step_avx(L, l, t, x);
}
#endif

/* Lines [l0, l1) of one colour, stepped together. */
static void solve_group(const spn__lines *L, uint32_t l0, uint32_t l1, const double *b, double *x)
{
    uint32_t longest = 0;
    for (uint32_t l = l0; l < l1; l++)
        if (L->start[l + 1] - L->start[l] > longest) longest = L->start[l + 1] - L->start[l];
    for (uint32_t t = 0; t < longest; t++)
        for (uint32_t l = l0; l < l1; l++)
            if (t < L->start[l + 1] - L->start[l]) forward_step(L, l, t, b, x);
    for (uint32_t t = longest; t-- > 0;)
        for (uint32_t l = l0; l < l1; l++)
            if (t < L->start[l + 1] - L->start[l]) backward_step(L, l, t, x);
}

void spn__lines_sweep(const spn__lines *L, const double *b, double *x, bool forward, int threads)
{
    const bool avx = spn__have_avx();
    (void)avx;
    for (uint32_t k = 0; k < L->colours; k++) {
        uint32_t c = forward ? k : L->colours - 1 - k;
        uint32_t l0 = L->colour_start[c], l1 = L->colour_start[c + 1], groups = (l1 - l0 + GROUP - 1) / GROUP;
        int team = L->start[l1] - L->start[l0] < PAR_MIN ? 1 : threads;
        (void)team;
#pragma omp parallel for schedule(static) num_threads(team)
        for (uint32_t g = 0; g < groups; g++) {
            uint32_t g0 = l0 + g * GROUP, g1 = l0 + (g + 1) * GROUP < l1 ? l0 + (g + 1) * GROUP : l1;
#if SPN__AVX
            if (avx) {
                solve_group_avx(L, g0, g1, b, x);
                continue;
            }
#endif
            solve_group(L, g0, g1, b, x);
        }
    }
}

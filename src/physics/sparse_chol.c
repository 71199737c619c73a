/* Sparse Cholesky factorisation for the implicit step's preconditioner
 * (sparse_chol.h).
 *
 * Ordering: minimum degree on the particle graph (order() below). A web is
 * made of threads, long chains of particles of two neighbours that cost no
 * fill when eliminated first, crossing at particles of four; minimum degree
 * takes the chains first and the crossings as they become cheap. On the
 * Araneus web of `spinneret build --species araneus` (1,918 free particles)
 * L holds 126k numbers, as many as CHOLMOD's approximate minimum degree
 * gives (124k); a nested dissection on the positions, tried first, gave
 * 288k, since its separators cut every thread they cross.
 *
 * Factorisation: the up-looking method (T. A. Davis, "Direct Methods for
 * Sparse Linear Systems", SIAM 2006, chapter 4): row k of L is the solution
 * of a triangular system whose pattern is the reach of row k of A in the
 * elimination tree (Liu's algorithm for the tree). The matrix has 3
 * unknowns a particle, each particle's three consecutive, and a particle's
 * diagonal block enters A whole, so its three columns of L share their rows
 * below its 3x3 block: the tree, the reaches, the pattern of L (counted once
 * at analysis), the factorisation and the solves all go a particle at a
 * time, on 3x3 blocks: one index for nine multiply-adds. A column at a time, the
 * factorisation took 3.6 ms on the Araneus web, 92 and 218 ms on the Zilla
 * webs of 14k and 50k particles; a particle at a time 2.2, 30 and 82.
 *
 * L is stored the same way, a particle's columns together: below its
 * diagonal block, each block of three rows is nine numbers in a row and
 * one row-particle's number. Stored by scalar column, with an index a
 * number (the three columns of a block in three places), the solve took
 * 1.19 and 4.99 ms on the Zilla webs, the factorisation 19.7 and 49.1;
 * stored by block 0.82 and 3.27, 17.7 and 42.3 (Zen 5, same bits). Blocks
 * of float32 numbers made neither faster and moved the solve's result by up
 * to 2.5 times its size on the larger web: the matrix is too ill-conditioned
 * for a factor rounded to 7 digits. The diagonal of each diagonal block is
 * kept inverted: the solves' divisions lay on the chain from one particle
 * to the next, and multiplications took 7-17% off the solve's time.
 * Renumbering the particles in a postorder of the elimination tree, for
 * locality, took 7-12% off the factorisation and added 18-26% to the
 * solve (a particle's parent then comes next, and waits for its stores).
 * Threads were tried: the elimination tree cut into 16 bins of subtrees,
 * whose rows the factorisation forms side by side and whose unknowns the
 * solves find side by side, the tree's top on one thread. The top holds
 * half the factorisation's work on the Zilla webs (their trees have no
 * large dense part: 98 of the 1 m web's 50k particles), and grouping each
 * bin's particles together slowed the solve as the postorder did: a step
 * of the 1 m web took 81 ms on one thread and 71 on two, against 70 and 71
 * in one piece. Not kept.
 *
 * Vectors: the factorisation and the solves take a 3x3 block's row or
 * column as one vector of four numbers (the fourth unused), with each
 * lane's operations those of the scalar code in its order, so every
 * instruction set's version (core/kernel.h) gives the scalar bits. The
 * factorisation went from 0.91, 16.2 and 42.4 ms to 0.49, 8.6 and 24.3 on
 * the Araneus and the two Zilla webs; the solve about 10% faster (Zen 5).
 * The backward solve then sums each block's product before taking it from
 * the running sums (other bits, by round-off): 3-11% off the solve.
 * Since the fifty-fifth session a block is stored by column, so that the
 * forward solve reads its columns as they lie (it had built each from three
 * numbers nine apart, 30 instructions a block against 19 now), and the
 * backward solve gathers each column's products with its row-particle's
 * unknowns lane by lane over the blocks, summing the lanes after them
 * (other bits again). The Zilla webs' 2 ms steps in wind 12.8-13.1 ->
 * 8.9-9.5 ms (0.5 m) and 64-70 -> 47-48 ms (1 m), the Araneus web's
 * 0.65 -> 0.60-0.62 (Zen 5, one thread).
 *
 * Every factorisation walks the same reaches in the same order, so its
 * bits depend on the values only. */
#include "sparse_chol.h"

#include "core/kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct spn__chol {
    uint32_t n;     /* particles */
    uint32_t N;     /* unknowns, 3 n */
    uint32_t *perm; /* n: new particle -> old */
    /* A's upper triangle in the new order, by scalar column (rows ascending) */
    size_t *ap;       /* N + 1 */
    uint32_t *ai;     /* ap[N] */
    double *ax;       /* ap[N] */
    size_t *dst_diag; /* 6 n: the entry of A each diagonal-block number adds into */
    size_t *dst_offd; /* 9 per neighbour entry: each number of the block's (a, b), or SIZE_MAX */
    uint32_t nadj;
    /* the particles' elimination tree, and L a particle's three columns at a
     * time: the Cholesky factor of its diagonal block (6 numbers: 1/00, 10,
     * 20, 1/11, 21, 1/22: its diagonal inverted, as the solves and the
     * factorisation multiply by it), then one 3x3 block (column-major: the
     * block's column a, this particle's unknown a, as numbers 3a .. 3a + 2,
     * row r the row-particle's unknown r) and the row-particle's number for
     * each particle below it */
    int32_t *bparent; /* n */
    double *ld;       /* 6 n */
    size_t *bp;       /* n + 1: particle k's blocks are bp[k] .. bp[k + 1) */
    double *lb;       /* 9 bp[n] */
    uint32_t *lj;     /* bp[n] */
    /* scratch: a reach's stack, marks and path (n each), the solve's vector
     * (N), a 3x3 block of the row being formed for each particle (12 n:
     * three rows of four, the fourth zero; the earlier particle's rows,
     * this one's columns) and the
     * row-particles each particle's columns hold so far (n) */
    uint32_t *stack, *mark, *next;
    double *x, *xb;
    uint32_t *filled;
};

static int cmp_u32(const void *pa, const void *pb)
{
    const uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
    return (a > b) - (a < b);
}

/* ---- ordering --------------------------------------------------------------- */

/* Minimum degree on the particle graph: the particle with the fewest
 * neighbours in the elimination graph goes next, and its neighbours become
 * one another's (the fill its elimination makes). Each particle's
 * neighbours are kept as a sorted list, merged on elimination; particles of
 * equal degree sit in a bucket, a list in which the latest arrival comes
 * first, so the order is a function of the graph alone. */
typedef struct md_graph {
    uint32_t n;
    uint32_t **nb; /* each particle's neighbours, sorted */
    uint32_t *len, *cap;
    uint32_t *head; /* n: the first particle of each degree, UINT32_MAX none */
    uint32_t *next, *prev;
    uint32_t *merged; /* scratch for a merge */
} md_graph;

static void md_link(md_graph *g, uint32_t i)
{
    const uint32_t d = g->len[i];
    g->prev[i] = UINT32_MAX, g->next[i] = g->head[d];
    if (g->head[d] != UINT32_MAX) g->prev[g->head[d]] = i;
    g->head[d] = i;
}

static void md_unlink(md_graph *g, uint32_t i)
{
    if (g->prev[i] != UINT32_MAX)
        g->next[g->prev[i]] = g->next[i];
    else
        g->head[g->len[i]] = g->next[i];
    if (g->next[i] != UINT32_MAX) g->prev[g->next[i]] = g->prev[i];
}

/* u's neighbours become (theirs and v's) less u and v; false when out of memory. */
static bool md_merge(md_graph *g, uint32_t u, uint32_t v)
{
    const uint32_t *a = g->nb[u], *b = g->nb[v], la = g->len[u], lb = g->len[v];
    uint32_t i = 0, j = 0, k = 0, *m = g->merged;
    while (i < la || j < lb) {
        uint32_t x;
        if (j >= lb || (i < la && a[i] < b[j]))
            x = a[i++];
        else if (i >= la || b[j] < a[i])
            x = b[j++];
        else
            x = a[i++], j++;
        if (x != u && x != v) m[k++] = x;
    }
    if (k > g->cap[u]) {
        uint32_t c = g->cap[u] * 2 > k ? g->cap[u] * 2 : k;
        uint32_t *p = realloc(g->nb[u], c * sizeof *p);
        if (!p) return false;
        g->nb[u] = p, g->cap[u] = c;
    }
    memcpy(g->nb[u], m, k * sizeof *m);
    g->len[u] = k;
    return true;
}

static bool order(spn__chol *c, const uint32_t *start, const int32_t *adj)
{
    const uint32_t n = c->n;
    md_graph g = {n,
                  calloc(n, sizeof(uint32_t *)),
                  calloc(n, sizeof(uint32_t)),
                  calloc(n, sizeof(uint32_t)),
                  malloc((size_t)(n + 1) * sizeof(uint32_t)),
                  malloc(n * sizeof(uint32_t)),
                  malloc(n * sizeof(uint32_t)),
                  malloc(n * sizeof(uint32_t))};
    bool ok = g.nb && g.len && g.cap && g.head && g.next && g.prev && g.merged;
    for (uint32_t i = 0; ok && i < n; i++) {
        const uint32_t deg = start[i + 1] - start[i];
        ok = (g.nb[i] = malloc((deg ? deg : 1) * sizeof(uint32_t))) != NULL;
        if (!ok) break;
        g.cap[i] = deg ? deg : 1;
        uint32_t k = 0;
        for (uint32_t j = start[i]; j < start[i + 1]; j++)
            if (adj[j] >= 0 && (uint32_t)adj[j] != i) g.nb[i][k++] = (uint32_t)adj[j];
        qsort(g.nb[i], k, sizeof(uint32_t), cmp_u32);
        uint32_t u = 0;
        for (uint32_t t = 0; t < k; t++)
            if (u == 0 || g.nb[i][u - 1] != g.nb[i][t]) g.nb[i][u++] = g.nb[i][t];
        g.len[i] = u;
    }
    if (ok) {
        for (uint32_t d = 0; d <= n; d++)
            g.head[d] = UINT32_MAX;
        for (uint32_t i = n; i-- > 0;)
            md_link(&g, i);
    }
    uint32_t low = 0;
    for (uint32_t k = 0; ok && k < n; k++) {
        while (g.head[low] == UINT32_MAX)
            low++;
        const uint32_t v = g.head[low];
        md_unlink(&g, v);
        c->perm[k] = v;
        for (uint32_t t = 0; ok && t < g.len[v]; t++) {
            const uint32_t u = g.nb[v][t];
            md_unlink(&g, u);
            ok = md_merge(&g, u, v);
            md_link(&g, u);
            if (g.len[u] < low) low = g.len[u];
        }
        g.len[v] = 0;
    }
    for (uint32_t i = 0; g.nb && i < n; i++)
        free(g.nb[i]);
    free(g.nb), free(g.len), free(g.cap), free(g.head), free(g.next), free(g.prev), free(g.merged);
    return ok;
}

/* ---- pattern ------------------------------------------------------------------- */

/* The position of v in the sorted list l[0 .. len). */
static uint32_t find(const uint32_t *l, uint32_t len, uint32_t v)
{
    uint32_t a = 0, b = len;
    while (b - a > 1) {
        const uint32_t m = a + (b - a) / 2;
        if (l[m] <= v)
            a = m;
        else
            b = m;
    }
    return a;
}

/* A's upper pattern in the new order and where each input number adds. */
static bool upper_pattern(spn__chol *c, const uint32_t *start, const int32_t *adj)
{
    const uint32_t n = c->n, N = c->N;
    uint32_t *iperm = malloc((n ? n : 1) * sizeof *iperm);
    uint32_t *bstart = calloc((size_t)n + 1, sizeof *bstart); /* per new particle: its earlier neighbours */
    uint32_t *bnbr = malloc((c->nadj ? c->nadj : 1) * sizeof *bnbr);
    c->ap = malloc(((size_t)N + 1) * sizeof *c->ap);
    c->dst_diag = malloc(6 * (size_t)(n ? n : 1) * sizeof *c->dst_diag);
    c->dst_offd = malloc(9 * (size_t)(c->nadj ? c->nadj : 1) * sizeof *c->dst_offd);
    bool ok = iperm && bstart && bnbr && c->ap && c->dst_diag && c->dst_offd;
    if (ok) {
        for (uint32_t k = 0; k < n; k++)
            iperm[c->perm[k]] = k;
        /* each new particle k: its neighbours numbered before it, sorted, once each */
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t p = c->perm[k];
            uint32_t len = 0, *l = bnbr + bstart[k];
            for (uint32_t j = start[p]; j < start[p + 1]; j++)
                if (adj[j] >= 0 && iperm[adj[j]] < k) l[len++] = iperm[adj[j]];
            qsort(l, len, sizeof *l, cmp_u32);
            uint32_t u = 0;
            for (uint32_t t = 0; t < len; t++)
                if (u == 0 || l[u - 1] != l[t]) l[u++] = l[t];
            bstart[k + 1] = bstart[k] + u;
        }
        /* column 3k + b: rows 3q + a of each earlier neighbour q, then 3k + a, a <= b */
        c->ap[0] = 0;
        for (uint32_t k = 0; k < n; k++)
            for (uint32_t b = 0; b < 3; b++)
                c->ap[3 * k + b + 1] = c->ap[3 * k + b] + 3 * (size_t)(bstart[k + 1] - bstart[k]) + b + 1;
        c->ai = malloc((c->ap[N] ? c->ap[N] : 1) * sizeof *c->ai);
        c->ax = malloc((c->ap[N] ? c->ap[N] : 1) * sizeof *c->ax);
        ok = c->ai && c->ax;
    }
    for (uint32_t k = 0; ok && k < n; k++) {
        const uint32_t nb = bstart[k + 1] - bstart[k];
        for (uint32_t b = 0; b < 3; b++) {
            size_t e = c->ap[3 * k + b];
            for (uint32_t t = 0; t < nb; t++)
                for (uint32_t a = 0; a < 3; a++)
                    c->ai[e++] = 3 * bnbr[bstart[k] + t] + a;
            for (uint32_t a = 0; a <= b; a++)
                c->ai[e++] = 3 * k + a;
        }
        /* diagonal numbers xx, yy, zz, xy, xz, yz: row a <= column b */
        static const uint8_t ra[6] = {0, 1, 2, 0, 0, 1}, cb[6] = {0, 1, 2, 1, 2, 2};
        const uint32_t p = c->perm[k];
        for (int m = 0; m < 6; m++)
            c->dst_diag[6 * (size_t)p + m] = c->ap[3 * k + cb[m]] + 3 * (size_t)nb + ra[m];
        /* a neighbour entry of p numbered before it: all nine numbers, in its
         * block of rows in the columns of k (the pair's other entry adds nothing) */
        for (uint32_t j = start[p]; j < start[p + 1]; j++) {
            size_t *d = c->dst_offd + 9 * (size_t)j;
            if (adj[j] < 0 || iperm[adj[j]] >= k) {
                for (int m = 0; m < 9; m++)
                    d[m] = SIZE_MAX;
                continue;
            }
            const uint32_t t = find(bnbr + bstart[k], nb, iperm[adj[j]]);
            for (uint32_t a = 0; a < 3; a++)
                for (uint32_t b = 0; b < 3; b++)
                    d[3 * a + b] = c->ap[3 * k + b] + 3 * (size_t)t + a;
        }
    }
    free(iperm), free(bstart), free(bnbr);
    return ok;
}

/* Particle k's neighbours numbered before it: A's blocks above its
 * diagonal block, every third row of column 3k from ap[3k]; their count. */
static uint32_t earlier(const spn__chol *c, uint32_t k)
{
    return (uint32_t)((c->ap[3 * k + 1] - c->ap[3 * k] - 1) / 3);
}

/* Liu's elimination tree of the particles (ancestor: n of scratch). A
 * particle's diagonal block enters A whole, so this is the scalar tree with
 * each particle's three columns a chain, read a particle at a time. */
static void etree(spn__chol *c, uint32_t *ancestor)
{
    for (uint32_t k = 0; k < c->n; k++) {
        c->bparent[k] = -1, ancestor[k] = UINT32_MAX;
        for (uint32_t t = 0, nb = earlier(c, k); t < nb; t++) {
            uint32_t i = c->ai[c->ap[3 * k] + 3 * t] / 3;
            while (i != UINT32_MAX && i < k) {
                const uint32_t up = ancestor[i];
                ancestor[i] = k;
                if (up == UINT32_MAX) c->bparent[i] = (int32_t)k;
                i = up;
            }
        }
    }
}

/* The particles row k of L reaches in the particles' elimination tree
 * (the particles of the blocks of row k of L), children first, in
 * stack[top .. n); returns top. */
static uint32_t block_reach(const spn__chol *c, uint32_t k)
{
    uint32_t top = c->n, *s = c->stack, *path = c->next;
    const size_t p0 = c->ap[3 * k];
    c->mark[k] = k;
    for (uint32_t t = 0, nb = earlier(c, k); t < nb; t++) {
        uint32_t i = c->ai[p0 + 3 * t] / 3, len = 0;
        for (; c->mark[i] != k; i = (uint32_t)c->bparent[i])
            path[len++] = i, c->mark[i] = k;
        while (len > 0)
            s[--top] = path[--len];
    }
    return top;
}

spn__chol *spn__chol_analyze(uint32_t n, const uint32_t *start, const int32_t *adj_other, size_t max_entries)
{
    if (n == 0 || n > UINT32_MAX / 3 - 1) return NULL;
    spn__chol *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->n = n, c->N = 3 * n, c->nadj = start[n];
    c->perm = malloc(n * sizeof *c->perm);
    c->bparent = malloc(n * sizeof *c->bparent);
    c->stack = malloc(n * sizeof *c->stack);
    c->mark = malloc(n * sizeof *c->mark);
    c->next = malloc(n * sizeof *c->next);
    c->x = calloc(c->N, sizeof *c->x);
    c->xb = calloc(12 * (size_t)n, sizeof *c->xb);
    c->filled = calloc(n, sizeof *c->filled);
    c->ld = malloc(6 * (size_t)n * sizeof *c->ld);
    c->bp = malloc(((size_t)n + 1) * sizeof *c->bp);
    if (!c->perm || !c->bparent || !c->stack || !c->mark || !c->next || !c->x || !c->xb || !c->filled || !c->ld ||
        !c->bp || !order(c, start, adj_other) || !upper_pattern(c, start, adj_other)) {
        spn__chol_free(c);
        return NULL;
    }
    etree(c, c->mark);
    /* the row-particles of each particle's columns: each particle k reaches
     * adds one to those it reaches */
    for (uint32_t k = 0; k < n; k++)
        c->mark[k] = UINT32_MAX;
    for (uint32_t k = 0; k < n; k++)
        for (uint32_t t = block_reach(c, k); t < n; t++)
            c->filled[c->stack[t]]++;
    c->bp[0] = 0;
    for (uint32_t k = 0; k < n; k++)
        c->bp[k + 1] = c->bp[k] + c->filled[k];
    const size_t blocks = c->bp[n];
    if (spn__chol_entries(c) > max_entries || !(c->lj = malloc((blocks ? blocks : 1) * sizeof *c->lj)) ||
        !(c->lb = malloc((9 * blocks + 1) * sizeof *c->lb))) {
        spn__chol_free(c);
        return NULL;
    }
    c->lb[9 * blocks] = 0; /* read, in a lane not used, past the last block (solve_particles) */
    return c;
}

/* Three numbers on a vector of four (GCC vector extension; elementwise
 * IEEE operations, so each lane has the scalar code's bits). */
typedef double chol_v4 __attribute__((vector_size(4 * sizeof(double))));

/* The up-looking method a particle at a time: row k of L is three rows, and
 * each particle i it reaches gives a 3x3 block L(k, i), found from the
 * block X_i of the rows solved so far by the triangular block L(i, i), then
 * taken from the blocks X_j of the particles below i in i's columns; it
 * becomes i's next block. */
SPN__KERNEL static bool factor_rows(spn__chol *c)
{
    const uint32_t n = c->n;
    const double *ax = c->ax;
    double *xb = c->xb;
    for (uint32_t k = 0; k < n; k++) {
        const size_t q0 = c->ap[3 * k], q1 = c->ap[3 * k + 1], q2 = c->ap[3 * k + 2];
        const uint32_t nb = earlier(c, k);
        /* A's blocks above the diagonal into X, its diagonal block into D */
        for (uint32_t t = 0; t < nb; t++) {
            double *x = xb + 12 * (size_t)(c->ai[q0 + 3 * t] / 3);
            for (int a = 0; a < 3; a++)
                x[4 * a] = ax[q0 + 3 * t + a], x[4 * a + 1] = ax[q1 + 3 * t + a], x[4 * a + 2] = ax[q2 + 3 * t + a];
        }
        const size_t e = 3 * (size_t)nb;
        chol_v4 D0 = {ax[q0 + e], ax[q1 + e], ax[q2 + e], 0}, D1 = {0, ax[q1 + e + 1], ax[q2 + e + 1], 0},
                D2 = {0, 0, ax[q2 + e + 2], 0};
        for (uint32_t top = block_reach(c, k); top < n; top++) {
            const uint32_t i = c->stack[top];
            const double *li = c->ld + 6 * (size_t)i;
            double *x = xb + 12 * (size_t)i;
            /* Y = L(i, i)^-1 X_i, a row a vector: Y's rows are i's, its
             * columns k's; L(k, i) = Y^T */
            chol_v4 X0, X1, X2;
            memcpy(&X0, x, sizeof X0), memcpy(&X1, x + 4, sizeof X1), memcpy(&X2, x + 8, sizeof X2);
            const chol_v4 Y0 = X0 * li[0], Y1 = (X1 - li[1] * Y0) * li[3],
                          Y2 = ((X2 - li[2] * Y0) - li[4] * Y1) * li[5];
            memset(x, 0, 12 * sizeof *x);
            /* X_j -= L(j, i) Y for the row-particles j of i's columns so far */
            const uint32_t f = c->filled[i];
            const double *l = c->lb + 9 * c->bp[i];
            const uint32_t *rows = c->lj + c->bp[i];
            for (uint32_t t = 0; t < f; t++, l += 9) {
                double *xj = xb + 12 * (size_t)rows[t];
                for (int r = 0; r < 3; r++) {
                    chol_v4 v;
                    memcpy(&v, xj + 4 * r, sizeof v);
                    v -= (Y0 * l[r] + Y1 * l[3 + r]) + Y2 * l[6 + r];
                    memcpy(xj + 4 * r, &v, sizeof v);
                }
            }
            /* the diagonal block: D -= Y^T Y (row b of D in D_b) */
            D0 -= (Y0 * Y0[0] + Y1 * Y1[0]) + Y2 * Y2[0];
            D1 -= (Y0 * Y0[1] + Y1 * Y1[1]) + Y2 * Y2[1];
            D2 -= (Y0 * Y0[2] + Y1 * Y1[2]) + Y2 * Y2[2];
            /* L(k, i) into i's columns, as row-particle f */
            c->filled[i] = f + 1;
            double *to = c->lb + 9 * (c->bp[i] + f);
            for (int b = 0; b < 3; b++) /* (column a: Y_a) */
                to[b] = Y0[b], to[3 + b] = Y1[b], to[6 + b] = Y2[b];
            c->lj[c->bp[i] + f] = k;
        }
        /* L(k, k): the Cholesky factor of D */
        const double d00 = D0[0], d01 = D0[1], d02 = D0[2], d11 = D1[1], d12 = D1[2], d22 = D2[2];
        const double l00 = sqrt(d00), l10 = d01 / l00, l20 = d02 / l00;
        const double s11 = d11 - l10 * l10, l11 = sqrt(s11), l21 = (d12 - l20 * l10) / l11;
        const double s22 = (d22 - l20 * l20) - l21 * l21, l22 = sqrt(s22);
        double *lk = c->ld + 6 * (size_t)k;
        lk[0] = 1 / l00, lk[1] = l10, lk[2] = l20, lk[3] = 1 / l11, lk[4] = l21, lk[5] = 1 / l22;
        if (!(d00 > 0 && s11 > 0 && s22 > 0 && isfinite(l00 + l10 + l20 + l11 + l21 + l22))) return false;
    }
    return true;
}

bool spn__chol_factor(spn__chol *c, const double *diag, const double *offd)
{
    const uint32_t N = c->N, n = c->n;
    memset(c->ax, 0, c->ap[N] * sizeof *c->ax);
    for (size_t m = 0; m < 6 * (size_t)n; m++)
        c->ax[c->dst_diag[m]] += diag[m];
    static const uint8_t sym[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2}; /* (a, b) -> xx yy zz xy xz yz */
    for (size_t j = 0; j < c->nadj; j++)
        for (int m = 0; m < 9; m++)
            if (c->dst_offd[9 * j + m] != SIZE_MAX) c->ax[c->dst_offd[9 * j + m]] += offd[6 * j + sym[m]];
    for (uint32_t k = 0; k < n; k++)
        c->mark[k] = UINT32_MAX, c->filled[k] = 0;
    const bool ok = factor_rows(c);
    if (!ok) memset(c->xb, 0, 12 * (size_t)n * sizeof *c->xb); /* a failed row leaves values behind */
    return ok;
}

/* L y = b, then L^T x = y, in y, a particle at a time. Forward, the
 * particle's three unknowns come from its diagonal block, and each block
 * below takes its product with them from its row-particle's three;
 * backward, the three sums over the blocks below come first, then the
 * diagonal block. */
SPN__KERNEL static void solve_particles(const spn__chol *c, double *y)
{
    for (uint32_t k = 0; k < c->n; k++) {
        const double *lk = c->ld + 6 * (size_t)k;
        double *yk = y + 3 * (size_t)k;
        const double y0 = yk[0] * lk[0];
        const double y1 = (yk[1] - lk[1] * y0) * lk[3];
        const double y2 = ((yk[2] - lk[2] * y0) - lk[4] * y1) * lk[5];
        yk[0] = y0, yk[1] = y1, yk[2] = y2;
        const double *l = c->lb + 9 * c->bp[k];
        const uint32_t *rows = c->lj + c->bp[k];
        /* (lane 3 zero: a column's lane 3 is the number after it, and the
         * lane then holds no product that could come out subnormal, slow on
         * every processor; with it left unset the solve took twice as long) */
        const chol_v4 Y0 = {y0, y0, y0, 0}, Y1 = {y1, y1, y1, 0}, Y2 = {y2, y2, y2, 0};
        for (size_t t = 0, nb = c->bp[k + 1] - c->bp[k]; t < nb; t++, l += 9) {
            double *yr = y + 3 * (size_t)rows[t];
            /* the block's columns as they lie, lane r its row r (the last
             * block's column 2 reads lb's closing zero) */
            chol_v4 c0, c1, c2, v = {yr[0], yr[1], yr[2], 0};
            memcpy(&c0, l, sizeof c0), memcpy(&c1, l + 3, sizeof c1), memcpy(&c2, l + 6, sizeof c2);
            v = ((v - c0 * Y0) - c1 * Y1) - c2 * Y2;
            yr[0] = v[0], yr[1] = v[1], yr[2] = v[2];
        }
    }
    for (uint32_t k = c->n; k-- > 0;) {
        const double *lk = c->ld + 6 * (size_t)k;
        double *yk = y + 3 * (size_t)k;
        const double *l = c->lb + 9 * c->bp[k];
        const uint32_t *rows = c->lj + c->bp[k];
        /* lane r of p_a: the products of the blocks' column a, row r, with
         * their row-particles' unknown r, summed over the blocks; then p_a's
         * lanes 0-2 summed and taken from y_a. Each lane a chain of one
         * addition a block, as the sums were before by rows. */
        chol_v4 p0 = {0, 0, 0, 0}, p1 = p0, p2 = p0;
        for (size_t t = 0, nb = c->bp[k + 1] - c->bp[k]; t < nb; t++, l += 9) {
            const double *x = y + 3 * (size_t)rows[t];
            const chol_v4 xr = {x[0], x[1], x[2], 0};
            chol_v4 c0, c1, c2;
            memcpy(&c0, l, sizeof c0), memcpy(&c1, l + 3, sizeof c1), memcpy(&c2, l + 6, sizeof c2);
            p0 += c0 * xr, p1 += c1 * xr, p2 += c2 * xr;
        }
        const double s0 = yk[0] - ((p0[0] + p0[1]) + p0[2]), s1 = yk[1] - ((p1[0] + p1[1]) + p1[2]);
        const double s2 = yk[2] - ((p2[0] + p2[1]) + p2[2]);
        const double x2 = s2 * lk[5];
        const double x1 = (s1 - lk[4] * x2) * lk[3];
        yk[2] = x2, yk[1] = x1, yk[0] = ((s0 - lk[1] * x1) - lk[2] * x2) * lk[0];
    }
}

void spn__chol_solve_at(const spn__chol *c, const uint32_t *ids, const double *b, double *out)
{
    double *y = c->x;
    for (uint32_t k = 0; k < c->n; k++) {
        const size_t at = 3 * (size_t)(ids ? ids[c->perm[k]] : c->perm[k]);
        y[3 * k] = b[at], y[3 * k + 1] = b[at + 1], y[3 * k + 2] = b[at + 2];
    }
    solve_particles(c, y);
    for (uint32_t k = 0; k < c->n; k++) {
        const size_t at = 3 * (size_t)(ids ? ids[c->perm[k]] : c->perm[k]);
        out[at] = y[3 * k], out[at + 1] = y[3 * k + 1], out[at + 2] = y[3 * k + 2];
    }
}

void spn__chol_solve(const spn__chol *c, const double *b, double *out) { spn__chol_solve_at(c, NULL, b, out); }

size_t spn__chol_entries(const spn__chol *c) { return 6 * (size_t)c->n + 9 * c->bp[c->n]; }

void spn__chol_free(spn__chol *c)
{
    if (!c) return;
    free(c->perm), free(c->ap), free(c->ai), free(c->ax), free(c->dst_diag), free(c->dst_offd);
    free(c->bparent), free(c->ld), free(c->bp), free(c->lb), free(c->lj), free(c->stack), free(c->mark), free(c->next);
    free(c->x), free(c->xb), free(c->filled);
    free(c);
}

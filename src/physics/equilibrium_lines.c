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
 * instead of five (the 5k web: the sweeps 97M -> 67M instructions).
 *
 * Layout: the lines of a colour go in groups of W = 8, side by side: step t
 * of the group's eight lines is one record of the sweep's arrays, each field
 * eight values long, one per line (a lane). The sweep then does each 3x3
 * product on all eight lines at once as plain loops over the lanes, which
 * the compiler turns into vector instructions, and reads its blocks in the
 * order it uses them, as contiguous streams. A lane past its line's end is
 * padded with zero blocks, which change nothing (a zero pivot inverse, a
 * zero coupling). Each lane's arithmetic is the order the first, line by
 * line, sweep had, so the bits did not change; the 5k web's solve went from
 * 23.8 to 18.6 ms, the 100k web's from 1.54 to 1.22 s and the 1M web's from
 * 38.3 to 33.2 s (one thread, CPU time). Before, a line's blocks were
 * stored line after line and the group stepped along eight separate
 * streams; about 190 instructions a line node, mostly moving single values
 * in and out of vector registers. (Earlier still, the blocks were read
 * through indices into the level-0 matrix: on the 1M web those indirect
 * loads missed the cache and were about 40% of the sweep's time.)
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
#include "core/big_alloc.h"
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define COLLINEAR 0.9    /* springs at a junction continue one line when cos(angle) < -this */
#define JUNCTION 8u      /* particles with more springs end every line through them */
#define W 8u             /* lines of a colour stepped together, side by side */
#define NONE UINT32_MAX
#define PAR_MIN 4096u    /* particles in a colour below which it stays on one thread */
#define FACTOR_PAR_MIN 32768u /* line nodes below which the factorisation stays on one thread */
#define PREFETCH_MIN 262144u  /* particles from which the sweep prefetches (solve_group) */
#define AHEAD 4u              /* steps ahead it prefetches */

struct spn__lines {
    uint32_t count;      /* lines */
    uint32_t *start;     /* count + 1: into node */
    uint32_t *node;      /* particles of each line, in order */
    uint32_t colours, *colour_start; /* lines [colour_start[c], colour_start[c + 1]) have colour c */
    /* The sweep's layout (see the file comment): the lines of a colour in
     * groups of W side by side, lane q of group g being line
     * colour_start[c] + W (g - colour_group[c]) + q; a group's step t is one
     * step s of the arrays below, W entries each, a lane past its line's
     * end padded (NONE, zero blocks). */
    uint32_t groups, *colour_group; /* colours + 1: groups [colour_group[c], colour_group[c + 1]) */
    uint32_t steps, *group_step;    /* groups + 1: steps [group_step[g], group_step[g + 1]) */
    bool prefetch;                  /* a web too big for the caches: solve_group prefetches */
    bool merged;                    /* some pair of particles is joined by several springs */
    uint32_t *snode;                /* W per step: the lane's particle, or NONE */
    uint32_t *supos;                /* W per step: the adjacency entry (particle, next particle), or NONE */
    uint32_t *off_step;             /* steps + 1: off blocks [off_step[s], off_step[s + 1]) of step s */
    uint32_t *soff;                 /* W per off block: the adjacency entry off the line's tridiagonal part, or NONE */
    uint32_t *soffcol;              /* W per off block: the particle it couples (0 in a padded lane) */
    /* float32 copies (see the file comment): entry f of lane q at (n j + f) W + q */
    float *offval;                  /* n = 6 per off block: its symmetric block */
    float *uval;                    /* 6 per step: U = A(particle, next particle) */
    float *dinv;                    /* 6 per step: the inverted pivot */
    float *cu;                      /* 9 per step: Dinv U by columns, for the back substitution */
    double *work;                   /* 3 per step */
};

void spn__lines_free(spn__lines *L)
{
    if (!L) return;
    free(L->start), free(L->node), free(L->colour_start);
    free(L->colour_group), free(L->group_step), free(L->snode), free(L->supos);
    free(L->off_step), free(L->soff), free(L->soffcol);
    free(L->offval), free(L->uval), free(L->dinv), free(L->cu), free(L->work);
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

/* The adjacency entry of particle i's first spring to particle c (when
 * several springs join them, the factorisation sums them from there) */
static uint32_t first_spring(const spn__eq *e, uint32_t i, uint32_t c)
{
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++)
        if (e->adj_other[j] == (int32_t)c) return j;
    return NONE;
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

static int by_key(const void *x, const void *y)
{
    const uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : a > b;
}

/* Within each colour, the lines longest first (ties in their old order): a
 * sweep steps a group of W lines as long as its longest, so lines of like
 * length go together. On the species webs a colour mixes a spiral of
 * hundreds of nodes with lines of one or two, and grouped as found they
 * padded the sweep several times over (zilla: 0.35 -> 0.58 s a settle).
 * The standard web's lines of a colour are all alike, so its order stays. */
static bool by_length(const spn__lines *L, uint32_t *order)
{
    uint64_t *key = malloc((L->count ? L->count : 1) * sizeof *key);
    if (!key) return false;
    for (uint32_t c = 0; c < L->colours; c++) {
        const uint32_t a = L->colour_start[c], b = L->colour_start[c + 1];
        for (uint32_t k = a; k < b; k++) {
            const uint32_t l = order[k], len = L->start[l + 1] - L->start[l];
            key[k - a] = (uint64_t)(UINT32_MAX - len) << 32 | l;
        }
        qsort(key, b - a, sizeof *key, by_key);
        for (uint32_t k = a; k < b; k++) order[k] = (uint32_t)key[k - a];
    }
    free(key);
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
        L->colour_start = spn__big_calloc((size_t)L->colours + 1, sizeof *L->colour_start);
        start = spn__big_alloc(((size_t)L->count + 1) * sizeof *start);
        node = spn__big_alloc((total ? total : 1) * sizeof *node);
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
        ok = by_length(L, order);
    }
    if (ok) {
        start[0] = 0;
        for (uint32_t k = 0; k < L->count; k++) {
            uint32_t l = nl[k], len = L->start[l + 1] - L->start[l]; /* nl: the order above */
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

/* The entries of line node k's row off the line's block tridiagonal part T
 * (not the diagonal, not the previous or next node of line l): the sweep
 * solves T x_line = b - (A - T) x over those alone. Their count, and, with
 * `put`, their particles into col[] and the adjacency entries of their
 * (first) springs into ent[], at stride W. */
static uint32_t off_entries(const spn__lines *L, const spn__eq *e, const spn__bsr *a0, uint32_t l, uint32_t k,
                            uint32_t *ent, uint32_t *col)
{
    uint32_t i = L->node[k], prev = k > L->start[l] ? L->node[k - 1] : i;
    uint32_t next = k + 1 < L->start[l + 1] ? L->node[k + 1] : i, cnt = 0;
    for (uint32_t p = a0->start[i]; p < a0->start[i + 1]; p++) {
        uint32_t c = a0->col[p];
        if (c == i || c == prev || c == next) continue;
        if (ent) ent[(size_t)W * cnt] = first_spring(e, i, c), col[(size_t)W * cnt] = c;
        cnt++;
    }
    return cnt;
}

/* The line of lane q of group g in colour c, or UINT32_MAX. */
static uint32_t lane_line(const spn__lines *L, uint32_t c, uint32_t g, uint32_t q)
{
    uint32_t l = L->colour_start[c] + W * (g - L->colour_group[c]) + q;
    return l < L->colour_start[c + 1] ? l : UINT32_MAX;
}

/* Group g (of colour c) laid out: pass 0 its lanes' particles, their
 * springs along the line, and each step's count of off blocks (the most any
 * lane has); pass 1, once the counts are summed into offsets, the adjacency
 * entries and columns of those blocks. A group writes only its own steps. */
static void lay_group(spn__lines *L, const spn__eq *e, const spn__bsr *a0, uint32_t c, uint32_t g, int pass)
{
    for (uint32_t q = 0; q < W; q++) {
        uint32_t l = lane_line(L, c, g, q), len = l == UINT32_MAX ? 0 : L->start[l + 1] - L->start[l];
        for (uint32_t s = L->group_step[g], t = 0; s < L->group_step[g + 1]; s++, t++) {
            const size_t slot = W * (size_t)s + q;
            uint32_t k = t < len ? L->start[l] + t : UINT32_MAX;
            if (pass == 0) {
                uint32_t cnt = k == UINT32_MAX ? 0 : off_entries(L, e, a0, l, k, NULL, NULL);
                if (cnt > L->off_step[s + 1]) L->off_step[s + 1] = cnt;
                L->snode[slot] = k == UINT32_MAX ? NONE : L->node[k];
                L->supos[slot] = k == UINT32_MAX || t + 1 >= len ? NONE : first_spring(e, L->node[k], L->node[k + 1]);
                continue;
            }
            size_t j0 = L->off_step[s], j1 = L->off_step[s + 1];
            uint32_t cnt = k == UINT32_MAX ? 0 : off_entries(L, e, a0, l, k, L->soff + W * j0 + q, L->soffcol + W * j0 + q);
            for (size_t j = j0 + cnt; j < j1; j++) L->soff[W * j + q] = NONE, L->soffcol[W * j + q] = 0;
        }
    }
}

/* Steps of the lines laid side by side: group and step offsets first (a
 * group's steps: its longest line; a step's off blocks: the most any lane
 * has), then the particles of each lane and the adjacency entries of the
 * springs whose blocks it reads. The groups are laid out on the team (0.11
 * s of the 1M web's first setup on one thread); each writes its own steps,
 * so the layout is the same on any team. */
static bool lay_out(spn__lines *L, const spn__eq *e, const spn__bsr *a0, int threads)
{
    L->colour_group = spn__big_alloc(((size_t)L->colours + 1) * sizeof *L->colour_group);
    if (!L->colour_group) return false;
    L->colour_group[0] = 0;
    for (uint32_t c = 0; c < L->colours; c++)
        L->colour_group[c + 1] = L->colour_group[c] + (L->colour_start[c + 1] - L->colour_start[c] + W - 1) / W;
    L->groups = L->colour_group[L->colours];
    L->group_step = spn__big_alloc(((size_t)L->groups + 1) * sizeof *L->group_step);
    uint32_t *colour = malloc(((size_t)L->groups + 1) * sizeof *colour); /* each group's */
    if (!L->group_step || !colour) {
        free(colour);
        return false;
    }
    L->group_step[0] = 0;
    for (uint32_t c = 0; c < L->colours; c++)
        for (uint32_t g = L->colour_group[c]; g < L->colour_group[c + 1]; g++) {
            uint32_t longest = 0;
            for (uint32_t q = 0, l; q < W && (l = lane_line(L, c, g, q)) != UINT32_MAX; q++)
                if (L->start[l + 1] - L->start[l] > longest) longest = L->start[l + 1] - L->start[l];
            L->group_step[g + 1] = L->group_step[g] + longest;
            colour[g] = c;
        }
    const size_t S = L->steps = L->group_step[L->groups];
    const int team = L->start[L->count] < FACTOR_PAR_MIN ? 1 : threads;
    (void)team;
    L->off_step = spn__big_calloc(S + 1, sizeof *L->off_step);
    L->snode = spn__big_alloc(W * (S ? S : 1) * sizeof *L->snode);
    L->supos = spn__big_alloc(W * (S ? S : 1) * sizeof *L->supos);
    bool ok = L->off_step && L->snode && L->supos;
    for (int pass = 0; ok && pass < 2; pass++) {
#pragma omp parallel for schedule(dynamic, 16) num_threads(team)
        for (uint32_t g = 0; g < L->groups; g++) lay_group(L, e, a0, colour[g], g, pass);
        if (pass == 0) {
            for (size_t s = 0; s < S; s++) L->off_step[s + 1] += L->off_step[s];
            const size_t nb = L->off_step[S] ? L->off_step[S] : 1, ns = S ? S : 1;
            L->soff = spn__big_alloc(W * nb * sizeof *L->soff);
            L->soffcol = spn__big_alloc(W * nb * sizeof *L->soffcol);
            /* zero: a padded lane's blocks stay zero (spn__lines_factor writes the real ones) */
            L->offval = spn__big_calloc(6 * W * nb, sizeof *L->offval);
            L->uval = spn__big_calloc(6 * W * ns, sizeof *L->uval);
            L->dinv = spn__big_alloc(6 * W * ns * sizeof *L->dinv);
            L->cu = spn__big_alloc(9 * W * ns * sizeof *L->cu);
            L->work = spn__big_alloc(3 * W * ns * sizeof *L->work);
            ok = L->soff && L->soffcol && L->offval && L->uval && L->dinv && L->cu && L->work;
        }
    }
    free(colour);
    return ok;
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
    if (!lay_out(L, e, a0, e->threads)) goto fail;
    /* level 0 has a block per pair of particles: fewer than the adjacency's entries when a pair has several springs */
    uint32_t joined = 0;
    for (uint32_t j = 0; j < nadj; j++) joined += e->adj_other[j] >= 0;
    L->merged = a0->start[a0->rows] - a0->rows != joined;
    L->prefetch = a0->rows >= PREFETCH_MIN;
    return L;
fail:
    free(partner);
    spn__lines_free(L);
    return NULL;
}

/* The six distinct entries (0 1 2 the diagonal, 3 4 5 the entries (0,1)
 * (0,2) (1,2)) of a level-0 block, read from the spring system: from zero,
 * particle i's diagonal block (diag_block), or the blocks of its springs to
 * the particle at the other end of adjacency entry j, its first spring there,
 * in adjacency order (spring_block). That is how the level-0 matrix sums them
 * (equilibrium_mg.c, level0_values), so the values are its bits; the
 * factorisation needs no copy of that matrix (the 1M web's is 360 MB). */
static void diag_block(const spn__eq *e, uint32_t i, double h[6])
{
    for (int k = 0; k < 6; k++) h[k] = 0, h[k] += e->diag[6 * (size_t)i + k];
}

static void spring_block(const spn__lines *L, const spn__eq *e, uint32_t i, uint32_t j, double h[6])
{
    double tmp[6];
    const double *o = spn__eq_offd(e, j, tmp);
    for (int k = 0; k < 6; k++) h[k] = 0, h[k] += o[k];
    if (!L->merged) return;
    for (uint32_t jj = j + 1; jj < e->adj_start[i + 1]; jj++)
        if (e->adj_other[jj] == e->adj_other[j]) {
            o = spn__eq_offd(e, jj, tmp);
            for (int k = 0; k < 6; k++) h[k] += o[k];
        }
}

/* The block of particle i and adjacency entry j as floats at stride W; a
 * NONE entry, a padded lane, keeps the zeros it was allocated with. (On the
 * species webs the lanes are three quarters padding, and rewriting their
 * zeros at every Newton step cost more than the real blocks.) */
static void to_float6(const spn__lines *L, const spn__eq *e, uint32_t i, uint32_t j, float *f)
{
    if (j == NONE) return;
    double h[6];
    spring_block(L, e, i, j, h);
    for (int q = 0; q < 6; q++) f[W * q] = (float)h[q];
}

/* Block Thomas factorisation of group g's lines, all eight lanes at once:
 * each lane's pivots P_0 = D_0, P_s = D_s - U^T P_{s-1}^-1 U (U = U_{s-1})
 * in float64, each lane in the order of the line-by-line factorisation this
 * replaced and of spn__sym_inverse, so the bits are the same. A padded
 * lane (past its line's end) factors an identity pivot and stores zeros. False if a pivot is not
 * positive definite. */
SPN__KERNEL static bool factor_group(spn__lines *L, const spn__eq *sys, uint32_t g)
{
    static const double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    static const int R[6] = {0, 1, 2, 0, 0, 1}, C[6] = {0, 1, 2, 1, 2, 2};
    double prev[6][W]; /* the last pivot's inverse */
    bool ok = true;
    for (size_t s = L->group_step[g]; s < L->group_step[g + 1]; s++) {
        const bool first = s == L->group_step[g];
        double d[9][W], u[9][W], w[9][W], piv[6][W];
        bool on[W];
        for (uint32_t q = 0; q < W; q++) {
            const uint32_t i = L->snode[W * s + q], up = first ? NONE : L->supos[W * (s - 1) + q];
            on[q] = i != NONE;
            double h[6], dd[9], uu[9];
            if (on[q]) diag_block(sys, i, h), spn__sym_full(h, dd);
            else memcpy(dd, ident, sizeof dd);
            if (up != NONE) spring_block(L, sys, L->snode[W * (s - 1) + q], up, h), spn__sym_full(h, uu);
            else memcpy(uu, zero, sizeof uu);
            for (int f = 0; f < 9; f++) d[f][q] = dd[f], u[f][q] = uu[f];
        }
        if (first) {
            for (uint32_t q = 0; q < W; q++) {
                piv[0][q] = d[0][q], piv[1][q] = d[4][q], piv[2][q] = d[8][q];
                piv[3][q] = d[1][q], piv[4][q] = d[2][q], piv[5][q] = d[5][q];
            }
        } else { /* w = P^-1 U, then D - U^T w: level-0 blocks are symmetric (sums of H_s or
                  * -H_s), so U^T P^-1 U is too and only its six distinct entries are formed */
            static const int M[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2};
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++)
                    for (uint32_t q = 0; q < W; q++) {
                        double v = 0;
                        v += prev[M[3 * r]][q] * u[c][q];
                        v += prev[M[3 * r + 1]][q] * u[3 + c][q];
                        v += prev[M[3 * r + 2]][q] * u[6 + c][q];
                        w[3 * r + c][q] = v;
                    }
            for (int k = 0; k < 6; k++)
                for (uint32_t q = 0; q < W; q++)
                    piv[k][q] = d[3 * R[k] + C[k]][q] - ((u[3 * R[k]][q] * w[C[k]][q] + u[3 * R[k] + 1][q] * w[3 + C[k]][q]) +
                                                         u[3 * R[k] + 2][q] * w[6 + C[k]][q]);
            float *cu = L->cu + 9 * W * (s - 1); /* Dinv_{s-1} U_{s-1}, by columns */
            for (int f = 0; f < 9; f++)
                for (uint32_t q = 0; q < W; q++) cu[W * (3 * (f % 3) + f / 3) + q] = (float)w[f][q];
        }
        /* spn__sym_inverse, lane by lane */
        float *dinv = L->dinv + 6 * W * s;
        for (uint32_t q = 0; q < W; q++) {
            const double a = piv[0][q], b = piv[1][q], c = piv[2][q], dd = piv[3][q], e = piv[4][q], f = piv[5][q];
            const double c00 = b * c - f * f, c01 = e * f - dd * c, c02 = dd * f - b * e;
            const double det = a * c00 + dd * c01 + e * c02;
            ok &= a > 0 && det > 1e-300 && det < HUGE_VAL;
            const double id = 1 / det;
            prev[0][q] = c00 * id, prev[1][q] = (a * c - e * e) * id, prev[2][q] = (a * b - dd * dd) * id;
            prev[3][q] = c01 * id, prev[4][q] = c02 * id, prev[5][q] = (dd * e - a * f) * id;
            for (int k = 0; k < 6; k++) dinv[W * k + q] = on[q] ? (float)prev[k][q] : 0.0f;
        }
    }
    float *last = L->cu + 9 * W * (size_t)(L->group_step[g + 1] - 1);
    if (L->group_step[g + 1] > L->group_step[g])
        for (uint32_t f = 0; f < 9 * W; f++) last[f] = 0;
    return ok;
}

bool spn__lines_factor(spn__lines *L, const spn__eq *e, int threads)
{
    /* float copies of the blocks the sweep reads, in the order it reads them
     * (level-0 blocks are symmetric: sums of -H_s or of H_s); each group's
     * own entries, so any thread count gives the same bits */
    const int team = L->start[L->count] < FACTOR_PAR_MIN ? 1 : threads;
    (void)team;
    int bad = 0;
#pragma omp parallel for schedule(static) num_threads(team) reduction(+ : bad)
    for (uint32_t g = 0; g < L->groups; g++) {
        for (size_t s = L->group_step[g]; s < L->group_step[g + 1]; s++) {
            for (size_t j = L->off_step[s]; j < L->off_step[s + 1]; j++)
                for (uint32_t q = 0; q < W; q++)
                    to_float6(L, e, L->snode[W * s + q], L->soff[W * j + q], L->offval + 6 * W * j + q);
            for (uint32_t q = 0; q < W; q++) to_float6(L, e, L->snode[W * s + q], L->supos[W * s + q], L->uval + 6 * W * s + q);
        }
        bad += !factor_group(L, e, g);
    }
    return bad == 0;
}

/* o -= h v on the W lanes, h a symmetric float block at stride W (entries
 * as to_float6), v and o three rows of W. Each lane's sums go in the order
 * (h0 v0 + h3 v1) + h4 v2 and so on, whatever the vector width. */
#define SYM_SUB(h, v0, v1, v2, o0, o1, o2, q)                                                                         \
    do {                                                                                                            \
        const double h0 = (h)[(q)], h1 = (h)[W + (q)], h2 = (h)[2 * W + (q)];                                        \
        const double h3 = (h)[3 * W + (q)], h4 = (h)[4 * W + (q)], h5 = (h)[5 * W + (q)];                            \
        (o0)[q] -= (h0 * (v0) + h3 * (v1)) + h4 * (v2);                                                              \
        (o1)[q] -= (h3 * (v0) + h1 * (v1)) + h5 * (v2);                                                              \
        (o2)[q] -= (h4 * (v0) + h5 * (v1)) + h2 * (v2);                                                              \
    } while (0)

/* The lines of group g solved with the current x off them: forward
 * elimination into work, then back substitution into work and x. */
SPN__KERNEL static void solve_group(const spn__lines *L, uint32_t g, const double *restrict b, double *restrict x)
{
    const size_t s0 = L->group_step[g], s1 = L->group_step[g + 1];
    for (size_t s = s0; s < s1; s++) {
        const uint32_t *nd = L->snode + W * s;
        if (L->prefetch && s + AHEAD < s1) {
            /* The lanes' particles are eight lines apart, so one load
             * instruction walks eight unrelated addresses and the hardware's
             * stride prefetcher cannot follow; on a web beyond the caches
             * (1M particles) the sweep waited on these reads: b and x off
             * the line in the forward pass, and x of the lanes' own
             * particles, written by the back substitution. Prefetching
             * them AHEAD steps early: the 1M web's sweeps 10-20% faster;
             * on the 5k web (in cache) it cost 13%, on the 100k web 2%, so
             * only from PREFETCH_MIN particles. */
            const uint32_t *na = L->snode + W * (s + AHEAD);
            for (uint32_t q = 0; q < W; q++) {
                const size_t i = 3 * (size_t)(na[q] == NONE ? 0 : na[q]);
                __builtin_prefetch(b + i);
                __builtin_prefetch(x + i, 1);
            }
            for (size_t j = L->off_step[s + AHEAD]; j < L->off_step[s + AHEAD + 1]; j++)
                for (uint32_t q = 0; q < W; q++) __builtin_prefetch(x + 3 * (size_t)L->soffcol[W * j + q]);
        }
        double r0[W], r1[W], r2[W];
        for (uint32_t q = 0; q < W; q++) {
            const double *bi = b + 3 * (size_t)(nd[q] == NONE ? 0 : nd[q]);
            r0[q] = bi[0], r1[q] = bi[1], r2[q] = bi[2];
        }
        for (size_t j = L->off_step[s]; j < L->off_step[s + 1]; j++) {
            const uint32_t *col = L->soffcol + W * j;
            const float *h = L->offval + 6 * W * j;
            double v0[W], v1[W], v2[W]; /* gathered first, so that the product below vectorises */
            for (uint32_t q = 0; q < W; q++) {
                const double *v = x + 3 * (size_t)col[q];
                v0[q] = v[0], v1[q] = v[1], v2[q] = v[2];
            }
            for (uint32_t q = 0; q < W; q++) SYM_SUB(h, v0[q], v1[q], v2[q], r0, r1, r2, q);
        }
        if (s > s0) { /* r -= U_{s-1}^T g_{s-1}; U is symmetric */
            const double *gp = L->work + 3 * W * (s - 1);
            const float *u = L->uval + 6 * W * (s - 1);
            for (uint32_t q = 0; q < W; q++) SYM_SUB(u, gp[q], gp[W + q], gp[2 * W + q], r0, r1, r2, q);
        }
        double *o = L->work + 3 * W * s;
        const float *m = L->dinv + 6 * W * s;
        for (uint32_t q = 0; q < W; q++) {
            const double h0 = m[q], h1 = m[W + q], h2 = m[2 * W + q], h3 = m[3 * W + q], h4 = m[4 * W + q],
                         h5 = m[5 * W + q];
            o[q] = (h0 * r0[q] + h3 * r1[q]) + h4 * r2[q];
            o[W + q] = (h3 * r0[q] + h1 * r1[q]) + h5 * r2[q];
            o[2 * W + q] = (h4 * r0[q] + h5 * r1[q]) + h2 * r2[q];
        }
    }
    for (size_t s = s1; s-- > s0;) { /* x_s = g_s - (Dinv_s U_s) x_{s+1} */
        double *gs = L->work + 3 * W * s;
        if (s + 1 < s1) {
            const double *n = gs + 3 * W;
            const float *m = L->cu + 9 * W * s; /* by columns */
            for (uint32_t q = 0; q < W; q++) {
                const double n0 = n[q], n1 = n[W + q], n2 = n[2 * W + q];
                gs[q] -= ((double)m[q] * n0 + (double)m[3 * W + q] * n1) + (double)m[6 * W + q] * n2;
                gs[W + q] -= ((double)m[W + q] * n0 + (double)m[4 * W + q] * n1) + (double)m[7 * W + q] * n2;
                gs[2 * W + q] -= ((double)m[2 * W + q] * n0 + (double)m[5 * W + q] * n1) + (double)m[8 * W + q] * n2;
            }
        }
        const uint32_t *nd = L->snode + W * s;
        for (uint32_t q = 0; q < W; q++)
            if (nd[q] != NONE) {
                double *xi = x + 3 * (size_t)nd[q];
                xi[0] = gs[q], xi[1] = gs[W + q], xi[2] = gs[2 * W + q];
            }
    }
}

void spn__lines_sweep(const spn__lines *L, const double *b, double *x, bool forward, int threads)
{
    for (uint32_t k = 0; k < L->colours; k++) {
        uint32_t c = forward ? k : L->colours - 1 - k;
        uint32_t g0 = L->colour_group[c], g1 = L->colour_group[c + 1];
        int team = L->start[L->colour_start[c + 1]] - L->start[L->colour_start[c]] < PAR_MIN ? 1 : threads;
        (void)team;
#pragma omp parallel for schedule(static) num_threads(team)
        for (uint32_t g = g0; g < g1; g++) solve_group(L, g, b, x);
    }
}

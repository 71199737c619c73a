/* The static problem behind spn_world_equilibrium: the total potential
 *   E(x) = sum_s 1/2 k_s (|l_s| - r_s)^2  -  sum_i f_ext,i . x_i
 * over the free particles (tension-only springs count only while stretched),
 * its gradient (minus the net force) and a positive semi-definite Hessian.
 *
 * A spring's exact Hessian block, with u = l/|l| and tension t = k(|l| - r), is
 *   H_s = k u u^T + (t/|l|) (I - u u^T)
 * and appears as +H_s on both ends' diagonals and -H_s between them. The
 * transverse term t/|l| is negative for a compressed spring; we use |t|/|l|
 * there (flipping the negative eigenvalue, as saddle-free Newton does) so the
 * block stays positive semi-definite, and a slack tension-only spring
 * contributes nothing. Dropping the term instead (clamping it to 0) was
 * measured too: a chain laid straight and compressed then needs 170 to 200+
 * Newton steps instead of 17 to 62, because a straight strut without
 * transverse stiffness gives Newton no scale for the buckling move. A taut web
 * has no compressed spring and keeps the exact Hessian, so Newton converges
 * quadratically near its rest state.
 *
 * The problem is read once through the public world API (so it does not depend
 * on the world's internal layout): free particles get local ids 0..n-1 in world
 * order, fixed ones touched by a spring follow. Every loop writes its own
 * outputs (springs, or particles gathering over their incident springs in
 * spring order) and every sum runs over fixed blocks added in order, so the
 * results are the same bits for any thread count. */
#include "core/big_alloc.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define PAR_MIN 32768u /* below this many items a loop runs on one thread: smaller loops lose more to the fork than they gain */

#ifdef _OPENMP /* (used by OpenMP pragmas only) */
static inline int team(const spn__eq *e, uint32_t items) { return items < PAR_MIN ? 1 : e->threads; }
#endif

void spn__eq_free(spn__eq *e)
{
    free(e->world_id);
    free(e->x);
    free(e->fext);
    free(e->xtrial);
    free(e->sa);
    free(e->sb);
    free(e->k);
    free(e->rest);
    free(e->tonly);
    free(e->adj_start);
    free(e->adj);
    free(e->adj_other);
    free(e->adj_col);
    free(e->offd);
    free(e->lane_start), free(e->lane_by_row), free(e->lane_col), free(e->lane_val), free(e->lane_diag);
    free(e->lane_val32), free(e->lane_diag32);
    free(e->hs);
    free(e->fs);
    free(e->diag);
    free(e->kscale);
    free(e->f);
    free(e->partial);
    memset(e, 0, sizeof *e);
}

/* A live spring as read from the world once (spn_world_spring also measures
 * its length, which the solver does not need: reading each spring once
 * instead of in each of three passes took the setup from 6.2M to 3.8M
 * instructions on the 5k web, whose whole solve is 290M). */
typedef struct spring_rec {
    uint32_t a, b;
    double k, rest;
    bool tonly;
} spring_rec;

/* Live springs (not broken, k > 0) into rec; returns their count. */
static uint32_t read_springs(const spn_world *w, spring_rec *rec)
{
    uint32_t ns = spn_world_spring_count(w), live = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken || !(si.k > 0)) continue;
        rec[live++] = (spring_rec){si.a, si.b, si.k, si.rest, si.tension_only};
    }
    return live;
}

/* Local ids: free particles with at least one live spring first, then the
 * fixed ones such springs touch. Others do not take part. */
static spn_status number_particles(spn__eq *e, const spn_world *w, const spring_rec *rec, uint32_t live,
                                   int32_t *local, uint8_t *touched)
{
    uint32_t np = spn_world_particle_count(w);
    for (uint32_t s = 0; s < live; s++) touched[rec[s].a] = touched[rec[s].b] = 1;
    uint32_t n = 0;
    for (uint32_t i = 0; i < np; i++)
        if (touched[i] && !spn_world_is_fixed(w, i)) local[i] = (int32_t)n++;
    uint32_t nl = n;
    for (uint32_t i = 0; i < np; i++)
        if (touched[i] && spn_world_is_fixed(w, i)) local[i] = (int32_t)nl++;
    e->n = n;
    e->nl = nl;
    e->np_world = np;
    e->world_id = spn__big_alloc((nl ? nl : 1) * sizeof *e->world_id);
    e->x = spn__big_alloc(3 * (size_t)(nl ? nl : 1) * sizeof *e->x);
    e->xtrial = spn__big_alloc(3 * (size_t)(nl ? nl : 1) * sizeof *e->xtrial);
    if (!e->world_id || !e->x || !e->xtrial) return SPN_ERR_NOMEM;
    const spn_vec3 *pos = spn_world_positions(w);
    for (uint32_t i = 0; i < np; i++) {
        if (local[i] < 0) continue;
        uint32_t l = (uint32_t)local[i];
        e->world_id[l] = i;
        memcpy(e->x + 3 * (size_t)l, &pos[i], 3 * sizeof(double));
    }
    memcpy(e->xtrial, e->x, 3 * (size_t)nl * sizeof *e->x);
    for (size_t c = 0; c < 3 * (size_t)nl; c++) e->xmax = fmax(e->xmax, fabs(e->x[c]));
    return SPN_OK;
}

static spn_status gather_springs(spn__eq *e, const spring_rec *rec, uint32_t live, const int32_t *local)
{
    uint32_t m = 0;
    size_t cap = live ? live : 1;
    e->sa = spn__big_alloc(cap * sizeof *e->sa);
    e->sb = spn__big_alloc(cap * sizeof *e->sb);
    e->k = spn__big_alloc(cap * sizeof *e->k);
    e->rest = spn__big_alloc(cap * sizeof *e->rest);
    e->tonly = spn__big_alloc(cap);
    if (!e->sa || !e->sb || !e->k || !e->rest || !e->tonly) return SPN_ERR_NOMEM;
    /* springs between free particles first, then those to a fixed one with
     * the free end as a (the edge-wise product needs no branch on the first) */
    for (int pass = 0; pass < 2; pass++) {
        for (uint32_t s = 0; s < live; s++) {
            const spring_rec *r = rec + s;
            if (r->a == r->b) continue;
            uint32_t a = (uint32_t)local[r->a], b = (uint32_t)local[r->b];
            if ((a >= e->n && b >= e->n) || (pass == 0) != (a < e->n && b < e->n)) continue;
            e->sa[m] = a < e->n ? a : b;
            e->sb[m] = a < e->n ? b : a;
            e->k[m] = r->k;
            e->rest[m] = r->rest;
            e->tonly[m] = r->tonly;
            m++;
        }
        if (pass == 0) e->m_free = m;
    }
    e->m = m;
    return SPN_OK;
}

static spn_status build_adjacency(spn__eq *e)
{
    uint32_t n = e->n;
    e->adj_start = spn__big_calloc((size_t)n + 1, sizeof *e->adj_start);
    e->adj = spn__big_alloc(2 * (size_t)(e->m ? e->m : 1) * sizeof *e->adj);
    e->adj_other = spn__big_alloc(2 * (size_t)(e->m ? e->m : 1) * sizeof *e->adj_other);
    e->adj_col = spn__big_alloc(2 * (size_t)(e->m ? e->m : 1) * sizeof *e->adj_col);
    e->kscale = spn__big_calloc(n ? n : 1, sizeof *e->kscale);
    uint32_t *fill = calloc(n ? n : 1, sizeof *fill);
    if (!e->adj_start || !e->adj || !e->adj_other || !e->adj_col || !e->kscale || !fill) {
        free(fill);
        return SPN_ERR_NOMEM;
    }
    for (uint32_t s = 0; s < e->m; s++) {
        if (e->sa[s] < n) e->adj_start[e->sa[s] + 1]++;
        if (e->sb[s] < n) e->adj_start[e->sb[s] + 1]++;
    }
    for (uint32_t i = 0; i < n; i++) e->adj_start[i + 1] += e->adj_start[i];
    for (uint32_t s = 0; s < e->m; s++) {
        uint32_t a = e->sa[s], b = e->sb[s];
        if (a < n) {
            uint32_t j = e->adj_start[a] + fill[a]++;
            e->adj[j] = s << 1;
            e->adj_other[j] = b < n ? (int32_t)b : -1;
            e->adj_col[j] = b < n ? (int32_t)b : (int32_t)a;
            e->kscale[a] += e->k[s];
        }
        if (b < n) {
            uint32_t j = e->adj_start[b] + fill[b]++;
            e->adj[j] = s << 1 | 1u;
            e->adj_other[j] = a < n ? (int32_t)a : -1;
            e->adj_col[j] = a < n ? (int32_t)a : (int32_t)b;
            e->kscale[b] += e->k[s];
        }
    }
    free(fill);
    return SPN_OK;
}

static void external_forces(spn__eq *e, const spn_world *w, const spn_equilibrium_def *def)
{
    spn_vec3 g = def->gravity ? spn_world_get_def(w)->gravity : spn_v3(0, 0, 0);
    for (uint32_t i = 0; i < e->n; i++) {
        uint32_t id = e->world_id[i];
        double mass = spn_world_mass(w, id);
        spn_vec3 f = spn_v3_add(spn_v3_scale(g, mass), def->load);
        if (def->loads) f = spn_v3_add(f, def->loads[id]);
        e->fext[3 * i] = f.x;
        e->fext[3 * i + 1] = f.y;
        e->fext[3 * i + 2] = f.z;
    }
}

/* Free particles without a live spring do not take part; only an external
 * force on one of them keeps the world from rest. */
static void isolated_forces(spn__eq *e, const spn_world *w, const spn_equilibrium_def *def, const int32_t *local)
{
    spn_vec3 g = def->gravity ? spn_world_get_def(w)->gravity : spn_v3(0, 0, 0);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        if (local[i] >= 0 || spn_world_is_fixed(w, i)) continue;
        spn_vec3 f = spn_v3_add(spn_v3_scale(g, spn_world_mass(w, i)), def->load);
        if (def->loads) f = spn_v3_add(f, def->loads[i]);
        double len = spn_v3_len(f);
        if (len > e->iso_force) {
            e->iso_force = len;
            e->iso_worst = i;
        }
    }
}

spn_status spn__eq_init(spn__eq *e, const spn_world *w, const spn_equilibrium_def *def)
{
    memset(e, 0, sizeof *e);
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w), live = 0;
    int32_t *local = malloc((np ? np : 1) * sizeof *local);
    uint8_t *touched = calloc(np ? np : 1, 1);
    spring_rec *rec = malloc((ns ? ns : 1) * sizeof *rec);
    spn_status st = local && touched && rec ? SPN_OK : SPN_ERR_NOMEM;
    if (st == SPN_OK) {
        for (uint32_t i = 0; i < np; i++) local[i] = -1;
        live = read_springs(w, rec);
        st = number_particles(e, w, rec, live, local, touched);
    }
    if (st == SPN_OK) st = gather_springs(e, rec, live, local);
    if (st == SPN_OK) isolated_forces(e, w, def, local);
    free(local);
    free(touched);
    free(rec);
    if (st == SPN_OK) st = build_adjacency(e);
    if (st == SPN_OK) st = spn__eq_build_lanes(e);
    if (st == SPN_OK) {
        size_t n = e->n ? e->n : 1, m = e->m ? e->m : 1;
        e->fext = spn__big_alloc(3 * n * sizeof *e->fext);
        e->f = spn__big_alloc(3 * n * sizeof *e->f);
        e->diag = spn__big_alloc(6 * n * sizeof *e->diag);
        e->hs = spn__big_alloc(6 * m * sizeof *e->hs);
        e->fs = spn__big_alloc(3 * m * sizeof *e->fs);
        size_t chunks = (n > m ? n : m) / SPN__EQ_CHUNK + 1;
        e->partial = spn__big_alloc(4 * chunks * sizeof *e->partial);
        if (!e->fext || !e->f || !e->diag || !e->hs || !e->fs || !e->partial) st = SPN_ERR_NOMEM;
    }
    if (st != SPN_OK) {
        spn__eq_free(e);
        return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory for %u particles", np);
    }
    e->nchunks = (e->n + SPN__EQ_CHUNK - 1) / SPN__EQ_CHUNK;
    int threads = def->threads > 0 ? def->threads : spn_world_get_def(w)->threads;
#ifdef _OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#endif
    e->threads = threads > 0 ? threads : 1;
    external_forces(e, w, def);
    return SPN_OK;
}

/* One spring's force on end a and its projected Hessian block; returns
 * |t| (|l| + max |x|), the scale of the rounding in its energy difference
 * (the ends' coordinates and the length are each rounded to an ulp). */
static double spring_terms(const spn__eq *e, uint32_t s, double *fs, double *h)
{
    const double *xa = e->x + 3 * (size_t)e->sa[s], *xb = e->x + 3 * (size_t)e->sb[s];
    double l[3] = {xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]};
    double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    double d = len - e->rest[s];
    if (!(len > 0) || (d <= 0 && e->tonly[s])) {
        memset(fs, 0, 3 * sizeof *fs);
        memset(h, 0, 6 * sizeof *h);
        return 0;
    }
    double k = e->k[s], t = k * d, inv = 1 / len;
    double u[3] = {l[0] * inv, l[1] * inv, l[2] * inv};
    double trans = fabs(t) * inv, ax = k - trans;
    fs[0] = -t * u[0];
    fs[1] = -t * u[1];
    fs[2] = -t * u[2];
    h[0] = ax * u[0] * u[0] + trans;
    h[1] = ax * u[1] * u[1] + trans;
    h[2] = ax * u[2] * u[2] + trans;
    h[3] = ax * u[0] * u[1];
    h[4] = ax * u[0] * u[2];
    h[5] = ax * u[1] * u[2];
    return fabs(t) * (len + e->xmax);
}

double spn__eq_spring_terms(const spn__eq *e, uint32_t s, double *fs, double *h)
{
    return spring_terms(e, s, fs, h);
}

/* Net force and diagonal block of free particle i. */
static void gather_particle(spn__eq *e, uint32_t i, double lambda)
{
    double f[3] = {e->fext[3 * i], e->fext[3 * i + 1], e->fext[3 * i + 2]};
    double d[6] = {0, 0, 0, 0, 0, 0};
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
        uint32_t s = e->adj[j] >> 1;
        const double *fs = e->fs + 3 * (size_t)s, *h = e->hs + 6 * (size_t)s;
        double sign = (e->adj[j] & 1u) ? -1 : 1;
        for (int c = 0; c < 3; c++) f[c] += sign * fs[c];
        for (int c = 0; c < 6; c++) d[c] += h[c];
    }
    double shift = lambda * e->kscale[i];
    d[0] += shift;
    d[1] += shift;
    d[2] += shift;
    memcpy(e->f + 3 * (size_t)i, f, sizeof f);
    memcpy(e->diag + 6 * (size_t)i, d, sizeof d);
}

double spn__eq_assemble(spn__eq *e, double lambda, uint32_t *worst)
{
    e->lambda = lambda;
    const uint32_t m = e->m, nchunks = e->nchunks, schunks = (m + SPN__EQ_CHUNK - 1) / SPN__EQ_CHUNK;
#pragma omp parallel for schedule(static) num_threads(team(e, m))
    for (uint32_t c = 0; c < schunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < m ? (c + 1) * SPN__EQ_CHUNK : m;
        double scale = 0;
        for (uint32_t s = c * SPN__EQ_CHUNK; s < end; s++)
            scale += spring_terms(e, s, e->fs + 3 * (size_t)s, e->hs + 6 * (size_t)s);
        e->partial[4 * c + 3] = scale;
    }
    double scale = 0;
    for (uint32_t c = 0; c < schunks; c++) scale += e->partial[4 * c + 3];
    e->noise = 4 * DBL_EPSILON * scale;
#pragma omp parallel for schedule(static) num_threads(team(e, e->n))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < e->n ? (c + 1) * SPN__EQ_CHUNK : e->n;
        double best = -1;
        uint32_t arg = 0;
        for (uint32_t i = c * SPN__EQ_CHUNK; i < end; i++) {
            gather_particle(e, i, lambda);
            spn__eq_lanes_store(e, i);
            const double *f = e->f + 3 * (size_t)i;
            double f2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
            if (f2 > best) {
                best = f2;
                arg = i;
            }
        }
        e->partial[4 * c] = best;
        e->partial[4 * c + 1] = arg;
    }
    double best = 0;
    uint32_t arg = 0;
    for (uint32_t c = 0; c < nchunks; c++)
        if (e->partial[4 * c] > best) {
            best = e->partial[4 * c];
            arg = (uint32_t)e->partial[4 * c + 1];
        }
    if (worst) *worst = arg;
    return sqrt(best);
}

double spn__eq_slack_limit(const spn__eq *e, const double *p, double cap)
{
    double alpha = 1;
    for (uint32_t s = 0; s < e->m; s++) {
        if (!e->tonly[s]) continue;
        uint32_t a = e->sa[s], b = e->sb[s];
        const double *xa = e->x + 3 * (size_t)a, *xb = e->x + 3 * (size_t)b;
        double l[3] = {xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]};
        double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]), d = len - e->rest[s];
        if (!(d > 0)) continue;
        const double *pa = p + 3 * (size_t)a;
        double dp[3] = {pa[0], pa[1], pa[2]};
        if (b < e->n) {
            const double *pb = p + 3 * (size_t)b;
            dp[0] -= pb[0], dp[1] -= pb[1], dp[2] -= pb[2];
        }
        double dl = (l[0] * dp[0] + l[1] * dp[1] + l[2] * dp[2]) / len;
        if (dl < -cap * d) alpha = fmin(alpha, cap * d / -dl);
    }
    return alpha;
}

double spn__eq_length_energy(const spn__eq *e, uint32_t s, double l0, double l1)
{
    const double d0 = l0 - e->rest[s], d1 = l1 - e->rest[s];
    return spn__spring_energy_change(e->k[s], e->tonly[s], d0, d1, d1 - d0);
}

static double spring_energy_delta(const spn__eq *e, uint32_t s)
{
    const double *xa = e->x + 3 * (size_t)e->sa[s], *xb = e->x + 3 * (size_t)e->sb[s];
    const double *ya = e->xtrial + 3 * (size_t)e->sa[s], *yb = e->xtrial + 3 * (size_t)e->sb[s];
    double l0 = sqrt((xa[0] - xb[0]) * (xa[0] - xb[0]) + (xa[1] - xb[1]) * (xa[1] - xb[1]) +
                     (xa[2] - xb[2]) * (xa[2] - xb[2]));
    double l1 = sqrt((ya[0] - yb[0]) * (ya[0] - yb[0]) + (ya[1] - yb[1]) * (ya[1] - yb[1]) +
                     (ya[2] - yb[2]) * (ya[2] - yb[2]));
    return spn__eq_length_energy(e, s, l0, l1);
}

double spn__eq_energy_delta(spn__eq *e, const double *p, double alpha)
{
    const uint32_t n3 = 3 * e->n, m = e->m;
    double *y = e->xtrial;
#pragma omp parallel for schedule(static) num_threads(team(e, e->n))
    for (uint32_t i = 0; i < n3; i++) y[i] = e->x[i] + alpha * p[i];
    uint32_t schunks = (m + SPN__EQ_CHUNK - 1) / SPN__EQ_CHUNK;
#pragma omp parallel for schedule(static) num_threads(team(e, m))
    for (uint32_t c = 0; c < schunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < m ? (c + 1) * SPN__EQ_CHUNK : m;
        double sum = 0;
        for (uint32_t s = c * SPN__EQ_CHUNK; s < end; s++) sum += spring_energy_delta(e, s);
        e->partial[c] = sum;
    }
    double de = 0;
    for (uint32_t c = 0; c < schunks; c++) de += e->partial[c];
    return de - alpha * spn__eq_dot(e, e->fext, p);
}


/* Sum of a[i] * b[i] over [lo, hi), four running sums so the additions
 * overlap instead of waiting on each other; fixed order all the same. */
static inline double chunk_dot(const double *a, const double *b, uint32_t lo, uint32_t hi)
{
    double s[4] = {0, 0, 0, 0};
    uint32_t i = lo;
    for (; i + 4 <= hi; i += 4)
        for (int k = 0; k < 4; k++) s[k] += a[i + k] * b[i + k];
    for (; i < hi; i++) s[0] += a[i] * b[i];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

double spn__eq_dot(const spn__eq *e, const double *a, const double *b)
{
    const uint32_t nchunks = e->nchunks, n3 = 3 * e->n;
    double *part = e->partial;
#pragma omp parallel for schedule(static) num_threads(team(e, e->n))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t end = 3 * (c + 1) * SPN__EQ_CHUNK < n3 ? 3 * (c + 1) * SPN__EQ_CHUNK : n3;
        part[c] = chunk_dot(a, b, 3 * c * SPN__EQ_CHUNK, end);
    }
    double sum = 0;
    for (uint32_t c = 0; c < nchunks; c++) sum += part[c];
    return sum;
}

double spn__eq_update(const spn__eq *e, double alpha, const double *d, const double *q, double *p, double *r,
                      double *rmax2)
{
    const uint32_t n = e->n, nchunks = e->nchunks;
    double *part = e->partial;
#pragma omp parallel for schedule(static) num_threads(team(e, e->n))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < n ? (c + 1) * SPN__EQ_CHUNK : n;
        double rr = 0, big = 0;
        for (uint32_t i = c * SPN__EQ_CHUNK; i < end; i++) {
            size_t k = 3 * (size_t)i;
            p[k] += alpha * d[k], p[k + 1] += alpha * d[k + 1], p[k + 2] += alpha * d[k + 2];
            double r0 = r[k] - alpha * q[k], r1 = r[k + 1] - alpha * q[k + 1], r2 = r[k + 2] - alpha * q[k + 2];
            r[k] = r0, r[k + 1] = r1, r[k + 2] = r2;
            double ri = r0 * r0 + r1 * r1 + r2 * r2;
            rr += ri;
            big = ri > big ? ri : big;
        }
        part[2 * c] = rr;
        part[2 * c + 1] = big;
    }
    double sum = 0, big = 0;
    for (uint32_t c = 0; c < nchunks; c++) {
        sum += part[2 * c];
        big = part[2 * c + 1] > big ? part[2 * c + 1] : big;
    }
    *rmax2 = big;
    return sum;
}

bool spn__sym_inverse(const double *h, double *inv)
{
    /* cofactors of [[a, d, e], [d, b, f], [e, f, c]] */
    double a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5];
    double c00 = b * c - f * f, c01 = e * f - d * c, c02 = d * f - b * e;
    double det = a * c00 + d * c01 + e * c02;
    if (!(a > 0) || !(det > 1e-300) || !isfinite(det)) return false;
    double id = 1 / det;
    inv[0] = c00 * id;
    inv[1] = (a * c - e * e) * id;
    inv[2] = (a * b - d * d) * id;
    inv[3] = c01 * id;
    inv[4] = c02 * id;
    inv[5] = (d * e - a * f) * id;
    return true;
}

/* Computed connectivity for a regular orb web: when a world's springs are
 * exactly a hub + rings x radials lattice, the explicit steps (Euler,
 * symplectic Euler, Mehla 2005 eq. 4.5) and the RK4 stages (eqs. 4.16-4.19)
 * run as a stencil over rows of particles instead of through spring records
 * and an adjacency. Same spring law as chunk.h (eq. 4.14, the same expression
 * per spring), no indices read, no gather or scatter: every loop below runs
 * over contiguous arrays and vectorises.
 *
 * The lattice. Particle 0 is the hub, particle 1 + j N + i is ring j
 * (0 = innermost), radial i. Radial springs join the hub to ring 0 and ring
 * j - 1 to ring j at the same i; ring springs join i to i + 1 in a row, and
 * the row's last to its first (the "wrap" spring, stored in ring slot N - 1).
 * spn__lattice_build recognises this from the spring list itself (any world
 * with that structure gets it, not only spn_scene_orb) and copies each
 * spring's k, kd and rest into per-slot arrays (the sign of rest carries the
 * tension-only flag: a slack spring has stretch < 0, which a zero rest length
 * never has). Anything that breaks the pattern (a broken spring, an added
 * one, a force callback, air drag) sends the step back to the general path.
 *
 * State. For the length of an spn_world_advance call (or around a lone
 * spn_world_step) the step keeps its own copy of the state, structure of
 * arrays (x, v by component, rows one after another), loaded from w->x,
 * w->v at its first step and written back by spn__lattice_sync.
 *
 * The sweep. Rows are swept outwards, read straight from those arrays: row
 * j's radial springs (to row j - 1, not moved yet) and its ring springs are
 * computed; then row j - 1 has every force it will get and is moved in
 * place. So every spring sees the state from before the step, and each
 * particle is read once and written once (lattice_sweep_t.h, the float32
 * step's sweep too). Big webs take several steps to a sweep
 * (lattice_block_t.h, both precisions too).
 *
 * Same bits as the general two-pass step. A particle's force is summed in the
 * order the gather uses for a web numbered like spn_scene_orb (radials added
 * before rings): gravity and drag, then its springs as lower end (radial out,
 * ring to i + 1, wrap), then as upper end (radial in, wrap, ring from i - 1).
 * So on such a web the trajectory is bit-identical to the general path's
 * below two sweep blocks (tests/test_physics_lattice.c); only the energy sums
 * of the blow-up check are added in another order.
 *
 * Parallel and deterministic. Rows are grouped into bands of at least
 * def.parallel_min / 8 particles, fixed whatever the thread count. The radial
 * springs between two bands are computed first (from the state before the
 * step) into `cut`, so bands can then be swept by any thread in any order;
 * each band's sums are added in band order. */
#include "lattice_rows.h"
#include "world_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- building ---- */

static void lattice_free(spn__lattice *L)
{
    if (!L) return;
    free(L->slots);
    free(L->cut), free(L->partial), free(L->rk4), free(L->state), free(L->masses), free(L->partial_k);
    free(L->split.first), free(L->split.rate), free(L->split.took);
    for (int t = 0; t < L->nbws; t++) free(L->bws[t]);
    free(L->bws);
    spn__lat32_free(L->f32);
    for (int t = 0; t < L->nws; t++) free(L->ws[t]);
    free(L->ws);
    for (int t = 0; t < L->ncols; t++) free(L->cols[t]);
    free(L->cols);
    free(L);
}

void spn__lattice_drop(spn_world *w)
{
    spn__lattice_sync(w);
    lattice_free(w->lat);
    w->lat = NULL;
}

/* Slot of public spring s (ends a < b): radial (true) or ring, and index. */
static bool slot_of(uint32_t n, uint32_t a, uint32_t b, uint32_t rings, bool *radial, size_t *slot)
{
    if (a > b) { uint32_t t = a; a = b; b = t; }
    if (a == 0) {
        *radial = true, *slot = b - 1;
        return b >= 1 && b <= n;
    }
    const uint32_t j = (a - 1) / n, i = (a - 1) % n;
    if (b - a == n && j + 1 < rings) *radial = true, *slot = (size_t)(j + 1) * n + i;
    else if (b - a == 1 && i + 1 < n) *radial = false, *slot = (size_t)j * n + i;
    else if (i == 0 && b - a == n - 1) *radial = false, *slot = (size_t)j * n + n - 1;
    else return false;
    return true;
}

static void store(spn__lattice *L, bool radial, size_t slot, spn__spring h)
{
    double *k = radial ? L->rk : L->gk, *kd = radial ? L->rkd : L->gkd, *rest = radial ? L->rrest : L->grest;
    slot = lat_slot(L, slot);
    k[slot] = h.k, kd[slot] = h.kd;
    rest[slot] = spn__tension_only(h) ? -h.rest : h.rest;
    spn__lat32_params_changed(L->f32);
}

void spn__lattice_build(spn_world *w)
{
    spn__lattice_drop(w);
    if (w->np < 4 || w->ns == 0) return;
    const uint32_t n = w->adj_start[1] - w->adj_start[0]; /* the hub's springs: one per radial */
    if (n < 3 || (w->np - 1) % n) return;
    const uint32_t rings = (w->np - 1) / n;
    if ((uint64_t)w->ns != 2 * (uint64_t)rings * n) return;
    for (uint32_t s = 0; s < w->ns; s++)
        if (w->sflags[s] & SPN_SPRING_BROKEN) return;
    spn__lattice *L = calloc(1, sizeof *L);
    if (!L) return;
    L->gov.t0 = -1, L->passes.t0 = -1;
    L->split.hold = -1;
    L->rings = rings, L->radials = n;
    L->pitch = padded64(n);
    L->nlat = 1 + (size_t)rings * L->pitch;
    void *first;
    size_t pitch;
    const size_t m = (size_t)rings * n;
    L->slots = spn__lattice_arrays(6, (size_t)rings * L->pitch, sizeof(double), 0, &first, &pitch);
    if (L->slots) {
        double **par[6] = {&L->rk, &L->rkd, &L->rrest, &L->gk, &L->gkd, &L->grest};
        for (int k = 0; k < 6; k++) *par[k] = (double *)first + k * pitch;
    }
    uint8_t *seen = calloc(2 * m, 1);
    bool ok = L->slots && seen;
    for (uint32_t s = 0; ok && s < w->ns; s++) {
        bool radial;
        size_t slot;
        ok = slot_of(n, w->sa[s], w->sb[s], rings, &radial, &slot) && !seen[2 * slot + radial];
        if (!ok) break;
        seen[2 * slot + radial] = 1;
        store(L, radial, slot, spn__hot_spring(w, s));
    }
    free(seen); /* ns = 2 m slots, each filled at most once: all are filled */
    if (!ok) {
        lattice_free(L);
        return;
    }
    w->lat = L;
}

void spn__lattice_spring_changed(spn_world *w, uint32_t s)
{
    if (!w->lat) return;
    if (w->sflags[s] & SPN_SPRING_BROKEN) {
        spn__lattice_drop(w);
        return;
    }
    bool radial;
    size_t slot;
    if (slot_of(w->lat->radials, w->sa[s], w->sb[s], w->lat->rings, &radial, &slot))
        store(w->lat, radial, slot, spn__hot_spring(w, s));
    else spn__lattice_drop(w);
}

/* Bands and per-thread workspaces for this step; false when out of memory. */
static bool prepare(spn_world *w, int threads)
{
    spn__lattice *L = w->lat;
    /* Bands of an eighth of parallel_min particles, or of an eighth of the
     * web where that is less, and at least SPN_BLOCK / 2: on a big web enough
     * of them for a static schedule to share out evenly, few enough that
     * the radials computed twice at their edges cost nothing; a web that
     * takes threads below parallel_min (lattice_threads) is cut into eight,
     * so that a blocked pass's split (lat_split) can move a band or two
     * toward a faster core (bands of an eighth of parallel_min gave the 5k
     * web 41 and 9 rows, SPN_BLOCK-sized ones 11, 11, 11, 11, 6). The rows
     * are then shared out evenly (lat_band_lo): the 5k web's eight are 6,
     * 6, 7, 6, 6, 6, 6 and 7 rows, 25 a thread on two when the cores run
     * alike (bands of 13 rows, 13, 13, 13 and 11, gave 26 and 24:
     * docs/physics-lattice.md, "Even bands"). */
    const uint32_t n = L->radials, eighth = w->def.parallel_min / 8, web = (uint32_t)(w->np / 8);
    const uint32_t want = eighth < web ? eighth : web, bsize = want > SPN_BLOCK / 2 ? want : SPN_BLOCK / 2;
    const uint32_t rows = (bsize + n - 1) / n, nbands = (L->rings + rows - 1) / rows;
    if (L->nbands != nbands) {
        free(L->cut), free(L->partial);
        L->nbands = nbands;
        L->cut = spn__lattice_arrays((size_t)L->nbands * 3, L->pitch, sizeof *L->cut, 0, NULL, NULL);
        L->partial = malloc((size_t)L->nbands * L_NSUMS * sizeof *L->partial);
        if (!L->cut || !L->partial) {
            L->nbands = 0;
            return false;
        }
    }
    if (L->nws < threads) {
        double **ws = realloc(L->ws, (size_t)threads * sizeof *ws);
        if (!ws) return false;
        L->ws = ws;
        L->stride = padded64(n);
        for (; L->nws < threads; L->nws++) {
            L->ws[L->nws] = spn__lattice_arrays(WS_COUNT, L->stride, sizeof **L->ws, 0, NULL, NULL);
            if (!L->ws[L->nws]) return false;
        }
    }
    return spn__lattice_cols_alloc(L, threads);
}

/* ---- the sweep ---- */

/* Row p0 of the evaluated state. */
LAT_INLINE void eval_rows(const lat_args *a, size_t p0, double **X, double **V)
{
    for (int c = 0; c < 3; c++) X[c] = (double *)a->ex[c] + p0, V[c] = (double *)a->ev[c] + p0;
}

/* Particles p0 .. p0+n-1 of an RK4 stage, their force F (3 arrays) known
 * (n: the hub's 1 or a row's padded length, LK(rk4_update)). */
LAT_INLINE void rk4_update(const lat_args *a, size_t p0, uint32_t n, double *const *F,
                           const lat_cols *cs)
{
    const spn__lattice *L = a->L;
    rk4_rows64 R;
    for (int c = 0; c < 3; c++) {
        R.V[c] = a->ev[c] + p0, R.xb[c] = L->x[c] + p0, R.vb[c] = L->v[c] + p0;
        R.xt[c] = a->tx[c] ? a->tx[c] + p0 : NULL, R.vt[c] = a->tv[c] ? a->tv[c] + p0 : NULL;
        R.ax[c] = L->ax[c] + p0, R.av[c] = L->av[c] + p0;
    }
    rk4_update64(n, a->stage, a->h, a->weight, a->drag, a->kin_known, a->g, a->mass + p0, a->inv_mass + p0, &R, F, cs);
}

/* Row p0 complete (radial in, ring, radial out or NULL): its update. */
LAT_INLINE void finish(const lat_args *a, size_t p0, uint32_t n, double *const *ri, double *const *rg,
                       double *const *ro, double *const *Fw, const lat_cols *cs)
{
    const spn__lattice *L = a->L;
    if (a->mode == MODE_RK4_STAGE || a->mode == MODE_RK4_LAST) {
        for (int c = 0; c < 3; c++)
            assemble64(n, a->g[c], a->drag, a->mass + p0, a->ev[c] + p0, ri[c], rg[c], ro ? ro[c] : NULL, Fw[c]);
        rk4_update(a, p0, padded64(n), Fw, cs);
        return;
    }
    double *X[3], *V[3];
    for (int c = 0; c < 3; c++) X[c] = L->x[c] + p0, V[c] = L->v[c] + p0;
    row_move64(n, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, a->mass + p0, a->inv_mass + p0, X, V, ri, rg,
               ro, cs);
}

/* The hub: its radial forces in radial order, then its update. */
static void hub(const lat_args *a, double *const *rad, const lat_cols *cs)
{
    const spn__lattice *L = a->L;
    if (a->mode != MODE_RK4_STAGE && a->mode != MODE_RK4_LAST) {
        hub_move64(L->radials, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, a->mass[0], a->inv_mass[0], L->x,
                   L->v, rad, cs);
        return;
    }
    const double v[3] = {a->ev[0][0], a->ev[1][0], a->ev[2][0]};
    double f[3];
    hub_force64(false, L->radials, a->mass[0], a->drag, a->g, v, rad, f);
    double *Fp[3] = {f, f + 1, f + 2};
    rk4_update(a, 0, 1, Fp, cs);
}

/* The sweep (lattice_sweep_t.h) on the float64 state. */
LAT_INLINE void radials64(const lat_args *a, double *const *Xa, double *const *Va, double *const *Xb, double *const *Vb,
                          uint32_t j, double *const *f, const lat_cols *cs, bool hold)
{
    (void)hold; /* float64 adds its terms into the columns in the spring loop */
    const spn__lattice *L = a->L;
    const size_t s0 = (size_t)j * L->pitch;
    const double *const *cXa = (const double *const *)Xa, *const *cVa = (const double *const *)Va;
    const double *const *cXb = (const double *const *)Xb, *const *cVb = (const double *const *)Vb;
    const bool el = wants_elastic(a->mode, a->stage);
    /* (over the padding too: padded64, lattice_rows_t.h) */
    springs_rows(padded64(L->radials), cXa, cVa, cXb, cVb, 0, 0, L->rk + s0, L->rkd + s0, L->rrest + s0, f, 0, cs, el);
}

LAT_INLINE void rings64(const lat_args *a, double *const *X, double *const *V, uint32_t j, double *const *f,
                        const lat_cols *cs, bool held)
{
    (void)held;
    const spn__lattice *L = a->L;
    const uint32_t n = L->radials;
    const size_t s0 = (size_t)j * L->pitch;
    const double *const *cX = (const double *const *)X, *const *cV = (const double *const *)V;
    const bool el = wants_elastic(a->mode, a->stage);
    springs_rows(n - 1, cX, cV, cX, cV, 0, 1, L->gk + s0, L->gkd + s0, L->grest + s0, f, 0, cs, el);
    springs_rows(1, cX, cV, cX, cV, 0, n - 1, L->gk + s0 + n - 1, L->gkd + s0 + n - 1, L->grest + s0 + n - 1, f, n - 1,
                 cs, el);
}

LAT_INLINE void hub_state64(const lat_args *a, double *x, double *v)
{
    for (int c = 0; c < 3; c++) x[c] = a->ex[c][0], v[c] = a->ev[c][0];
}

static double *cut64(const lat_args *a, uint32_t b, int c)
{
    return a->L->cut + ((size_t)b * 3 + (size_t)c) * a->L->pitch;
}
static size_t pitch64(const lat_args *a) { return a->L->pitch; }
static double *ws64(const lat_args *a, int thread) { return a->L->ws[thread]; }
static size_t stride64(const lat_args *a) { return a->L->stride; }

#define LK_T double
#define LK(name) name##64
#define LK_ARGS lat_args
#define eval64 eval_rows
#define hub64 hub
#define finish64 finish
#include "lattice_sweep_t.h"
#undef eval64
#undef hub64
#undef finish64

/* The blocked pass (lattice_block_t.h) on the float64 state. */
static void state64(const lat_args *a, double **X, double **V)
{
    for (int c = 0; c < 3; c++) X[c] = a->L->x[c], V[c] = a->L->v[c];
}

static const double *mass64(const lat_args *a) { return a->mass; }
static const double *inv_mass64(const lat_args *a) { return a->inv_mass; }

#define LK_RK4_AVX2
#include "lattice_block_t.h"
#undef LK_RK4_AVX2
#undef LK_ARGS
#undef LK
#undef LK_T

/* ---- state: load and write-back ---- */

/* Rows [lo, hi) of the world's state and masses into the lattice's arrays
 * (row 0: the hub). */
static void load_rows(void *ctx, size_t lo, size_t hi)
{
    const spn_world *w = ctx;
    spn__lattice *L = w->lat;
    const spn_vec3 *x = w->x, *v = w->v;
    double *x0 = L->x[0], *x1 = L->x[1], *x2 = L->x[2], *v0 = L->v[0], *v1 = L->v[1], *v2 = L->v[2];
    double *m = L->mass, *im = L->inv_mass;
    const double *wm = w->mass, *wim = w->inv_mass;
    for (uint32_t r = (uint32_t)lo; r < hi; r++) {
        size_t from, to;
        const uint32_t count = lat_row(L, r, &from, &to);
        for (uint32_t i = 0; i < count; i++) {
            const size_t s = from + i, d = to + i;
            m[d] = wm[s], im[d] = wim[s];
            x0[d] = x[s].x, x1[d] = x[s].y, x2[d] = x[s].z;
            v0[d] = v[s].x, v1[d] = v[s].y, v2[d] = v[s].z;
        }
    }
}

/* The world's state into the lattice's arrays; false when out of memory. */
static bool load(spn_world *w, int threads)
{
    spn__lattice *L = w->lat;
    if (!L->state) {
        void *first, *first2;
        size_t pitch, pitch2;
        if (!(L->state = spn__lattice_arrays(6, L->nlat, sizeof(double), 1, &first, &pitch))) return false;
        if (!(L->masses = spn__lattice_arrays(2, L->nlat, sizeof(double), 1, &first2, &pitch2))) {
            free(L->state), L->state = NULL;
            return false;
        }
        L->mass = first2, L->inv_mass = (double *)first2 + pitch2;
        double *q = first;
        for (int c = 0; c < 3; c++)
            L->x[c] = q + c * pitch, L->v[c] = q + (3 + c) * pitch;
    }
    spn__lat_for(L, threads, (size_t)L->rings + 1, load_rows, w);
    spn__lattice_state_moved(L);
    L->live = true;
    L->mv2.ok = false;
    return true;
}

/* Rows [lo, hi) of the lattice's state back into the world's. */
static void write_rows(void *ctx, size_t lo, size_t hi)
{
    spn_world *w = ctx;
    const spn__lattice *L = w->lat;
    spn_vec3 *x = w->x, *v = w->v;
    const double *x0 = L->x[0], *x1 = L->x[1], *x2 = L->x[2], *v0 = L->v[0], *v1 = L->v[1], *v2 = L->v[2];
    for (uint32_t r = (uint32_t)lo; r < hi; r++) {
        size_t to, from;
        const uint32_t count = lat_row(L, r, &to, &from);
        for (uint32_t i = 0; i < count; i++) {
            const size_t d = to + i, s = from + i;
            x[d] = spn_v3(x0[s], x1[s], x2[s]), v[d] = spn_v3(v0[s], v1[s], v2[s]);
        }
    }
}

static void write_back(spn_world *w, int threads)
{
    spn__lat_for(w->lat, threads, (size_t)w->lat->rings + 1, write_rows, w);
    w->lat->live = false;
}

void spn__lattice_sync(spn_world *w)
{
    if (!w->lat) return;
    spn__lat32_sync(w);
    if (w->lat->live) write_back(w, spn__threads(w, w->np));
}

void spn__lattice_discard(spn_world *w)
{
    if (!w->lat) return;
    spn__lat32_discard(w->lat->f32);
    w->lat->live = false;
}

/* The state ready for a step (loaded unless a call already holds it; a
 * step with a backup copies it to x0, v0 first), RK4's arrays, the step's
 * arguments in a. False, with w->x and w->v up to date, when out of memory. */
static bool begin(spn_world *w, int threads, double dt, bool rk4, lat_args *a)
{
    spn__lattice *L = w->lat;
    if (!w->no_backup) spn__lattice_sync(w); /* a step with a backup starts from w->x */
    if (!L->live) {
        if (!w->no_backup) {
            memcpy(w->x0, w->x, w->np * sizeof *w->x);
            memcpy(w->v0, w->v, w->np * sizeof *w->v);
        }
        if (!load(w, threads)) return false;
    }
    if (rk4 && !L->rk4) {
        void *first;
        size_t pitch;
        if (!(L->rk4 = spn__lattice_arrays(18, L->nlat, sizeof(double), 1, &first, &pitch))) {
            spn__lattice_sync(w);
            return false;
        }
        double *q = first;
        for (int k = 0; k < 6; k++)
            L->trial[0][k] = q + k * pitch, L->trial[1][k] = q + (6 + k) * pitch;
        for (int c = 0; c < 3; c++)
            L->ax[c] = q + (12 + c) * pitch, L->av[c] = q + (15 + c) * pitch;
    }
    memset(a, 0, sizeof *a);
    a->L = L;
    a->mass = L->mass, a->inv_mass = L->inv_mass;
    a->g[0] = w->def.gravity.x, a->g[1] = w->def.gravity.y, a->g[2] = w->def.gravity.z;
    a->drag = w->def.drag, a->dt = dt;
    for (int c = 0; c < 3; c++) a->ex[c] = L->x[c], a->ev[c] = L->v[c];
    return true;
}

/* Before an RK4 step (after begin): whether its first stage can take m v^2
 * from the step before (lat_mv2). A debug build checks the carried sum
 * against the state (to round-off: the carry is meant to be bit-exact, but
 * a stale one is what this would catch). */
static bool mv2_known(const spn_world *w)
{
    const spn__lattice *L = w->lat;
    if (!L->mv2.ok || w->def.drag != 0) return false;
#ifndef NDEBUG
    double mv2 = 0;
    for (size_t i = 0; i < L->nlat; i++) /* (the padding between rows has no mass) */
        if (L->inv_mass[i] != 0)
            mv2 += L->mass[i] * (L->v[0][i] * L->v[0][i] + L->v[1][i] * L->v[1][i] + L->v[2][i] * L->v[2][i]);
    assert(fabs(mv2 - L->mv2.sum) <= 1e-9 * mv2 + 1e-300);
#endif
    return true;
}

/* After a step with a backup (spn_world_step, or a run that does not
 * replay), the world's arrays again. */
static void end(spn_world *w, int threads)
{
    if (!w->no_backup) write_back(w, threads);
}

static bool applies(const spn_world *w)
{
    /* (hysteresis sets each spring's damping per step in the spring records,
     * which the lattice's slots do not follow) */
    return w->compiled && w->lat && !w->lattice_off && !w->force_fn && !spn__air_active(w) && !w->nhyst;
}

/* The integrators the lattice steps: Euler, symplectic Euler and RK4. */
static bool lattice_integrator(spn_integrator in)
{
    return in == SPN_INTEGRATOR_EULER || in == SPN_INTEGRATOR_SYMPLECTIC || in == SPN_INTEGRATOR_RK4;
}

const char *spn_world_step_path(const spn_world *w)
{
    return lattice_integrator(w->def.integrator) && applies(w) ? "lattice" : "general";
}

void spn_world_set_lattice(spn_world *w, bool allow) { w->lattice_off = !allow; }

/* Bytes per step of the memory traffic the lattice steps of one
 * spn_world_advance call cannot avoid: each pass over the web reads the
 * state it starts from, the masses and the spring slots once and writes the
 * state once (the float32 step also reads its slots' reference differences).
 * A blocked pass (lattice_block_t.h) keeps the rows in flight in the cache,
 * so its up to SPN__LAT_BLOCK_MAX explicit steps, or its RK4 step's four
 * stages, cost one such pass; an RK4 step taken stage by stage also reads
 * and writes its trial state and its stage sums: stage 0 reads the state and
 * writes a trial state and the sums, stages 1 and 2 read the trial state,
 * the state and the sums and write a trial state and the sums, stage 3
 * reads the same and writes the state: 17 state-sized arrays and four passes
 * over masses and slots. Not counted: the call's load and write-back of the
 * state, the float32 step's rebase every 64 steps, the hub, the bands'
 * cut rows. A model, not a measurement (this VM has no memory counters):
 * bench_step divides it by the time of a step for the share of the
 * machine's bandwidth the step reaches. 0 when the world's steps do not
 * take the lattice. */
double spn__lattice_step_bytes(const spn_world *w, int steps, int blocked)
{
    const spn_integrator in = w->def.integrator;
    const bool rk4 = in == SPN_INTEGRATOR_RK4;
    if (steps < 1 || blocked < 0 || blocked > steps || strcmp(spn_world_step_path(w), "lattice") != 0) return 0;
    const bool f32 = w->precision == SPN_PRECISION_FLOAT32;
    const double size = f32 ? sizeof(float) : sizeof(double), np = w->np,
                 slots = (double)w->lat->rings * w->lat->radials;
    const double state = 6 * np * size,                              /* x and v by component */
        fixed = (2 * np + (f32 ? 12 : 6) * slots) * size,            /* masses; k, kd, rest (and f32 differences) */
        pass = fixed + 2 * state,                                    /* read once, the state written once */
        single = rk4 ? 4 * fixed + 17 * state : pass;                /* a step taken without blocking */
    const int passes = rk4 ? blocked : (blocked + SPN__LAT_BLOCK_MAX - 1) / SPN__LAT_BLOCK_MAX;
    return (passes * pass + (steps - blocked) * single) / steps;
}

/* Threads for a lattice step: from an eighth of def.parallel_min particles
 * (4,096 by default), where the rest of a step goes parallel from
 * parallel_min. A lattice step is one sweep with no gather pass, so two
 * threads pay on smaller webs when the machine has a core to spare (inside
 * spn_world_advance, below): the 5k
 * web's symplectic step 3.0 -> 1.8 wall ns a spring-step, RK4 14 -> 7.7
 * (Zen 4, docs/physics-lattice.md, "Threads"). Below parallel_min the
 * governor (below) decides step by step. The bits do not depend on it (the
 * trajectory does not depend on the bands, the energy sums on the bands
 * only). */
static int lattice_threads(const spn_world *w)
{
    /* Below parallel_min only inside a replayable spn_world_advance: a lone
     * step copies the state in and out around its sweep, and on two threads
     * took as long as on one (5.5 against 5.3 ns a spring-step, 5k web)
     * with twice the CPU. */
    if (w->lat->team) return spn__lattice_team_size(w); /* (the team's threads, lattice_team.c) */
    if (w->np < w->def.parallel_min && !w->no_backup) return 1;
    return spn__threads(w, w->np >= w->def.parallel_min / 8 ? w->def.parallel_min : 0);
}

/* ---- threads below parallel_min: the governor ----
 *
 * A step of the 5k web is 30-60 us of work. Two threads nearly halve it on
 * a quiet machine, but when other programs keep the cores busy a thread
 * waits at each barrier for the scheduler to give its partner a core: with
 * a build running beside it, a third of the runs took 300 ns a spring-step
 * instead of 3-6 on one thread, and one blocked pass of four steps took
 * 16 ms instead of 0.12 (docs/physics-lattice.md, "Threads"). A wrong
 * choice of threads costs a hundred times what a wrong choice of one
 * thread does, so on a web between parallel_min / 8 and parallel_min
 * particles each unit of work (a step, or a blocked pass) is timed, and:
 * - first each choice runs LAT_GOV_FIRST units, threads first, and its
 *   figure is their minimum: a choice's first units allocate workspaces
 *   and find the caches cold (5k web, ns a particle-step: threads' first
 *   pass 134-170, the second 6.5-15, later ones 2.8-3.7; one thread's
 *   first 4.6-11, later 4.2-4.5), so that figures taken from the first
 *   unit of each kept one thread for the first 2 ms;
 * - the choice kept has a running mean of its units' cost (an eighth of
 *   each new unit), and gives way when that exceeds 1.5 times the other's
 *   last figure: one stalled unit on threads at once, one unit slowed by
 *   chance (an interrupt) on a quiet machine not;
 * - the other is tried for LAT_GOV_TRY units, and taken if it was faster
 *   over all of them; the try stops as lost as soon as its sum exceeds what
 *   those units cost the kept choice, so on a busy machine a try of
 *   threads costs one stalled unit;
 * - each choice is tried again a wait after it was last tried or left,
 *   from LAT_GOV_MIN_WAIT, doubled by a lost try (to LAT_GOV_MAX_WAIT) and
 *   halved by a won one. On a busy machine threads are tried every 4 s
 *   (one stalled pass, 0.4%), and after a try won by chance the stall that
 *   follows sends them back to near that wait; on a quiet one a few steps
 *   on one thread are tried as often; threads are back within 4 s of the
 *   machine quietening, and within a few ms of stalls by chance.
 * Results are the same bits either way (tests/test_physics_lattice.c). */
#define LAT_GOV_MIN_WAIT 2e-3
#define LAT_GOV_MAX_WAIT 4.0
#define LAT_GOV_TRY 8
#define LAT_GOV_FIRST 3

int spn__lat_gov_pick(lat_gov *g, double now)
{
    if (g->first[1] < LAT_GOV_FIRST) return g->mode = 1; /* first threads, */
    if (g->first[0] < LAT_GOV_FIRST) return g->mode = 0; /* then one thread */
    if (!(g->wait[0] > 0)) {
        g->kept = g->ns[1] < g->ns[0];
        g->wait[0] = g->wait[1] = LAT_GOV_MIN_WAIT;
        g->next = now + g->wait[!g->kept];
    }
    return g->mode = g->try_units > 0 || now >= g->next ? !g->kept : g->kept;
}

void spn__lat_gov_record(lat_gov *g, double ns, double now)
{
    const int m = g->mode;
    if (g->first[m] < LAT_GOV_FIRST) {
        g->ns[m] = g->first[m]++ ? fmin(g->ns[m], ns) : ns;
        return;
    }
    if (m == g->kept) {
        g->ns[m] += (ns - g->ns[m]) / 8;
        if (g->ns[m] > 1.5 * g->ns[!m]) g->kept = !m, g->next = now + g->wait[m]; /* given way */
        return;
    }
    g->try_sum += ns;
    const bool lost = g->try_sum > LAT_GOV_TRY * g->ns[g->kept];
    if (!lost && ++g->try_units < LAT_GOV_TRY) return;
    g->ns[m] = g->try_sum / (lost ? g->try_units + 1 : g->try_units);
    if (lost) {
        g->wait[m] = g->wait[m] < LAT_GOV_MAX_WAIT / 2 ? 2 * g->wait[m] : LAT_GOV_MAX_WAIT;
        g->next = now + g->wait[m];
    } else {
        g->wait[m] = g->wait[m] > 2 * LAT_GOV_MIN_WAIT ? g->wait[m] / 2 : LAT_GOV_MIN_WAIT;
        g->kept = m, g->next = now + g->wait[!m];
    }
    g->try_sum = 0, g->try_units = 0;
}

void spn__lattice_set_unblocked(spn_world *w, bool single) { w->lattice_unblocked = single; }

bool spn__lattice_gov_prefer(spn_world *w, bool threads)
{
    if (!w->lat) return false;
    lat_gov *g = &w->lat->gov;
    g->ns[threads] = 1, g->ns[!threads] = 1e300; /* no unit measures slower than that */
    g->kept = threads, g->try_sum = 0, g->try_units = 0, g->first[0] = g->first[1] = LAT_GOV_FIRST;
    g->wait[0] = g->wait[1] = LAT_GOV_MAX_WAIT, g->next = HUGE_VAL, g->t0 = -1;
    return true;
}

static double seconds_now(void) { return 1e-9 * spn__lattice_clock_ns(); }

/* Governor g's choice for a unit starting now, its timing started. A unit
 * begun and not ended (a blocked pass declined on one thread, the single
 * step taken instead) passes its pick on to the next. */
static int gov_start(lat_gov *g)
{
    const double now = seconds_now();
    if (!(g->t0 >= 0)) spn__lat_gov_pick(g, now);
    g->t0 = now;
    return g->mode;
}

/* The threads for a unit of work on a web that may take them (threads), as
 * the governor picks below parallel_min, its timing started. */
static int gov_begin(spn_world *w, int threads)
{
    lat_gov *g = &w->lat->gov;
    if (threads < 2 || w->np >= w->def.parallel_min) {
        g->t0 = -1;
        return threads;
    }
    return gov_start(g) ? threads : 1;
}

/* The unit begun by gov_begin (and passes_pick) done: `levels` steps or
 * RK4 stages, timed for each governor that timed it. */
static void gov_end(spn_world *w, uint32_t levels)
{
    lat_gov *const G[2] = {&w->lat->gov, &w->lat->passes};
    double now = -1;
    for (int i = 0; i < 2; i++) {
        lat_gov *g = G[i];
        if (!(g->t0 >= 0)) continue;
        if (now < 0) now = seconds_now();
        spn__lat_gov_record(g, (now - g->t0) * 1e9 / ((double)w->np * levels), now);
        g->t0 = -1;
    }
}

/* ---- one thread: passes or single steps ----
 *
 * A blocked pass keeps the rows in flight in the caches, but it pays for
 * that with per-level force rows, sum columns and bookkeeping, a working
 * set of some 100 KB a front on the 5k web. On one thread it is the faster
 * way for tiny webs (whose single steps are mostly fixed costs) and for
 * webs larger than the L2 cache, not always in between. Measured on the Zen
 * 5 (forty-sixth session, one thread, minimum ns a spring-step, single
 * steps against passes): symplectic float64 500 particles 2.35-2.46 against
 * 2.30-2.31, 5k 2.05-2.09 against 2.17-2.26, 20k 2.13-2.14 against
 * 1.99-2.01; float32 5k 1.58-1.66 against 1.79-1.84, 20k and 50k alike;
 * RK4 5k float64 10.5-11.1 against 9.25-9.38, float32 6.20-6.41 against
 * 6.50-6.66. Where the line falls for the explicit steps depends on the
 * machine's caches, so on a web that steps on one thread (def.threads 1,
 * or too small for threads) each of their units is also timed by a second
 * governor with the thread governor's rules (above): choice 0 a single
 * step (the sweep), 1 a blocked pass. Not where the thread governor chose
 * one thread: there single steps made threads lose its tries (a try
 * outside the call's team pays a parallel region a pass), and the 5k web's
 * symplectic step stayed on one thread (2.10 ns a spring-step in a `make
 * bench` run, against 1.4-1.5 on two). RK4 keeps its passes: its
 * single stages read and write six whole-web arrays each, and its passes
 * were the faster by a seventh or more (a governor's tries of the sweep
 * cost it 1-4% in `make bench`'s short runs). The bits are the same either
 * way (tests/test_physics_lattice.c). True: take a blocked pass for this
 * unit (its timing started). */
static bool passes_pick(spn_world *w)
{
    return w->lattice_passes_held || gov_start(&w->lat->passes);
}

void spn__lattice_hold_passes(spn_world *w, bool held) { w->lattice_passes_held = held; }

/* A team for a replayable advance call (lattice_team.c) when its steps
 * would go on threads: on a web the governor rules, only when its pick now
 * is threads. A team's threads must all get a core to start and to end
 * it, so on a busy machine, where the governor keeps one thread, opening
 * one each call would wait for the scheduler each call (5k web, one other
 * program spinning: 2.8-3.0 ns a spring-step against one thread's 2.3);
 * the passes then go as before, a try of threads in a region of its own. */
int spn__lattice_team_threads(spn_world *w)
{
    if (!lattice_integrator(w->def.integrator) || !applies(w)) return 1;
    const int threads = lattice_threads(w);
    if (threads < 2) return 1;
    if (w->np < w->def.parallel_min) {
        lat_gov *g = &w->lat->gov;
        const int mode = g->t0 >= 0 ? g->mode : spn__lat_gov_pick(g, seconds_now());
        if (!mode) return 1;
    }
    return threads;
}

/* Threads for this world's bands, and the bands ready; 0 when the lattice
 * path does not apply. */
static int ready(spn_world *w)
{
    if (!applies(w)) return 0;
    int threads = lattice_threads(w);
    if (!prepare(w, threads)) return 0;
    if ((uint32_t)threads > w->lat->nbands) threads = (int)w->lat->nbands;
    return gov_begin(w, threads < 1 ? 1 : threads);
}

/* float32 inside spn_world_advance's replayable runs only (and for the step
 * it retakes after a blow-up, so that the retake fails as the run did): a
 * lone step would load and write back the float32 state around itself. */
static bool float32(const spn_world *w)
{
    return w->precision == SPN_PRECISION_FLOAT32 && (w->no_backup || spn__lat32_live(w->lat->f32));
}

bool spn__lattice_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r)
{
    const int threads = ready(w);
    if (!threads) {
        spn__lattice_sync(w);
        return false;
    }
    if (float32(w)) {
        if (w->lat->live) write_back(w, threads);
        const bool done = spn__lat32_explicit(w, threads, dt, symplectic, r);
        if (done) gov_end(w, 1);
        return done;
    }
    spn__lat32_sync(w);
    lat_args a;
    if (!begin(w, threads, dt, false, &a)) return false;
    a.mode = symplectic ? MODE_SYMPLECTIC : MODE_EULER;
    w->lat->mv2.ok = false;
    double sum[L_NSUMS];
    sweep64(&a, threads, sum);
    spn__lattice_state_moved(w->lat);
    lat_explicit_result(sum, dt, w->def.drag, r);
    end(w, threads);
    gov_end(w, 1);
    return true;
}

/* RK4 as in explicit.c (four fused passes), each pass one lattice sweep:
 * stage s evaluated at the trial state of stage s - 1, writing the next one
 * into the other trial array; the last stage moves the state in place. */
bool spn__lattice_rk4(spn_world *w, double dt, spn__step_result *r)
{
    const int threads = ready(w);
    if (!threads) {
        spn__lattice_sync(w);
        return false;
    }
    if (float32(w)) {
        if (w->lat->live) write_back(w, threads);
        const bool done = spn__lat32_rk4(w, threads, dt, r);
        if (done) gov_end(w, 4);
        return done;
    }
    spn__lat32_sync(w);
    lat_args a;
    if (!begin(w, threads, dt, true, &a)) return false;
    spn__lattice *L = w->lat;
    static const double weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5, 0.5, 1};
    double sums[4][L_NSUMS];
    const bool known = mv2_known(w);
    a.kin_known = known;
    for (int stage = 0; stage < 4; stage++) {
        double *const *from = L->trial[(stage + 1) % 2], *const *to = L->trial[stage % 2];
        for (int c = 0; c < 3; c++) {
            a.ex[c] = stage ? from[c] : L->x[c], a.ev[c] = stage ? from[3 + c] : L->v[c];
            a.tx[c] = to[c], a.tv[c] = to[3 + c];
        }
        a.mode = stage < 3 ? MODE_RK4_STAGE : MODE_RK4_LAST;
        a.stage = stage;
        a.weight = weight[stage];
        a.h = stage < 3 ? frac[stage + 1] * dt : dt / 6;
        sweep64(&a, threads, sums[stage]);
    }
    spn__lattice_state_moved(L);
    lat_mv2_carry(&L->mv2, known, sums);
    lat_rk4_result(sums, dt, w->def.drag, r);
    end(w, threads);
    gov_end(w, 4);
    return true;
}

/* Steps as blocked passes (lattice_block_t.h), inside a replayable
 * spn_world_advance, on one thread or on threads (lattice_threads, the
 * governor below parallel_min): up to k Euler or symplectic steps in one
 * pass, or one RK4 step (its four stages) per pass, in float64 or
 * (spn_world_set_precision) float32. Each step's results into r[]; the
 * count done, 0 when a blocked pass does not apply (the caller then takes
 * single steps: the bands too thin for the levels, fewer than two explicit
 * steps left, or spn__lattice_set_unblocked). */
int spn__lattice_block_steps(spn_world *w, double dt, int k, spn__step_result *r)
{
    const spn_integrator in = w->def.integrator;
    const bool rk4 = in == SPN_INTEGRATOR_RK4;
    if (!lattice_integrator(in)) return 0;
    if (k > LAT_LEVELS) k = LAT_LEVELS;
    const uint32_t levels = rk4 ? 4 : (uint32_t)k;
    if (levels < 2 || !w->no_backup) return 0;
    if (w->lattice_unblocked) return 0;
    /* on one thread too: RK4 always, explicit steps as the pass governor
     * picks (above; from the forty-third session to the forty-sixth every
     * one-thread step went in passes, measured then on the 5k web at RK4
     * 15.9 -> 11.0 and symplectic 2.85 -> 2.65 CPU ns a spring-step;
     * docs/physics-lattice.md, "One thread") */
    const int threads = ready(w);
    if (!threads || !spn__lattice_block_ready(w->lat, threads, levels)) return 0;
    /* (a unit the thread governor put on one thread, the one it is timing,
     * stays a pass: its tries of threads, outside a team, could not win
     * against single steps, and the 5k web's symplectic step then stayed on
     * one thread; the single step ends the unit) */
    if (threads == 1 && !rk4 && !(w->lat->gov.t0 >= 0) && !passes_pick(w)) return 0;
    const int mode = rk4 ? MODE_RK4_STAGE : in == SPN_INTEGRATOR_SYMPLECTIC ? MODE_SYMPLECTIC : MODE_EULER;
    if (float32(w)) {
        if (w->lat->live) write_back(w, threads);
        const int done = spn__lat32_block_steps(w, threads, dt, mode, k, r);
        if (done) gov_end(w, levels);
        return done;
    }
    spn__lat32_sync(w);
    lat_args la[LAT_LEVELS];
    if (!begin(w, threads, dt, false, &la[0])) return 0;
    const bool known = rk4 && mv2_known(w);
    la[0].kin_known = known;
    static const double weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5, 0.5, 1};
    for (uint32_t s = 0; s < levels; s++) {
        la[s] = la[0];
        la[s].mode = rk4 ? (s < 3 ? MODE_RK4_STAGE : MODE_RK4_LAST) : mode;
        la[s].stage = rk4 ? (int)s : 0;
        la[s].weight = weight[s % 4];
        la[s].h = s < 3 ? frac[s + 1] * dt : dt / 6;
    }
    double sums[LAT_LEVELS][L_NSUMS];
    if (!block_pass64(w->lat, la, rk4, threads, levels, sums)) return 0;
    gov_end(w, levels);
    if (rk4) {
        lat_mv2_carry(&w->lat->mv2, known, sums);
        lat_rk4_result(sums, dt, w->def.drag, &r[0]);
        return 1;
    }
    w->lat->mv2.ok = false;
    for (int q = 0; q < k; q++) lat_explicit_result(sums[q], dt, w->def.drag, &r[q]);
    return k;
}

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
 * The sweep. Rows are swept outwards. Row j's state is copied into structure-
 * of-arrays buffers; its radial springs (to row j - 1, whose pre-step state is
 * still in the other buffer) and its ring springs are computed; then row j - 1
 * has every force it will get and is moved. So every spring sees the state
 * from before the step, and each particle is read once and written once.
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

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- building ---- */

static void lattice_free(spn__lattice *L)
{
    if (!L) return;
    free(L->rk), free(L->rkd), free(L->rrest), free(L->gk), free(L->gkd), free(L->grest);
    free(L->cut), free(L->partial), free(L->rk4);
    spn__lat32_free(L->f32);
    for (int t = 0; t < L->nws; t++) free(L->ws[t]);
    free(L->ws);
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
    const size_t m = (size_t)rings * n;
    L->rings = rings, L->radials = n;
    L->rk = malloc(m * sizeof *L->rk), L->rkd = malloc(m * sizeof *L->rkd), L->rrest = malloc(m * sizeof *L->rrest);
    L->gk = malloc(m * sizeof *L->gk), L->gkd = malloc(m * sizeof *L->gkd), L->grest = malloc(m * sizeof *L->grest);
    uint8_t *seen = calloc(2 * m, 1);
    bool ok = L->rk && L->rkd && L->rrest && L->gk && L->gkd && L->grest && seen;
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
    /* Bands of an eighth of parallel_min (at least SPN_BLOCK) particles:
     * enough of them for a static schedule to share out evenly, few enough
     * that the radials computed twice at their edges cost nothing. */
    const uint32_t n = L->radials, bsize = w->def.parallel_min / 8 > SPN_BLOCK ? w->def.parallel_min / 8 : SPN_BLOCK;
    const uint32_t rows = (bsize + n - 1) / n;
    if (L->band_rows != rows) {
        free(L->cut), free(L->partial);
        L->band_rows = rows;
        L->nbands = (L->rings + rows - 1) / rows;
        L->cut = malloc((size_t)L->nbands * 3 * n * sizeof *L->cut);
        L->partial = malloc((size_t)L->nbands * L_NSUMS * sizeof *L->partial);
        if (!L->cut || !L->partial) {
            L->band_rows = 0;
            return false;
        }
    }
    if (L->nws < threads) {
        double **ws = realloc(L->ws, (size_t)threads * sizeof *ws);
        if (!ws) return false;
        L->ws = ws;
        L->stride = ((size_t)n + 7) & ~(size_t)7;
        for (; L->nws < threads; L->nws++) {
            L->ws[L->nws] = malloc(WS_COUNT * L->stride * sizeof **L->ws);
            if (!L->ws[L->nws]) return false;
        }
    }
    return true;
}

/* ---- the sweep ---- */

/* The hub: its radials (ring 0's radial forces, on the hub as inner end, in
 * radial order), then its update. */
static void hub(const lat_args *a, double *const *rad, double (*acc)[LANES])
{
    const uint32_t n = a->L->radials;
    const double m = a->mass[0], dm = a->drag * m;
    spn_vec3 xh, vh;
    state_of(a, 0, &xh, &vh);
    double f[3] = {m * a->g.x - dm * vh.x, m * a->g.y - dm * vh.y, m * a->g.z - dm * vh.z};
    for (uint32_t i = 0; i < n; i++) f[0] += rad[0][i], f[1] += rad[1][i], f[2] += rad[2][i];
    double X[3] = {xh.x, xh.y, xh.z}, V[3] = {vh.x, vh.y, vh.z};
    double T[3], Bh[6] = {0};
    double *Xp[3] = {X, X + 1, X + 2}, *Vp[3] = {V, V + 1, V + 2}, *Fp[3] = {f, f + 1, f + 2};
    double *Tp[3] = {T, T + 1, T + 2}, *Bp[6] = {Bh, Bh + 1, Bh + 2, Bh + 3, Bh + 4, Bh + 5};
    update(a, 0, 1, Xp, Vp, Fp, Tp, Bp, acc);
}

/* Radial springs into band b's first row, from the state before the step. */
SPN__KERNEL static void cut_pass(const lat_args *a, double *ws, uint32_t b)
{
    const spn__lattice *L = a->L;
    const uint32_t n = L->radials, j = b * L->band_rows;
    const size_t st = L->stride;
    double *X[2][3], *V[2][3], *f[3];
    for (int r = 0; r < 2; r++) rows_of(ws, st, WS_X, r, X[r]), rows_of(ws, st, WS_V, r, V[r]);
    for (int c = 0; c < 3; c++) f[c] = L->cut + ((size_t)b * 3 + c) * n;
    load_row(a, j - 1, X[0], V[0]);
    load_row(a, j, X[1], V[1]);
    double acc_e[LANES] = {0}, acc_p[LANES] = {0};
    springs_rows(n, X[0], V[0], X[1], V[1], 0, 0, L->rk + (size_t)j * n, L->rkd + (size_t)j * n,
                 L->rrest + (size_t)j * n, f, 0, ws + (size_t)WS_E * st, ws + (size_t)WS_P * st, acc_e, acc_p);
    double *p = L->partial + (size_t)b * L_NSUMS;
    p[L_ELASTIC] = lane_total(acc_e), p[L_DAMP] = lane_total(acc_p);
}

/* Sweep band b (see the file comment). */
SPN__KERNEL static void band_pass(const lat_args *a, double *ws, uint32_t b)
{
    const spn__lattice *L = a->L;
    const uint32_t n = L->radials, lo = b * L->band_rows;
    const uint32_t hi = lo + L->band_rows < L->rings ? lo + L->band_rows : L->rings;
    const size_t st = L->stride;
    double *X[2][3], *V[2][3], *RAD[2][3], *RING[2][3], *F[3];
    for (int r = 0; r < 2; r++) {
        rows_of(ws, st, WS_X, r, X[r]), rows_of(ws, st, WS_V, r, V[r]);
        rows_of(ws, st, WS_RAD, r, RAD[r]), rows_of(ws, st, WS_RING, r, RING[r]);
    }
    rows_of(ws, st, WS_F, 0, F);
    double *e = ws + (size_t)WS_E * st, *p = ws + (size_t)WS_P * st;
    double *t[3] = {e, p, ws + (size_t)WS_Q * st}, *B[6];
    for (int c = 0; c < 6; c++) B[c] = ws + (size_t)(WS_B + c) * st;
    double acc_e[LANES] = {0}, acc_p[LANES] = {0}, acc[L_NSUMS][LANES] = {{0}};
    double *cut[3], *next_cut[3];
    for (int c = 0; c < 3; c++) {
        cut[c] = L->cut + ((size_t)b * 3 + c) * n;
        next_cut[c] = L->cut + ((size_t)(b + 1) * 3 + c) * n;
    }
    int cur = 0;
    double **rad_cur = NULL, **rad_prev = NULL;
    for (uint32_t j = lo; j < hi; j++, cur ^= 1) {
        const int prev = cur ^ 1;
        const size_t s0 = (size_t)j * n;
        load_row(a, j, X[cur], V[cur]);
        if (j == lo && j > 0) {
            rad_cur = cut; /* computed by cut_pass; its sums are in the band's partial */
        } else if (j == 0) {
            spn_vec3 xh, vh;
            state_of(a, 0, &xh, &vh);
            for (uint32_t i = 0; i < n; i++) {
                X[prev][0][i] = xh.x, X[prev][1][i] = xh.y, X[prev][2][i] = xh.z;
                V[prev][0][i] = vh.x, V[prev][1][i] = vh.y, V[prev][2][i] = vh.z;
            }
            springs_rows(n, X[prev], V[prev], X[cur], V[cur], 0, 0, L->rk, L->rkd, L->rrest, RAD[cur], 0, e, p,
                         acc_e, acc_p);
            rad_cur = RAD[cur];
            hub(a, rad_cur, acc);
        } else {
            springs_rows(n, X[prev], V[prev], X[cur], V[cur], 0, 0, L->rk + s0, L->rkd + s0, L->rrest + s0,
                         RAD[cur], 0, e, p, acc_e, acc_p);
            rad_cur = RAD[cur];
        }
        springs_rows(n - 1, X[cur], V[cur], X[cur], V[cur], 0, 1, L->gk + s0, L->gkd + s0, L->grest + s0,
                     RING[cur], 0, e, p, acc_e, acc_p);
        springs_rows(1, X[cur], V[cur], X[cur], V[cur], 0, n - 1, L->gk + s0 + n - 1, L->gkd + s0 + n - 1,
                     L->grest + s0 + n - 1, RING[cur], n - 1, e, p, acc_e, acc_p);
        if (j > lo) {
            const size_t q0 = 1 + (size_t)(j - 1) * n;
            finish_row(a, q0, n, X[prev], V[prev], rad_prev, RING[prev], (const double *const *)rad_cur, F, t, B, acc);
        }
        rad_prev = rad_cur;
    }
    const int last = cur ^ 1;
    const size_t q0 = 1 + (size_t)(hi - 1) * n;
    finish_row(a, q0, n, X[last], V[last], rad_prev, RING[last],
               hi < L->rings ? (const double *const *)next_cut : NULL, F, t, B, acc);
    store_band_sums(L->partial + (size_t)b * L_NSUMS, b == 0, acc_e, acc_p, acc);
}

/* One force evaluation and update over the whole lattice; sums into sum[]. */
static void sweep(spn_world *w, const lat_args *a, int threads, double *sum)
{
    spn__lattice *L = w->lat;
    const uint32_t nb = L->nbands;
#pragma omp parallel num_threads(threads)
    {
        double *ws = L->ws[spn__thread_num()];
#pragma omp for schedule(static)
        for (uint32_t b = 1; b < nb; b++) cut_pass(a, ws, b);
#pragma omp for schedule(static)
        for (uint32_t b = 0; b < nb; b++) band_pass(a, ws, b);
    }
    for (int k = 0; k < L_NSUMS; k++) sum[k] = 0;
    for (uint32_t b = 0; b < nb; b++)
        for (int k = 0; k < L_NSUMS; k++) sum[k] += L->partial[(size_t)b * L_NSUMS + k];
}

static lat_args args_of(spn_world *w)
{
    lat_args a;
    memset(&a, 0, sizeof a);
    a.L = w->lat;
    a.xs = w->x, a.vs = w->v, a.x = w->x, a.v = w->v, a.x0 = w->x0, a.v0 = w->v0;
    a.mass = w->mass, a.inv_mass = w->inv_mass;
    a.g = w->def.gravity, a.drag = w->def.drag;
    a.backup = !w->no_backup;
    return a;
}

static bool applies(const spn_world *w)
{
    /* (hysteresis sets each spring's damping per step in the spring records,
     * which the lattice's slots do not follow) */
    return w->compiled && w->lat && !w->lattice_off && !w->force_fn && !spn__air_active(w) && !w->nhyst;
}

const char *spn_world_step_path(const spn_world *w)
{
    const spn_integrator in = w->def.integrator;
    const bool explicit = in == SPN_INTEGRATOR_EULER || in == SPN_INTEGRATOR_SYMPLECTIC || in == SPN_INTEGRATOR_RK4;
    return explicit && applies(w) ? "lattice" : "general";
}

void spn_world_set_lattice(spn_world *w, bool allow) { w->lattice_off = !allow; }

/* Threads for this world's bands, and the bands ready; 0 when the lattice
 * path does not apply. */
static int ready(spn_world *w)
{
    if (!applies(w)) return 0;
    int threads = spn__threads(w, w->np);
    if (!prepare(w, threads)) return 0;
    if ((uint32_t)threads > w->lat->nbands) threads = (int)w->lat->nbands;
    return threads < 1 ? 1 : threads;
}

/* float32 inside spn_world_advance's replayable runs only (and for the step
 * it retakes after a blow-up, so that the retake fails as the run did): a
 * lone step would load and write back the float32 state around itself,
 * slower than the float64 step (5k web: 5.9 against 5.2 CPU ns). */
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
    if (float32(w)) return spn__lat32_explicit(w, threads, dt, symplectic, r);
    spn__lattice_sync(w);
    lat_args a = args_of(w);
    a.dt = dt;
    a.mode = symplectic ? MODE_SYMPLECTIC : MODE_EULER;
    double sum[L_NSUMS];
    sweep(w, &a, threads, sum);
    r->elastic = sum[L_ELASTIC];
    r->e_before = 0.5 * sum[L_MV2] + sum[L_ELASTIC];
    r->gain_kp = sum[L_GAIN];
    r->work = 0;
    r->dissipated = dt * (sum[L_DAMP] + w->def.drag * sum[L_MV2]);
    r->kinetic = 0.5 * sum[L_MVN2];
    return true;
}

/* RK4 as in explicit.c (four fused passes), each pass one lattice sweep. */
bool spn__lattice_rk4(spn_world *w, double dt, spn__step_result *r)
{
    const int threads = ready(w);
    if (!threads) {
        spn__lattice_sync(w);
        return false;
    }
    if (float32(w)) return spn__lat32_rk4(w, threads, dt, r);
    spn__lattice_sync(w);
    spn__lattice *L = w->lat;
    const size_t np = w->np;
    if (!L->rk4 && !(L->rk4 = calloc(12 * np, sizeof *L->rk4))) return false;
    static const double weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5, 0.5, 1};
    lat_args a = args_of(w);
    for (int c = 0; c < 3; c++) {
        a.xt[c] = L->rk4 + c * np, a.vt[c] = L->rk4 + (3 + c) * np;
        a.ax[c] = L->rk4 + (6 + c) * np, a.av[c] = L->rk4 + (9 + c) * np;
    }
    a.dt = dt;
    double damp = 0, sum[L_NSUMS];
    for (int stage = 0; stage < 4; stage++) {
        a.stage = stage;
        a.mode = stage < 3 ? MODE_RK4_STAGE : MODE_RK4_LAST;
        for (int c = 0; c < 3; c++) a.sx[c] = stage ? a.xt[c] : NULL, a.sv[c] = stage ? a.vt[c] : NULL;
        a.weight = weight[stage];
        a.h_next = stage < 3 ? frac[stage + 1] * dt : 0;
        sweep(w, &a, threads, sum);
        if (stage == 0) {
            r->e_before = 0.5 * sum[L_MV2] + sum[L_ELASTIC];
            r->elastic = sum[L_ELASTIC];
        }
        damp += weight[stage] * (sum[L_DAMP] + w->def.drag * sum[L_MV2]);
    }
    r->gain_kp = sum[L_GAIN];
    r->kinetic = 0.5 * sum[L_MVN2];
    r->work = 0;
    r->dissipated = dt / 6 * damp;
    return true;
}

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
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Per-band sums: elastic energy, spring damping power, sum m v^2 at the
 * evaluated state, energy gain of the update, sum m v^2 after it. */
enum { L_ELASTIC, L_DAMP, L_MV2, L_GAIN, L_MVN2, L_NSUMS };
#define LANES 8
#define LAT_INLINE static inline __attribute__((always_inline))
/* The sweep is also compiled for AVX-512 and AVX2, chosen when the program
 * loads (as SPN__KERNEL; no FMA, every operation correctly rounded, so all
 * versions give the same bits). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(SPN_NO_CLONES)
#define LAT_KERNEL __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define LAT_KERNEL
#endif

/* Arrays of one thread's workspace, each N doubles (see ws_array). */
enum {
    WS_X = 0,     /* 2 rows x 3: pre-step positions of the previous and current row */
    WS_V = 6,     /* 2 rows x 3: velocities */
    WS_RAD = 12,  /* 2 rows x 3: radial force on the inner end */
    WS_RING = 18, /* 2 rows x 3: ring force on the lower end */
    WS_F = 24,    /* 3: assembled force on the row being moved */
    WS_E = 27,    /* per-spring elastic energy (scratch) */
    WS_P = 28,    /* per-spring damping power (scratch) */
    WS_Q = 29,    /* a third per-particle sum term (scratch) */
    WS_B = 30,    /* 6: RK4's base state x, v of the row being moved, SoA */
    WS_COUNT = 36
};

struct spn__lattice {
    uint32_t rings, radials;
    double *rk, *rkd, *rrest; /* radial slots: ring * N + i, (ring - 1, i) -> (ring, i) */
    double *gk, *gkd, *grest; /* ring slots: ring * N + i, (i, i + 1); i = N - 1: (0, N - 1) */
    uint32_t band_rows, nbands;
    double *cut;     /* per band: 3 x N radial forces into its first row (band 0 unused) */
    double *partial; /* per band: L_NSUMS */
    int nws;         /* workspaces allocated (one per thread) */
    double **ws;
    size_t stride;   /* doubles per workspace array (N rounded up) */
    double *rk4;     /* RK4: 12 arrays of np (xt, vt, ax, av by component), on first use */
};

/* ---- building ---- */

static void lattice_free(spn__lattice *L)
{
    if (!L) return;
    free(L->rk), free(L->rkd), free(L->rrest), free(L->gk), free(L->gkd), free(L->grest);
    free(L->cut), free(L->partial), free(L->rk4);
    for (int t = 0; t < L->nws; t++) free(L->ws[t]);
    free(L->ws);
    free(L);
}

void spn__lattice_drop(spn_world *w)
{
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

/* ---- the kernels ---- */

/* What an update does with a row once its forces are complete. */
enum { MODE_EULER, MODE_SYMPLECTIC, MODE_RK4_STAGE, MODE_RK4_LAST };

typedef struct lat_args {
    const spn__lattice *L;
    const spn_vec3 *xs, *vs;          /* the state the forces are evaluated at */
    spn_vec3 *x, *v, *x0, *v0;        /* the world's state (and its backup) */
    const double *sx[3], *sv[3];      /* RK4: the state as SoA arrays (sx[0] NULL: xs, vs) */
    double *xt[3], *vt[3], *ax[3], *av[3]; /* RK4: trial state and weighted sums, SoA */
    const double *mass, *inv_mass;
    spn_vec3 g;
    double drag, dt, h_next, weight;
    int mode, stage;
    bool backup;
} lat_args;

LAT_INLINE void lane_add(double *restrict acc, const double *restrict e, uint32_t n)
{
    uint32_t i = 0;
    for (; i + LANES <= n; i += LANES)
        for (int l = 0; l < LANES; l++) acc[l] += e[i + l];
    for (; i < n; i++) acc[i % LANES] += e[i];
}

LAT_INLINE double lane_total(const double *acc)
{
    return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

/* Springs j = 0..n-1 from (a[j]) to (b[j]), SoA: force on end a into f, the
 * elastic energy and damping power into e, p. The arithmetic of chunk_forces
 * (same bits): a spring is off (no force) at zero length or when slack and
 * tension-only, and then 1/len is replaced by 0 and k by 0, which is what
 * chunk_forces' 0/1 factors give, with selects instead of products. */
LAT_INLINE void springs(uint32_t n, const double *restrict axp, const double *restrict ayp,
                        const double *restrict azp, const double *restrict bxp, const double *restrict byp,
                        const double *restrict bzp, const double *restrict avx, const double *restrict avy,
                        const double *restrict avz, const double *restrict bvx, const double *restrict bvy,
                        const double *restrict bvz, const double *restrict kk, const double *restrict kkd,
                        const double *restrict rr, double *restrict fx, double *restrict fy, double *restrict fz,
                        double *restrict e, double *restrict p)
{
    for (uint32_t j = 0; j < n; j++) {
        const double lx = axp[j] - bxp[j], ly = ayp[j] - byp[j], lz = azp[j] - bzp[j];
        const double ux = avx[j] - bvx[j], uy = avy[j] - bvy[j], uz = avz[j] - bvz[j];
        const double d2 = lx * lx + ly * ly + lz * lz;
        const double len = sqrt(d2);
        const double rs = rr[j];
        const double stretch = len - fabs(rs);
        const bool on = len > 0 && !(stretch < 0 && rs < 0);
        const double inv = on ? 1 / len : 0;
        const double rate = (ux * lx + uy * ly + uz * lz) * inv;
        const double k = on ? kk[j] : 0, kd = kkd[j];
        const double mag = k * stretch + kd * rate;
        const double s = -mag * inv;
        e[j] = 0.5 * k * stretch * stretch;
        p[j] = kd * rate * rate;
        fx[j] = s * lx, fy[j] = s * ly, fz[j] = s * lz;
    }
}

/* Springs from row buffers a to b (each 3 arrays of stride st) with
 * parameters k, kd, rest, forces into f; sums into acc. */
LAT_INLINE void springs_rows(uint32_t n, double *const *ax, double *const *av, double *const *bx,
                             double *const *bv, size_t off_a, size_t off_b, const double *k, const double *kd,
                             const double *rest, double *const *f, size_t off_f, double *e, double *p,
                             double *acc_e, double *acc_p)
{
    springs(n, ax[0] + off_a, ax[1] + off_a, ax[2] + off_a, bx[0] + off_b, bx[1] + off_b, bx[2] + off_b,
            av[0] + off_a, av[1] + off_a, av[2] + off_a, bv[0] + off_b, bv[1] + off_b, bv[2] + off_b, k, kd, rest,
            f[0] + off_f, f[1] + off_f, f[2] + off_f, e, p);
    lane_add(acc_e, e, n);
    lane_add(acc_p, p, n);
}

/* n particles' state (AoS) into SoA buffers. Restrict parameters, not
 * restrict locals: GCC 12 vectorises the strided accesses only then. */
LAT_INLINE void deinterleave(uint32_t n, const spn_vec3 *restrict xs, const spn_vec3 *restrict vs,
                             double *restrict x0, double *restrict x1, double *restrict x2, double *restrict v0,
                             double *restrict v1, double *restrict v2)
{
    for (uint32_t i = 0; i < n; i++) {
        x0[i] = xs[i].x, x1[i] = xs[i].y, x2[i] = xs[i].z;
        v0[i] = vs[i].x, v1[i] = vs[i].y, v2[i] = vs[i].z;
    }
}

/* Row j of the evaluated state into SoA buffers. */
LAT_INLINE void load_row(const lat_args *a, uint32_t j, double *const *X, double *const *V)
{
    const uint32_t n = a->L->radials;
    const size_t p0 = 1 + (size_t)j * n;
    if (!a->sx[0]) {
        deinterleave(n, a->xs + p0, a->vs + p0, X[0], X[1], X[2], V[0], V[1], V[2]);
        return;
    }
    for (int c = 0; c < 3; c++) {
        memcpy(X[c], a->sx[c] + p0, n * sizeof *X[c]);
        memcpy(V[c], a->sv[c] + p0, n * sizeof *V[c]);
    }
}

/* Particle p of the evaluated state. */
static inline void state_of(const lat_args *a, size_t p, spn_vec3 *x, spn_vec3 *v)
{
    if (!a->sx[0]) {
        *x = a->xs[p], *v = a->vs[p];
        return;
    }
    *x = spn_v3(a->sx[0][p], a->sx[1][p], a->sx[2][p]);
    *v = spn_v3(a->sv[0][p], a->sv[1][p], a->sv[2][p]);
}

/* The three updates below move particles whose state at the evaluation is
 * (X, V) (SoA) and whose complete force is F. Fixed particles are selected
 * out, not skipped, so the loops vectorise; the per-particle terms of the
 * sums go to t_mv2, t_gain, t_mvn2. */

/* Euler or symplectic Euler: x, v in place (and the backup x0, v0). */
LAT_INLINE void update_explicit(uint32_t n, bool sym, bool backup, double dt, spn_vec3 g,
                                const double *restrict mass, const double *restrict inv_mass,
                                const double *restrict Xx, const double *restrict Xy, const double *restrict Xz,
                                const double *restrict Vx, const double *restrict Vy, const double *restrict Vz,
                                const double *restrict Fx, const double *restrict Fy, const double *restrict Fz,
                                spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0,
                                spn_vec3 *restrict v0, double *restrict t_mv2, double *restrict t_gain,
                                double *restrict t_mvn2)
{
    if (backup)
        for (uint32_t i = 0; i < n; i++) {
            x0[i].x = Xx[i], x0[i].y = Xy[i], x0[i].z = Xz[i];
            v0[i].x = Vx[i], v0[i].y = Vy[i], v0[i].z = Vz[i];
        }
    for (uint32_t i = 0; i < n; i++) {
        const double im = inv_mass[i], s = dt * im;
        const bool fr = im != 0;
        const double mf = fr ? mass[i] : 0;
        const double vx = Vx[i], vy = Vy[i], vz = Vz[i], xx = Xx[i], xy = Xy[i], xz = Xz[i];
        const double nx = vx + Fx[i] * s, ny = vy + Fy[i] * s, nz = vz + Fz[i] * s;
        const double dx = (sym ? nx : vx) * dt, dy = (sym ? ny : vy) * dt, dz = (sym ? nz : vz) * dt;
        x[i].x = fr ? xx + dx : xx, x[i].y = fr ? xy + dy : xy, x[i].z = fr ? xz + dz : xz;
        v[i].x = fr ? nx : vx, v[i].y = fr ? ny : vy, v[i].z = fr ? nz : vz;
        t_mv2[i] = mf * (vx * vx + vy * vy + vz * vz);
        t_mvn2[i] = mf * (nx * nx + ny * ny + nz * nz);
        t_gain[i] = mf * (0.5 * ((nx - vx) * (nx + vx) + (ny - vy) * (ny + vy) + (nz - vz) * (nz + vz)) -
                          (g.x * dx + g.y * dy + g.z * dz));
    }
}

/* One particle of an Euler or symplectic Euler row: update_explicit's body,
 * on values (the loops below do the loads and stores, so they vectorise). */
typedef struct moved {
    double x[3], v[3], mv2, gain, mvn2;
} moved;

LAT_INLINE moved explicit_one(double fx, double fy, double fz, double im, double m, double xx, double xy, double xz,
                              double vx, double vy, double vz, bool sym, double dt, spn_vec3 g)
{
    moved o;
    const double s = dt * im;
    const bool fr = im != 0;
    const double mf = fr ? m : 0;
    const double nx = vx + fx * s, ny = vy + fy * s, nz = vz + fz * s;
    const double dx = (sym ? nx : vx) * dt, dy = (sym ? ny : vy) * dt, dz = (sym ? nz : vz) * dt;
    o.x[0] = fr ? xx + dx : xx, o.x[1] = fr ? xy + dy : xy, o.x[2] = fr ? xz + dz : xz;
    o.v[0] = fr ? nx : vx, o.v[1] = fr ? ny : vy, o.v[2] = fr ? nz : vz;
    o.mv2 = mf * (vx * vx + vy * vy + vz * vz);
    o.mvn2 = mf * (nx * nx + ny * ny + nz * nz);
    o.gain = mf * (0.5 * ((nx - vx) * (nx + vx) + (ny - vy) * (ny + vy) + (nz - vz) * (nz + vz)) -
                   (g.x * dx + g.y * dy + g.z * dz));
    return o;
}

#define STORE_MOVED(i, o)                                                                                       \
    do {                                                                                                        \
        x[i].x = (o).x[0], x[i].y = (o).x[1], x[i].z = (o).x[2];                                                \
        v[i].x = (o).v[0], v[i].y = (o).v[1], v[i].z = (o).v[2];                                                \
        t_mv2[i] = (o).mv2, t_gain[i] = (o).gain, t_mvn2[i] = (o).mvn2;                                         \
    } while (0)

/* An Euler or symplectic Euler row with the force assembled on the fly (as
 * assemble_c, same order) instead of through F: one pass, not four. */
LAT_INLINE void explicit_row(uint32_t n, bool sym, bool backup, double dt, spn_vec3 g, double drag,
                             const double *restrict mass, const double *restrict inv_mass,
                             const double *restrict Xx, const double *restrict Xy, const double *restrict Xz,
                             const double *restrict Vx, const double *restrict Vy, const double *restrict Vz,
                             const double *restrict ix, const double *restrict iy, const double *restrict iz,
                             const double *restrict rx, const double *restrict ry, const double *restrict rz,
                             const double *restrict ox, const double *restrict oy, const double *restrict oz,
                             spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0,
                             spn_vec3 *restrict v0, double *restrict t_mv2, double *restrict t_gain,
                             double *restrict t_mvn2)
{
    if (backup)
        for (uint32_t i = 0; i < n; i++) {
            x0[i].x = Xx[i], x0[i].y = Xy[i], x0[i].z = Xz[i];
            v0[i].x = Vx[i], v0[i].y = Vy[i], v0[i].z = Vz[i];
        }
    const uint32_t l = n - 1;
    double e0[3], el[3];
    const double gc[3] = {g.x, g.y, g.z};
    const double *V[3] = {Vx, Vy, Vz}, *I[3] = {ix, iy, iz}, *R[3] = {rx, ry, rz}, *O[3] = {ox, oy, oz};
    for (int c = 0; c < 3; c++) {
        double f0 = mass[0] * gc[c] - (drag * mass[0]) * V[c][0], fl = mass[l] * gc[c] - (drag * mass[l]) * V[c][l];
        if (ox) f0 += O[c][0], fl += O[c][l];
        e0[c] = ((f0 + R[c][0]) + R[c][l]) - I[c][0];
        el[c] = ((fl - I[c][l]) - R[c][l]) - R[c][l - 1];
    }
    if (ox)
        for (uint32_t i = 1; i < l; i++) {
            const double m = mass[i], dm = drag * m;
            const double fx = ((((m * g.x - dm * Vx[i]) + ox[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const double fy = ((((m * g.y - dm * Vy[i]) + oy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const double fz = ((((m * g.z - dm * Vz[i]) + oz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved o = explicit_one(fx, fy, fz, inv_mass[i], m, Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i], sym, dt, g);
            STORE_MOVED(i, o);
        }
    else
        for (uint32_t i = 1; i < l; i++) {
            const double m = mass[i], dm = drag * m;
            const double fx = (((m * g.x - dm * Vx[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const double fy = (((m * g.y - dm * Vy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const double fz = (((m * g.z - dm * Vz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved o = explicit_one(fx, fy, fz, inv_mass[i], m, Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i], sym, dt, g);
            STORE_MOVED(i, o);
        }
    const uint32_t ends[2] = {0, l};
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        const double *f = k ? el : e0;
        const moved o = explicit_one(f[0], f[1], f[2], inv_mass[i], mass[i], Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i],
                                     sym, dt, g);
        STORE_MOVED(i, o);
    }
}

/* RK4 stage sums: m v^2 of the free particles (no gain or new energy yet). */
LAT_INLINE void rk4_mv2(uint32_t n, const double *restrict mass, const double *restrict inv_mass,
                        const double *restrict Vx, const double *restrict Vy, const double *restrict Vz,
                        double *restrict t_mv2, double *restrict t_gain, double *restrict t_mvn2)
{
    for (uint32_t i = 0; i < n; i++) {
        t_mv2[i] = (inv_mass[i] != 0 ? mass[i] : 0) * (Vx[i] * Vx[i] + Vy[i] * Vy[i] + Vz[i] * Vz[i]);
        t_gain[i] = t_mvn2[i] = 0;
    }
}

/* An RK4 stage but the last: the weighted sums ax, av and the next trial
 * state xt = x + h V, vt = v + h F / m (a fixed particle stays at x, v). */
LAT_INLINE void update_rk4_stage(uint32_t n, bool first, double h, double wgt, const double *restrict mass,
                                 const double *restrict inv_mass, const double *restrict Vc,
                                 const double *restrict Fc, const double *restrict xb, const double *restrict vb,
                                 double *restrict xt, double *restrict vt, double *restrict ax,
                                 double *restrict av)
{
    (void)mass;
    for (uint32_t i = 0; i < n; i++) {
        const double im = inv_mass[i], s = h * im;
        const bool fr = im != 0;
        const double vc = Vc[i], fc = Fc[i], xc = xb[i], wc = vb[i];
        ax[i] = fr ? (first ? vc : ax[i] + vc * wgt) : ax[i];
        av[i] = fr ? (first ? fc : av[i] + fc * wgt) : av[i];
        xt[i] = fr ? xc + vc * h : xc;
        vt[i] = fr ? wc + fc * s : wc;
    }
}

/* The last RK4 stage: x += h/6 (ax + V), v += h/6 (av + F) / m. */
LAT_INLINE void update_rk4_last(uint32_t n, bool backup, double h6, spn_vec3 g, const double *restrict mass,
                                const double *restrict inv_mass, const double *restrict Vx,
                                const double *restrict Vy, const double *restrict Vz, const double *restrict Fx,
                                const double *restrict Fy, const double *restrict Fz, const double *restrict axx,
                                const double *restrict axy, const double *restrict axz, const double *restrict avx,
                                const double *restrict avy, const double *restrict avz, const double *restrict bxx,
                                const double *restrict bxy, const double *restrict bxz, const double *restrict bvx,
                                const double *restrict bvy, const double *restrict bvz, spn_vec3 *restrict x,
                                spn_vec3 *restrict v,
                                spn_vec3 *restrict x0, spn_vec3 *restrict v0, double *restrict t_mv2,
                                double *restrict t_gain, double *restrict t_mvn2)
{
    if (backup) {
        memcpy(x0, x, n * sizeof *x);
        memcpy(v0, v, n * sizeof *v);
    }
    for (uint32_t i = 0; i < n; i++) {
        const double im = inv_mass[i], s = h6 * im;
        const bool fr = im != 0;
        const double mf = fr ? mass[i] : 0;
        const double vx = Vx[i], vy = Vy[i], vz = Vz[i];
        const double xx = bxx[i], xy = bxy[i], xz = bxz[i], wx = bvx[i], wy = bvy[i], wz = bvz[i];
        const double dx = (axx[i] + vx) * h6, dy = (axy[i] + vy) * h6, dz = (axz[i] + vz) * h6;
        const double nx = wx + (avx[i] + Fx[i]) * s, ny = wy + (avy[i] + Fy[i]) * s, nz = wz + (avz[i] + Fz[i]) * s;
        x[i].x = fr ? xx + dx : xx, x[i].y = fr ? xy + dy : xy, x[i].z = fr ? xz + dz : xz;
        v[i].x = fr ? nx : wx, v[i].y = fr ? ny : wy, v[i].z = fr ? nz : wz;
        t_mv2[i] = mf * (vx * vx + vy * vy + vz * vz);
        t_mvn2[i] = mf * (nx * nx + ny * ny + nz * nz);
        t_gain[i] = mf * (0.5 * ((nx - wx) * (nx + wx) + (ny - wy) * (ny + wy) + (nz - wz) * (nz + wz)) -
                          (g.x * dx + g.y * dy + g.z * dz));
    }
}

/* Update particles p0 .. p0+n-1 as the mode says; sums into acc. */
LAT_INLINE void update(const lat_args *a, size_t p0, uint32_t n, double *const *X, double *const *V,
                       double *const *F, double *const *t, double *const *B, double (*acc)[LANES])
{
    const double *mass = a->mass + p0, *inv_mass = a->inv_mass + p0;
    /* RK4 reads the base state x, v: as SoA first (GCC 12 does not vectorise
     * a loop that both reads and writes the interleaved arrays). */
    if (a->mode == MODE_RK4_STAGE || a->mode == MODE_RK4_LAST)
        deinterleave(n, a->x + p0, a->v + p0, B[0], B[1], B[2], B[3], B[4], B[5]);
    switch (a->mode) {
    case MODE_EULER:
    case MODE_SYMPLECTIC:
        update_explicit(n, a->mode == MODE_SYMPLECTIC, a->backup, a->dt, a->g, mass, inv_mass, X[0], X[1], X[2],
                        V[0], V[1], V[2], F[0], F[1], F[2], a->x + p0, a->v + p0, a->x0 + p0, a->v0 + p0, t[0],
                        t[1], t[2]);
        break;
    case MODE_RK4_STAGE:
        /* One component at a time, and the sum term apart: GCC 12 does not
         * vectorise one loop over all those arrays. */
        rk4_mv2(n, mass, inv_mass, V[0], V[1], V[2], t[0], t[1], t[2]);
        /* (three calls, not a loop: GCC 12 does not vectorise an inlined
         * function with restrict parameters inside a loop) */
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[0], F[0], B[0], B[3],
                         a->xt[0] + p0, a->vt[0] + p0, a->ax[0] + p0, a->av[0] + p0);
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[1], F[1], B[1], B[4],
                         a->xt[1] + p0, a->vt[1] + p0, a->ax[1] + p0, a->av[1] + p0);
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[2], F[2], B[2], B[5],
                         a->xt[2] + p0, a->vt[2] + p0, a->ax[2] + p0, a->av[2] + p0);
        break;
    default:
        update_rk4_last(n, a->backup, a->dt / 6, a->g, mass, inv_mass, V[0], V[1], V[2], F[0], F[1], F[2],
                        a->ax[0] + p0, a->ax[1] + p0, a->ax[2] + p0, a->av[0] + p0, a->av[1] + p0, a->av[2] + p0,
                        B[0], B[1], B[2], B[3], B[4], B[5], a->x + p0, a->v + p0, a->x0 + p0, a->v0 + p0, t[0], t[1], t[2]);
    }
    lane_add(acc[L_MV2], t[0], n);
    lane_add(acc[L_GAIN], t[1], n);
    lane_add(acc[L_MVN2], t[2], n);
}

/* The complete force on row q: gravity and drag, then (see the file comment)
 * radial out (ro, NULL on the outermost ring), ring to i + 1 and wrap as the
 * lower end, radial in (ri), wrap and ring from i - 1 as the upper end. */
LAT_INLINE void assemble_c(uint32_t n, double gc, double drag, const double *restrict mass,
                           const double *restrict vc, const double *restrict in, const double *restrict ring,
                           const double *restrict out, double *restrict f)
{
    const double wrap = ring[n - 1];
    if (out)
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = ((((mass[i] * gc - (drag * mass[i]) * vc[i]) + out[i]) + ring[i]) - in[i]) - ring[i - 1];
    else
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = (((mass[i] * gc - (drag * mass[i]) * vc[i]) + ring[i]) - in[i]) - ring[i - 1];
    const uint32_t l = n - 1;
    double f0 = mass[0] * gc - (drag * mass[0]) * vc[0], fl = mass[l] * gc - (drag * mass[l]) * vc[l];
    if (out) f0 += out[0], fl += out[l];
    f[0] = ((f0 + ring[0]) + wrap) - in[0];
    f[l] = ((fl - in[l]) - wrap) - ring[l - 1];
}

LAT_INLINE void assemble(const lat_args *a, size_t p0, uint32_t n, double *const *V, double *const *ri,
                         double *const *rg, const double *const *ro, double *const *F)
{
    const double g[3] = {a->g.x, a->g.y, a->g.z};
    for (int c = 0; c < 3; c++)
        assemble_c(n, g[c], a->drag, a->mass + p0, V[c], ri[c], rg[c], ro ? ro[c] : NULL, F[c]);
}

/* Row q (particles p0 ..) complete: its force, then its update. */
LAT_INLINE void finish_row(const lat_args *a, size_t p0, uint32_t n, double *const *X, double *const *V,
                           double *const *ri, double *const *rg, const double *const *ro, double *const *F,
                           double *const *t, double *const *B, double (*acc)[LANES])
{
    if (a->mode == MODE_EULER || a->mode == MODE_SYMPLECTIC) {
        explicit_row(n, a->mode == MODE_SYMPLECTIC, a->backup, a->dt, a->g, a->drag, a->mass + p0,
                     a->inv_mass + p0, X[0], X[1], X[2], V[0], V[1], V[2], ri[0], ri[1], ri[2], rg[0], rg[1], rg[2],
                     ro ? ro[0] : NULL, ro ? ro[1] : NULL, ro ? ro[2] : NULL, a->x + p0, a->v + p0, a->x0 + p0,
                     a->v0 + p0, t[0], t[1], t[2]);
        lane_add(acc[L_MV2], t[0], n);
        lane_add(acc[L_GAIN], t[1], n);
        lane_add(acc[L_MVN2], t[2], n);
        return;
    }
    assemble(a, p0, n, V, ri, rg, ro, F);
    update(a, p0, n, X, V, F, t, B, acc);
}

LAT_INLINE void rows_of(double *ws, size_t st, int base, int row, double **out)
{
    for (int c = 0; c < 3; c++) out[c] = ws + (size_t)(base + 3 * row + c) * st;
}

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
LAT_KERNEL static void cut_pass(const lat_args *a, double *ws, uint32_t b)
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
LAT_KERNEL static void band_pass(const lat_args *a, double *ws, uint32_t b)
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
    double *out = L->partial + (size_t)b * L_NSUMS;
    if (b == 0) out[L_ELASTIC] = out[L_DAMP] = 0;
    out[L_ELASTIC] += lane_total(acc_e), out[L_DAMP] += lane_total(acc_p);
    out[L_MV2] = lane_total(acc[L_MV2]), out[L_GAIN] = lane_total(acc[L_GAIN]), out[L_MVN2] = lane_total(acc[L_MVN2]);
}

static int thread_id(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* One force evaluation and update over the whole lattice; sums into sum[]. */
static void sweep(spn_world *w, const lat_args *a, int threads, double *sum)
{
    spn__lattice *L = w->lat;
    const uint32_t nb = L->nbands;
#pragma omp parallel num_threads(threads)
    {
        double *ws = L->ws[thread_id()];
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
    return w->compiled && w->lat && !w->lattice_off && !w->force_fn && !spn__air_active(w);
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

bool spn__lattice_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r)
{
    const int threads = ready(w);
    if (!threads) return false;
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
    if (!threads) return false;
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

/* The cyclic preconditioner: the equilibrium solver's Newton systems on a
 * hub + rings x radials web, solved exactly for the web's rotational
 * average by a Fourier transform around the rings.
 *
 * The idea. Number the web as lattice.c does (particle 0 the hub, 1 + j N +
 * i ring j radial i) and describe each ring particle's displacement in its
 * own frame: along its radial, along its ring, out of the plane. In those
 * frames a web that is the same under a turn by 2 pi / N has a stiffness
 * matrix that does not change when every index i moves on by one: it is
 * block circulant around the rings, so the discrete Fourier transform along
 * i splits it into N independent systems, one per angular mode k, each block
 * tridiagonal from ring to ring (3x3 complex Hermitian blocks). The hub's
 * displacement couples only to modes 0 (out of plane) and +-1 (in plane);
 * it is eliminated by a 3x3 Schur complement. The whole solve is a transform
 * forward, a block Thomas sweep per mode, a transform back: O(n log N), and
 * exact for such a web.
 *
 * A real web is not exactly symmetric (gravity in its plane pulls its upper
 * threads tighter than its lower ones; a load off the hub bends it
 * unevenly). The preconditioner uses the group average of the actual
 * Hessian K: the mean over the N turns g of U_g^T K U_g, U_g the turn in
 * the local frames. Block by block that is: every ring's diagonal, ring and
 * radial blocks in local frames averaged over i, the hub's blocks averaged
 * likewise. An average of symmetric positive definite matrices conjugated by
 * orthogonal ones is symmetric positive definite, so M is a valid
 * preconditioner for CG on the true system whatever the web's shape; how
 * good it is depends on how close the web is to its average. CG on K then
 * corrects the difference. spn__cyc_asymmetry is the blocks' spread about
 * their ring means relative to the blocks, a diagnostic: the axial
 * stiffness dominates it, so it says little of the soft modes that set CG's
 * count (a prey of 4 T0: 0.02, and twice the CG of a symmetric load).
 *
 * Layout of a solve (N radials, Q free rings, B = 3 Q real sequences):
 *  1. r in local frames, transposed to rows i of B numbers; pairs of real
 *     sequences packed as one complex one (re: even, im: odd);
 *  2. the batched FFT along i (fft.c), columns split between threads;
 *  3. the pairs separated into the modes k = 0..N/2 of each real sequence
 *     (the rest are their conjugates), scaled by 1 / N, rows k of B;
 *  4. per mode, block Thomas over the rings (factors from setup), then
 *     the hub's correction of modes 0 and 1;
 *  5. the pairs packed again for all k, the FFT back, rotated to global.
 * Every step writes its own outputs in a fixed order: the same bits on any
 * thread count. Fixed rings are left out (each ring is free or fixed as a
 * whole, or the web is not taken); a fixed hub decouples. */
#include "core/big_alloc.h"
#include "equilibrium_internal.h"
#include "fft.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PAR_MIN 32768u
#define NONE UINT32_MAX

struct spn__cyc {
    uint32_t N, Q, K; /* radials, free rings, modes kept (N / 2 + 1) */
    uint32_t B, Bc;   /* real sequences 3 Q, complex ones ceil(B / 2) */
    int32_t hub;      /* the hub's local id, or -1 when it is fixed */
    bool hub_coupled; /* the hub free and ring 0 free: modes 0 and 1 carry it */
    uint32_t *node;   /* Q N: local id of free ring q, radial i */
    uint32_t *ring_s; /* Q N: the spring (q, i) -> (q, i + 1) */
    uint32_t *rad_s;  /* Q N: the spring (q, i) -> (q + 1, i), or NONE when ring q + 1 is not the next free one */
    uint32_t *hub_s;  /* N: the spring hub -> (0, i), when hub_coupled */
    uint32_t *sent;   /* per spring: its adjacency entry at its free end a (matrices kept in e->offd) */
    double base[9];   /* columns e1, e2, n: the frame of radial 0 */
    double *cs, *sn;  /* N: cos, sin of 2 pi i / N */
    /* the averaged blocks (row-major 3x3) */
    double *dbar, *gbar, *cbar; /* Q each: diagonal, ring (to i + 1), radial (to q + 1) */
    double hdiag[9], hcoup[9];  /* hub: diagonal in the base frame, coupling S (ring 0 frames) */
    /* factors: per mode k and ring q, Gamma^-1 as 9 numbers (3 real
     * diagonal entries, then re, im of 01, 02, 12) */
    double *gam;
    double *zhub;    /* modes 0, 1: A_m^-1 e_0 F_m, Q x 3 rows of 3 complex (re, im) */
    double schur[6]; /* the hub's Schur complement, inverted (symmetric 6-layout) */
    double asym;     /* spread of the last factored system about its average */
    spn__fft *fft;
    /* work */
    double *zr, *zi, *tr, *ti; /* N Bc each; the transform's scratch tr, ti spn__fft_scratch_rows Bc */
    double *xr, *xi;           /* K B each */
    int threads;
};

static inline int team_of(const spn__cyc *C, const spn__eq *e) { return e->n < PAR_MIN ? 1 : C->threads; }

/* ---- recognising the lattice ---- */

/* Slot of the spring between world particles a and b of a web of n radials
 * and `rings` rings: 0 ring, 1 radial (hub radials included), -1 none; *j,
 * *i the lower end's ring and radial (ring -1: the hub). */
static int slot_of(uint32_t n, uint32_t rings, uint32_t a, uint32_t b, int64_t *j, uint32_t *i)
{
    if (a > b) {
        uint32_t t = a;
        a = b;
        b = t;
    }
    if (a == 0) {
        if (b < 1 || b > n) return -1;
        *j = -1, *i = b - 1;
        return 1;
    }
    const uint32_t ja = (a - 1) / n, ia = (a - 1) % n;
    *j = ja, *i = ia;
    if (b - a == n && ja + 1 < rings) return 1;
    if (b - a == 1 && ia + 1 < n) return 0;
    if (ia == 0 && b - a == n - 1) {
        *i = n - 1;
        return 0;
    }
    return -1;
}

void spn__cyc_free(spn__cyc *C)
{
    if (!C) return;
    free(C->sent), free(C->node), free(C->ring_s), free(C->rad_s), free(C->hub_s), free(C->cs), free(C->sn);
    free(C->dbar), free(C->gbar), free(C->cbar), free(C->gam), free(C->zhub);
    free(C->zr), free(C->zi), free(C->tr), free(C->ti), free(C->xr), free(C->xi);
    spn__fft_free(C->fft);
    free(C);
}

static void normalise(double *v)
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
}

/* The base frame from ring q's particles: the centre their mean, the normal
 * their turning sense (so that i grows anticlockwise about it), e1 towards
 * radial 0. false when the ring is degenerate. */
static bool base_frame(spn__cyc *C, const spn__eq *e, uint32_t q)
{
    const uint32_t N = C->N;
    double c[3] = {0, 0, 0}, nrm[3] = {0, 0, 0};
    for (uint32_t i = 0; i < N; i++)
        for (int a = 0; a < 3; a++)
            c[a] += e->x[3 * (size_t)C->node[(size_t)q * N + i] + a] / N;
    for (uint32_t i = 0; i < N; i++) {
        const double *p = e->x + 3 * (size_t)C->node[(size_t)q * N + i];
        const double *s = e->x + 3 * (size_t)C->node[(size_t)q * N + (i + 1) % N];
        const double u[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]}, v[3] = {s[0] - c[0], s[1] - c[1], s[2] - c[2]};
        nrm[0] += u[1] * v[2] - u[2] * v[1], nrm[1] += u[2] * v[0] - u[0] * v[2], nrm[2] += u[0] * v[1] - u[1] * v[0];
    }
    normalise(nrm);
    const double *p0 = e->x + 3 * (size_t)C->node[(size_t)q * N];
    double e1[3] = {p0[0] - c[0], p0[1] - c[1], p0[2] - c[2]};
    const double dn = e1[0] * nrm[0] + e1[1] * nrm[1] + e1[2] * nrm[2];
    for (int a = 0; a < 3; a++)
        e1[a] -= dn * nrm[a];
    normalise(e1);
    const double e2[3] = {nrm[1] * e1[2] - nrm[2] * e1[1], nrm[2] * e1[0] - nrm[0] * e1[2],
                          nrm[0] * e1[1] - nrm[1] * e1[0]};
    const double len = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    if (!(fabs(len - 1) < 1e-6) || !(fabs(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2] - 1) < 1e-6))
        return false;
    for (int a = 0; a < 3; a++)
        C->base[3 * a] = e1[a], C->base[3 * a + 1] = e2[a], C->base[3 * a + 2] = nrm[a];
    return true;
}

spn__cyc *spn__cyc_build(const spn__eq *e, const char **why)
{
    *why = NULL;
    int32_t *loc = NULL;
    spn__cyc *C = NULL;
    /* the hub's springs: one per radial */
    uint32_t hub_l = NONE, N = 0, top = 0;
    for (uint32_t l = 0; l < e->nl; l++) {
        if (e->world_id[l] == 0) hub_l = l;
        if (e->world_id[l] > top) top = e->world_id[l];
    }
    if (hub_l == NONE) {
        *why = "particle 0 (the hub) has no spring";
        return NULL;
    }
    for (uint32_t s = 0; s < e->m; s++)
        N += e->sa[s] == hub_l || e->sb[s] == hub_l;
    if (N < 3 || top == 0) {
        *why = "particle 0 is not a hub of three or more radials";
        return NULL;
    }
    /* the lattice: particles 1 .. rings N; particles after it without a
     * spring (a prey body held by contacts) take no part */
    const uint32_t rings = (top - 1) / N + 1, np = 1 + rings * N;
    loc = malloc(np * sizeof *loc);
    uint8_t *ring_free = calloc(rings, 1), *ring_fixed = calloc(rings, 1);
    uint32_t *qof = malloc(rings * sizeof *qof); /* ring -> free ring index, or NONE */
    C = calloc(1, sizeof *C);
    if (!loc || !ring_free || !ring_fixed || !qof || !C) {
        *why = "out of memory";
        goto fail;
    }
    for (uint32_t i = 0; i < np; i++)
        loc[i] = -1;
    for (uint32_t l = 0; l < e->nl; l++)
        loc[e->world_id[l]] = (int32_t)l;
    for (uint32_t p = 1; p < np; p++) {
        const uint32_t j = (p - 1) / N;
        if (loc[p] >= 0 && (uint32_t)loc[p] < e->n)
            ring_free[j] = 1;
        else
            ring_fixed[j] = 1;
    }
    uint32_t Q = 0;
    for (uint32_t j = 0; j < rings; j++) {
        if (ring_free[j] && ring_fixed[j]) {
            *why = "a ring is partly fixed";
            goto fail;
        }
        Q += ring_free[j];
    }
    if (Q == 0) {
        *why = "no ring is free";
        goto fail;
    }
    C->N = N, C->Q = Q, C->K = N / 2 + 1, C->B = 3 * Q, C->Bc = (3 * Q + 1) / 2;
    C->hub = hub_l < e->n ? (int32_t)hub_l : -1;
    C->hub_coupled = C->hub >= 0 && ring_free[0];
    const size_t QN = (size_t)Q * N;
    C->node = malloc(QN * sizeof *C->node), C->ring_s = malloc(QN * sizeof *C->ring_s);
    C->rad_s = malloc(QN * sizeof *C->rad_s), C->hub_s = malloc(N * sizeof *C->hub_s);
    if (!C->node || !C->ring_s || !C->rad_s || !C->hub_s) {
        *why = "out of memory";
        goto fail;
    }
    for (uint32_t j = 0, q = 0; j < rings; j++)
        qof[j] = ring_free[j] ? q++ : NONE;
    for (uint32_t j = 0; j < rings; j++)
        if (qof[j] != NONE)
            for (uint32_t i = 0; i < N; i++)
                C->node[(size_t)qof[j] * N + i] = (uint32_t)loc[1 + (size_t)j * N + i];
    for (size_t k = 0; k < QN; k++)
        C->ring_s[k] = C->rad_s[k] = NONE;
    for (uint32_t i = 0; i < N; i++)
        C->hub_s[i] = NONE;
    /* every spring a lattice slot, each slot at most once */
    for (uint32_t s = 0; s < e->m; s++) {
        int64_t j;
        uint32_t i;
        const int kind = slot_of(N, rings, e->world_id[e->sa[s]], e->world_id[e->sb[s]], &j, &i);
        uint32_t *slot = NULL;
        if (kind < 0) {
            *why = "a spring is not a ring or radial segment";
            goto fail;
        }
        if (kind == 0)
            slot = qof[j] != NONE ? &C->ring_s[(size_t)qof[j] * N + i] : NULL;
        else if (j < 0)
            slot = C->hub_coupled ? &C->hub_s[i] : NULL;
        else if (qof[j] != NONE && qof[j + 1] != NONE)
            slot = &C->rad_s[(size_t)qof[j] * N + i];
        if (slot && *slot != NONE) {
            *why = "two springs join the same particles";
            goto fail;
        }
        if (slot) *slot = s;
    }
    /* each free ring needs its N ring springs; radial slots between two free
     * rings and the hub's must all be there */
    for (uint32_t q = 0; q < Q; q++)
        for (uint32_t i = 0; i < N; i++)
            if (C->ring_s[(size_t)q * N + i] == NONE) {
                *why = "a ring segment is missing";
                goto fail;
            }
    for (uint32_t j = 0; j + 1 < rings; j++)
        if (qof[j] != NONE && qof[j + 1] != NONE)
            for (uint32_t i = 0; i < N; i++)
                if (C->rad_s[(size_t)qof[j] * N + i] == NONE) {
                    *why = "a radial segment is missing";
                    goto fail;
                }
    if (C->hub_coupled)
        for (uint32_t i = 0; i < N; i++)
            if (C->hub_s[i] == NONE) {
                *why = "a hub segment is missing";
                goto fail;
            }
    if (!(C->sent = malloc((e->m ? e->m : 1) * sizeof *C->sent))) {
        *why = "out of memory";
        goto fail;
    }
    for (uint32_t i = 0; i < e->n; i++)
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++)
            if (e->sa[e->adj[j] >> 1] == i) C->sent[e->adj[j] >> 1] = j;
    if (!base_frame(C, e, 0)) {
        *why = "a ring has no plane";
        goto fail;
    }
    C->cs = malloc(N * sizeof *C->cs), C->sn = malloc(N * sizeof *C->sn);
    C->dbar = malloc(9 * (size_t)Q * sizeof *C->dbar), C->gbar = malloc(9 * (size_t)Q * sizeof *C->gbar);
    C->cbar = malloc(9 * (size_t)Q * sizeof *C->cbar);
    C->gam = spn__big_alloc(9 * (size_t)C->K * Q * sizeof *C->gam);
    C->zhub = malloc(2 * 2 * 9 * (size_t)Q * sizeof *C->zhub);
    const size_t nz = (size_t)N * C->Bc, nx = (size_t)C->K * C->B;
    C->fft = spn__fft_plan(N);
    const size_t nt = C->fft ? spn__fft_scratch_rows(C->fft) * C->Bc : 0;
    C->zr = spn__big_alloc(nz * sizeof(double)), C->zi = spn__big_alloc(nz * sizeof(double));
    C->tr = nt ? spn__big_alloc(nt * sizeof(double)) : NULL, C->ti = nt ? spn__big_alloc(nt * sizeof(double)) : NULL;
    C->xr = spn__big_alloc(nx * sizeof(double)), C->xi = spn__big_alloc(nx * sizeof(double));
    if (!C->cs || !C->sn || !C->dbar || !C->gbar || !C->cbar || !C->gam || !C->zhub || !C->zr || !C->zi || !C->tr ||
        !C->ti || !C->xr || !C->xi || !C->fft) {
        *why = "out of memory";
        goto fail;
    }
    for (uint32_t i = 0; i < N; i++) { /* exact reduction, so i and N - i are mirror images */
        const double a = 2 * SPN_PI * (double)i / N;
        C->cs[i] = cos(a), C->sn[i] = sin(a);
    }
    C->threads = e->threads;
    free(loc), free(ring_free), free(ring_fixed), free(qof);
    return C;
fail:
    free(loc), free(ring_free), free(ring_fixed), free(qof);
    spn__cyc_free(C);
    return NULL;
}

/* ---- small matrices ---- */

/* F: the frame of radial i, columns radial, tangential, normal (row-major). */
static void frame(const spn__cyc *C, uint32_t i, double *F)
{
    const double c = C->cs[i], s = C->sn[i];
    for (int a = 0; a < 3; a++) {
        const double *b = C->base + 3 * a;
        F[3 * a] = c * b[0] + s * b[1];
        F[3 * a + 1] = -s * b[0] + c * b[1];
        F[3 * a + 2] = b[2];
    }
}

/* acc += Fa^T X Fb, X row-major 3x3 */
static void add_rotated(double *acc, const double *Fa, const double *X, const double *Fb)
{
    double t[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            t[3 * r + c] = X[3 * r] * Fb[c] + X[3 * r + 1] * Fb[3 + c] + X[3 * r + 2] * Fb[6 + c];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            acc[3 * r + c] += Fa[r] * t[c] + Fa[3 + r] * t[3 + c] + Fa[6 + r] * t[6 + c];
}

/* -H_s as a full 3x3 */
static void offdiag(const spn__cyc *C, const spn__eq *e, uint32_t s, double *X)
{
    double m[9], tmp[6];
    spn__sym_full(e->hs ? e->hs + 6 * (size_t)s : spn__eq_offd(e, C->sent[s], tmp), m);
    if (!e->hs) { /* offd holds the block itself, not H_s */
        for (int c = 0; c < 9; c++)
            X[c] = m[c];
        return;
    }
    for (int c = 0; c < 9; c++)
        X[c] = -m[c];
}

static double frob2(const double *a)
{
    double s = 0;
    for (int c = 0; c < 9; c++)
        s += a[c] * a[c];
    return s;
}

/* Hermitian 3x3 in the 9-number form: (re, im) of entry (r, c). */
static inline void herm_get(const double *g, int r, int c, double *re, double *im)
{
    static const int off[3][3] = {{-1, 0, 1}, {0, -1, 2}, {1, 2, -1}};
    if (r == c) {
        *re = g[r], *im = 0;
        return;
    }
    const int o = off[r][c];
    *re = g[3 + 2 * o];
    *im = r < c ? g[4 + 2 * o] : -g[4 + 2 * o];
}

/* Inverse of a Hermitian positive definite 3x3 given as full complex
 * (ar, ai row-major) into the 9-number form; false when not definite. */
static bool herm_inverse(const double *ar, const double *ai, double *g)
{
    /* Cholesky A = L L^H, then A^-1 = L^-H L^-1 */
    double lr[9] = {0}, li[9] = {0};
    for (int j = 0; j < 3; j++) {
        double d = ar[4 * j];
        for (int k = 0; k < j; k++)
            d -= lr[3 * j + k] * lr[3 * j + k] + li[3 * j + k] * li[3 * j + k];
        if (!(d > 0)) return false;
        const double ljj = sqrt(d);
        lr[4 * j] = ljj;
        for (int i = j + 1; i < 3; i++) {
            double sr = ar[3 * i + j], si = ai[3 * i + j];
            for (int k = 0; k < j; k++) { /* - L_ik conj(L_jk) */
                sr -= lr[3 * i + k] * lr[3 * j + k] + li[3 * i + k] * li[3 * j + k];
                si -= li[3 * i + k] * lr[3 * j + k] - lr[3 * i + k] * li[3 * j + k];
            }
            lr[3 * i + j] = sr / ljj, li[3 * i + j] = si / ljj;
        }
    }
    /* W = L^-1 (lower triangular) */
    double wr[9] = {0}, wi[9] = {0};
    for (int j = 0; j < 3; j++) {
        wr[4 * j] = 1 / lr[4 * j];
        for (int i = j + 1; i < 3; i++) {
            double sr = 0, si = 0;
            for (int k = j; k < i; k++) {
                sr += lr[3 * i + k] * wr[3 * k + j] - li[3 * i + k] * wi[3 * k + j];
                si += lr[3 * i + k] * wi[3 * k + j] + li[3 * i + k] * wr[3 * k + j];
            }
            wr[3 * i + j] = -sr / lr[4 * i], wi[3 * i + j] = -si / lr[4 * i];
        }
    }
    /* A^-1 = W^H W: entry (r, c) = sum_k conj(W_kr) W_kc */
    double fr[9], fi[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double sr = 0, si = 0;
            for (int k = 0; k < 3; k++) {
                sr += wr[3 * k + r] * wr[3 * k + c] + wi[3 * k + r] * wi[3 * k + c];
                si += wr[3 * k + r] * wi[3 * k + c] - wi[3 * k + r] * wr[3 * k + c];
            }
            fr[3 * r + c] = sr, fi[3 * r + c] = si;
        }
    g[0] = fr[0], g[1] = fr[4], g[2] = fr[8];
    g[3] = fr[1], g[4] = fi[1], g[5] = fr[2], g[6] = fi[2], g[7] = fr[5], g[8] = fi[5];
    return true;
}

/* y = G x, G Hermitian (9-number form), x, y complex 3-vectors */
static inline void herm_mul(const double *g, const double *xr, const double *xi, double *yr, double *yi)
{
    for (int r = 0; r < 3; r++) {
        double sr = 0, si = 0;
        for (int c = 0; c < 3; c++) {
            double gr, gi;
            herm_get(g, r, c, &gr, &gi);
            sr += gr * xr[c] - gi * xi[c];
            si += gr * xi[c] + gi * xr[c];
        }
        yr[r] = sr, yi[r] = si;
    }
}

/* ---- factoring ---- */

/* A (row-major 3x3) replaced by (A + A^T) / 2 */
static void symmetrise(double *A)
{
    for (int r = 0; r < 3; r++)
        for (int c = r + 1; c < 3; c++)
            A[3 * r + c] = A[3 * c + r] = 0.5 * (A[3 * r + c] + A[3 * c + r]);
}

/* sum += Fa^T X Fb; returns that block's |.|_F^2 (for the spread) */
static double add_local(double *sum, const double *Fa, const double *X, const double *Fb)
{
    double one[9] = {0};
    add_rotated(one, Fa, X, Fb);
    for (int c = 0; c < 9; c++)
        sum[c] += one[c];
    return frob2(one);
}

/* The averaged blocks of free ring q, and its spread about them. */
static void ring_means(spn__cyc *C, const spn__eq *e, uint32_t q, double *spread, double *size)
{
    const uint32_t N = C->N;
    double *D = C->dbar + 9 * (size_t)q, *G = C->gbar + 9 * (size_t)q, *R = C->cbar + 9 * (size_t)q;
    memset(D, 0, 9 * sizeof *D), memset(G, 0, 9 * sizeof *G), memset(R, 0, 9 * sizeof *R);
    double sq = 0;
    const bool radial = C->rad_s[(size_t)q * N] != NONE;
    for (uint32_t i = 0; i < N; i++) {
        double Fi[9], Fn[9], X[9];
        frame(C, i, Fi);
        frame(C, (i + 1) % N, Fn);
        spn__sym_full(e->diag + 6 * (size_t)C->node[(size_t)q * N + i], X);
        sq += add_local(D, Fi, X, Fi);
        offdiag(C, e, C->ring_s[(size_t)q * N + i], X);
        sq += add_local(G, Fi, X, Fn);
        if (radial) {
            offdiag(C, e, C->rad_s[(size_t)q * N + i], X);
            sq += add_local(R, Fi, X, Fi);
        }
    }
    for (int c = 0; c < 9; c++)
        D[c] /= N, G[c] /= N, R[c] /= N;
    /* symmetric by construction up to rounding: make them exactly so */
    symmetrise(D), symmetrise(R);
    *size = sq;
    *spread = sq - N * (frob2(D) + frob2(G) + frob2(R)); /* sum |X - mean|^2 = sum |X|^2 - N |mean|^2 */
}

/* The hub's averaged blocks: its diagonal in the base frame averaged over
 * the turns, and its coupling to ring 0 in the radials' frames. */
static void hub_means(spn__cyc *C, const spn__eq *e)
{
    const uint32_t N = C->N;
    double Dh[9], Db[9] = {0};
    spn__sym_full(e->diag + 6 * (size_t)C->hub, Dh);
    add_rotated(Db, C->base, Dh, C->base);
    /* mean over g of P_g^T Db P_g: the in-plane part keeps its trace and
     * antisymmetric part (zero here), the couplings to the normal vanish */
    memset(C->hdiag, 0, sizeof C->hdiag);
    const double t = 0.5 * (Db[0] + Db[4]);
    C->hdiag[0] = C->hdiag[4] = t, C->hdiag[8] = Db[8];
    memset(C->hcoup, 0, sizeof C->hcoup);
    for (uint32_t i = 0; i < N; i++) {
        double Fi[9], X[9];
        frame(C, i, Fi);
        offdiag(C, e, C->hub_s[i], X);
        add_rotated(C->hcoup, Fi, X, Fi);
    }
    for (int c = 0; c < 9; c++)
        C->hcoup[c] /= N;
    symmetrise(C->hcoup);
}

/* Block Thomas factors of mode k; false when a pivot is not definite. */
static bool factor_mode(spn__cyc *C, uint32_t k)
{
    const uint32_t N = C->N, Q = C->Q;
    const double w = 2 * SPN_PI * (double)k / N, co = cos(w), si = sin(w);
    double prev[9] = {0}; /* Gamma_{q-1}^-1 */
    for (uint32_t q = 0; q < Q; q++) {
        const double *D = C->dbar + 9 * (size_t)q, *G = C->gbar + 9 * (size_t)q;
        double ar[9], ai[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                ar[3 * r + c] = D[3 * r + c] + (G[3 * r + c] + G[3 * c + r]) * co;
                ai[3 * r + c] = (G[3 * r + c] - G[3 * c + r]) * si;
            }
        if (q > 0) { /* - C Gamma^-1 C, C real symmetric */
            const double *R = C->cbar + 9 * (size_t)(q - 1);
            double tr[9], ti[9]; /* Gamma^-1 C */
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) {
                    double sr = 0, sm = 0;
                    for (int m = 0; m < 3; m++) {
                        double gr, gi;
                        herm_get(prev, r, m, &gr, &gi);
                        sr += gr * R[3 * m + c], sm += gi * R[3 * m + c];
                    }
                    tr[3 * r + c] = sr, ti[3 * r + c] = sm;
                }
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) {
                    double sr = 0, sm = 0;
                    for (int m = 0; m < 3; m++)
                        sr += R[3 * r + m] * tr[3 * m + c], sm += R[3 * r + m] * ti[3 * m + c];
                    ar[3 * r + c] -= sr, ai[3 * r + c] -= sm;
                }
        }
        double *g = C->gam + 9 * ((size_t)k * Q + q);
        if (!herm_inverse(ar, ai, g)) return false;
        memcpy(prev, g, sizeof prev);
    }
    return true;
}

/* Solve mode k's block tridiagonal system in place: x (3 Q complex, split
 * re/im with stride 1 over the ring's 3 components) */
static void solve_mode(const spn__cyc *C, uint32_t k, double *xr, double *xi)
{
    const uint32_t Q = C->Q;
    const double *gam = C->gam + 9 * (size_t)k * Q;
    for (uint32_t q = 0; q < Q; q++) { /* forward: t_q = Gamma_q^-1 (b_q - C_{q-1} t_{q-1}) */
        double *br = xr + 3 * (size_t)q, *bi = xi + 3 * (size_t)q;
        if (q > 0) {
            const double *R = C->cbar + 9 * (size_t)(q - 1), *pr = br - 3, *pi = bi - 3;
            for (int r = 0; r < 3; r++) {
                br[r] -= R[3 * r] * pr[0] + R[3 * r + 1] * pr[1] + R[3 * r + 2] * pr[2];
                bi[r] -= R[3 * r] * pi[0] + R[3 * r + 1] * pi[1] + R[3 * r + 2] * pi[2];
            }
        }
        double yr[3], yi[3];
        herm_mul(gam + 9 * (size_t)q, br, bi, yr, yi);
        memcpy(br, yr, sizeof yr), memcpy(bi, yi, sizeof yi);
    }
    for (uint32_t q = Q - 1; q-- > 0;) { /* back: x_q = t_q - Gamma_q^-1 C_q x_{q+1} */
        const double *R = C->cbar + 9 * (size_t)q, *nr = xr + 3 * (size_t)(q + 1), *ni = xi + 3 * (size_t)(q + 1);
        double vr[3], vi[3], yr[3], yi[3];
        for (int r = 0; r < 3; r++) {
            vr[r] = R[3 * r] * nr[0] + R[3 * r + 1] * nr[1] + R[3 * r + 2] * nr[2];
            vi[r] = R[3 * r] * ni[0] + R[3 * r + 1] * ni[1] + R[3 * r + 2] * ni[2];
        }
        herm_mul(gam + 9 * (size_t)q, vr, vi, yr, yi);
        for (int r = 0; r < 3; r++)
            xr[3 * (size_t)q + r] -= yr[r], xi[3 * (size_t)q + r] -= yi[r];
    }
}

/* E_0 = diag(0, 0, 1) and E_+ = (1/2)[[1, -i, 0], [i, 1, 0], [0, 0, 0]]:
 * the turn's matrix P(-theta) = E_0 + E_+ e^{i theta} + conj(E_+) e^{-i theta}. */
static void e_matrix(int m, double *er, double *ei)
{
    memset(er, 0, 9 * sizeof *er), memset(ei, 0, 9 * sizeof *ei);
    if (m == 0) {
        er[8] = 1;
    } else {
        er[0] = er[4] = 0.5;
        ei[1] = -0.5, ei[3] = 0.5;
    }
}

/* The hub's part of modes 0 and 1: Z_m = A_m^-1 (e_0 F_m), F_m = S^T E_m,
 * and the inverted Schur complement
 * D_h - N (G_0 Z_0,0 + 2 Re G_1 Z_1,0), G_m = E_m S. */
static bool factor_hub(spn__cyc *C)
{
    const uint32_t N = C->N, Q = C->Q;
    const double *S = C->hcoup;
    double sch[9];
    memcpy(sch, C->hdiag, sizeof sch);
    double *colr = malloc(3 * (size_t)Q * sizeof *colr), *coli = malloc(3 * (size_t)Q * sizeof *coli);
    if (!colr || !coli) {
        free(colr), free(coli);
        return false;
    }
    for (int m = 0; m < 2; m++) {
        double er[9], ei[9], fr[9], fi[9], gr[9], gi[9];
        e_matrix(m, er, ei);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double a = 0, b = 0, g = 0, h = 0;
                for (int t = 0; t < 3; t++) {
                    a += S[3 * t + r] * er[3 * t + c], b += S[3 * t + r] * ei[3 * t + c]; /* S^T E */
                    g += er[3 * r + t] * S[3 * t + c], h += ei[3 * r + t] * S[3 * t + c]; /* E S */
                }
                fr[3 * r + c] = a, fi[3 * r + c] = b, gr[3 * r + c] = g, gi[3 * r + c] = h;
            }
        double *z = C->zhub + (size_t)m * 18 * Q; /* row (q, comp) has 3 complex: re at 6 row + 2 col */
        for (int c = 0; c < 3; c++) {
            memset(colr, 0, 3 * (size_t)Q * sizeof *colr), memset(coli, 0, 3 * (size_t)Q * sizeof *coli);
            for (int r = 0; r < 3; r++)
                colr[r] = fr[3 * r + c], coli[r] = fi[3 * r + c];
            solve_mode(C, (uint32_t)m, colr, coli);
            for (size_t row = 0; row < 3 * (size_t)Q; row++)
                z[6 * row + 2 * c] = colr[row], z[6 * row + 2 * c + 1] = coli[row];
        }
        /* the Schur term: N G_m Z_m,0 (twice its real part for m = 1: mode N - 1 is its conjugate) */
        const double mult = m == 0 ? (double)N : 2.0 * N;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double s = 0;
                for (int t = 0; t < 3; t++)
                    s += gr[3 * r + t] * z[6 * t + 2 * c] - gi[3 * r + t] * z[6 * t + 2 * c + 1];
                sch[3 * r + c] -= mult * s;
            }
    }
    free(colr), free(coli);
    const double h[6] = {
        sch[0], sch[4], sch[8], 0.5 * (sch[1] + sch[3]), 0.5 * (sch[2] + sch[6]), 0.5 * (sch[5] + sch[7])};
    return spn__sym_inverse(h, C->schur);
}

bool spn__cyc_factor(spn__cyc *C, const spn__eq *e)
{
    const int team = team_of(C, e);
    const uint32_t Q = C->Q;
    double *spread = malloc(2 * (size_t)Q * sizeof *spread);
    if (!spread) return false;
    (void)team;
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t q = 0; q < Q; q++)
        ring_means(C, e, q, spread + q, spread + Q + q);
    double num = 0, den = 0;
    for (uint32_t q = 0; q < Q; q++)
        num += spread[q], den += spread[Q + q];
    free(spread);
    C->asym = den > 0 ? sqrt(fmax(num, 0) / den) : 0;
    int bad = 0;
#pragma omp parallel for schedule(static) num_threads(team) reduction(+ : bad)
    for (uint32_t k = 0; k < C->K; k++)
        bad += !factor_mode(C, k);
    if (bad) return false;
    if (C->hub_coupled) {
        hub_means(C, e);
        if (!factor_hub(C)) return false;
    }
    return true;
}

double spn__cyc_asymmetry(const spn__cyc *C) { return C->asym; }

/* ---- applying ---- */

/* The columns [b0, b1) of B (or Bc) split in team parts of whole cache lines. */
static void part(size_t total, int t, int team, size_t *b0, size_t *b1)
{
    const size_t per = ((total + (size_t)team - 1) / (size_t)team + 7) / 8 * 8;
    *b0 = (size_t)t * per < total ? (size_t)t * per : total;
    *b1 = *b0 + per < total ? *b0 + per : total;
}

void spn__cyc_apply(const spn__cyc *C, const spn__eq *e, const double *r, double *z)
{
    spn__cyc *W = (spn__cyc *)C; /* the work arrays */
    const uint32_t N = C->N, Q = C->Q, K = C->K, B = C->B;
    const size_t Bc = C->Bc;
    const int team = team_of(C, e);
    double *zr = W->zr, *zi = W->zi, *xr = W->xr, *xi = W->xi;
    double hub_r[3] = {0, 0, 0};
    if (C->hub >= 0) { /* the hub's residual in the base frame */
        const double *v = r + 3 * (size_t)C->hub;
        for (int a = 0; a < 3; a++)
            hub_r[a] = C->base[a] * v[0] + C->base[3 + a] * v[1] + C->base[6 + a] * v[2];
    }
    (void)team;
    /* 1. local frames, rows i; real sequence b = 3 q + c goes to column b / 2, re if even */
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t i = 0; i < N; i++) {
        double F[9];
        frame(C, i, F);
        double *rowr = zr + (size_t)i * Bc, *rowi = zi + (size_t)i * Bc;
        if (B & 1u) rowi[Bc - 1] = 0;
        for (uint32_t q = 0; q < Q; q++) {
            const double *v = r + 3 * (size_t)C->node[(size_t)q * N + i];
            for (int c = 0; c < 3; c++) {
                const double l = F[c] * v[0] + F[3 + c] * v[1] + F[6 + c] * v[2];
                const size_t b = 3 * (size_t)q + (size_t)c;
                if (b & 1u)
                    rowi[b >> 1] = l;
                else
                    rowr[b >> 1] = l;
            }
        }
    }
    /* 2. forward transform */
#pragma omp parallel num_threads(team)
    {
        size_t b0, b1;
        part(Bc, spn__thread_num(), spn__thread_count(), &b0, &b1);
        if (b1 > b0) spn__fft_run(C->fft, -1, zr, zi, Bc, b0, b1, W->tr, W->ti);
    }
    /* 3. modes k = 0..N/2 of each real sequence, scaled by 1/N */
    const double h = 0.5 / N;
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t k = 0; k < K; k++) {
        const double *ar = zr + (size_t)k * Bc, *ai = zi + (size_t)k * Bc;
        const double *cr = zr + (size_t)((N - k) % N) * Bc, *ci = zi + (size_t)((N - k) % N) * Bc;
        double *or_ = xr + (size_t)k * B, *oi = xi + (size_t)k * B;
        for (size_t t = 0; t < Bc; t++) {
            or_[2 * t] = h * (ar[t] + cr[t]), oi[2 * t] = h * (ai[t] - ci[t]);
            if (2 * t + 1 < B) or_[2 * t + 1] = h * (ai[t] + ci[t]), oi[2 * t + 1] = h * (cr[t] - ar[t]);
        }
    }
    /* 4. the modes' systems */
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t k = 0; k < K; k++)
        solve_mode(C, k, xr + (size_t)k * B, xi + (size_t)k * B);
    double hub_u[3] = {0, 0, 0};
    if (C->hub_coupled) {
        /* u_h = Schur^-1 (r_h - N (G_0 y_0,0 + 2 Re G_1 y_1,0)); then u_m -= Z_m u_h */
        const double *S = C->hcoup;
        double rhs[3] = {hub_r[0], hub_r[1], hub_r[2]};
        for (int m = 0; m < 2; m++) {
            double er[9], ei[9];
            e_matrix(m, er, ei);
            const double *yr = xr + (size_t)m * B, *yi = xi + (size_t)m * B, mult = m == 0 ? (double)N : 2.0 * N;
            double sr[3], si[3]; /* S y_0 (ring 0's block) */
            for (int a = 0; a < 3; a++) {
                sr[a] = S[3 * a] * yr[0] + S[3 * a + 1] * yr[1] + S[3 * a + 2] * yr[2];
                si[a] = S[3 * a] * yi[0] + S[3 * a + 1] * yi[1] + S[3 * a + 2] * yi[2];
            }
            for (int a = 0; a < 3; a++) {
                double re = 0;
                for (int t = 0; t < 3; t++)
                    re += er[3 * a + t] * sr[t] - ei[3 * a + t] * si[t];
                rhs[a] -= mult * re;
            }
        }
        spn__sym_mul(C->schur, rhs, hub_u);
        for (int m = 0; m < 2; m++) {
            const double *zm = C->zhub + (size_t)m * 18 * Q;
            double *yr = xr + (size_t)m * B, *yi = xi + (size_t)m * B;
            for (size_t row = 0; row < B; row++)
                for (int c = 0; c < 3; c++)
                    yr[row] -= zm[6 * row + 2 * c] * hub_u[c], yi[row] -= zm[6 * row + 2 * c + 1] * hub_u[c];
        }
    } else if (C->hub >= 0) { /* a hub alone: its own block (global frame) */
        double inv[6];
        if (spn__sym_inverse(e->diag + 6 * (size_t)C->hub, inv)) spn__sym_mul(inv, r + 3 * (size_t)C->hub, hub_u);
    }
    /* 5. all N modes of the packed pairs, the transform back */
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t k = 0; k < N; k++) {
        const bool mirror = k >= K;
        const uint32_t src = mirror ? N - k : k;
        const double sg = mirror ? -1 : 1;
        const double *pr = xr + (size_t)src * B, *pi = xi + (size_t)src * B;
        double *outr = zr + (size_t)k * Bc, *outi = zi + (size_t)k * Bc;
        for (size_t t = 0; t < Bc; t++) {
            const double er = pr[2 * t], ei = sg * pi[2 * t];
            const double orr = 2 * t + 1 < B ? pr[2 * t + 1] : 0, oi = 2 * t + 1 < B ? sg * pi[2 * t + 1] : 0;
            outr[t] = er - oi, outi[t] = ei + orr;
        }
    }
#pragma omp parallel num_threads(team)
    {
        size_t b0, b1;
        part(Bc, spn__thread_num(), spn__thread_count(), &b0, &b1);
        if (b1 > b0) spn__fft_run(C->fft, 1, zr, zi, Bc, b0, b1, W->tr, W->ti);
    }
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t i = 0; i < N; i++) {
        double F[9];
        frame(C, i, F);
        const double *rowr = zr + (size_t)i * Bc, *rowi = zi + (size_t)i * Bc;
        for (uint32_t q = 0; q < Q; q++) {
            double l[3];
            for (int c = 0; c < 3; c++) {
                const size_t b = 3 * (size_t)q + (size_t)c;
                l[c] = b & 1u ? rowi[b >> 1] : rowr[b >> 1];
            }
            double *v = z + 3 * (size_t)C->node[(size_t)q * N + i];
            for (int a = 0; a < 3; a++)
                v[a] = F[3 * a] * l[0] + F[3 * a + 1] * l[1] + F[3 * a + 2] * l[2];
        }
    }
    if (C->hub >= 0) {
        double *v = z + 3 * (size_t)C->hub;
        if (C->hub_coupled)
            for (int a = 0; a < 3; a++)
                v[a] = C->base[3 * a] * hub_u[0] + C->base[3 * a + 1] * hub_u[1] + C->base[3 * a + 2] * hub_u[2];
        else
            for (int a = 0; a < 3; a++)
                v[a] = hub_u[a];
    }
}

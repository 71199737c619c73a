/* Forces on the spring world: springs with axial damping (Mehla 2005,
 * eq. 4.14), gravity and viscous drag (eqs. 4.6-4.7, drag per unit mass here),
 * the user force callback, and aerodynamic drag on threads.
 *
 * A force evaluation is two passes. The spring pass computes each spring's
 * force on its end a into w->fs (end b gets the opposite, eq. 4.15). The
 * gather pass sums, for each particle, gravity, drag and its springs' forces
 * in adjacency order. No two threads write the same element and every sum runs
 * in a fixed order, so the result is bit-identical for any thread count.
 *
 * Air drag on a tagged segment (independence principle for a yawed cylinder):
 * only the air velocity normal to the segment counts,
 *   u = ((w(x_a) - v_a) + (w(x_b) - v_b)) / 2,  u_n = u - t (t . u),
 *   F = 1/2 rho C_d(Re) d L |u_n| u_n,   Re = rho |u_n| d / mu,
 * half of F on each end: the air relative to the segment, taken as its
 * velocity is, as the mean of its ends'. The air callback is called
 * serially in a fixed order, once per particle that ends a tagged segment,
 * so it may keep state (a seeded gust generator, say). */
#include "world_internal.h"
#include "chunk.h"
#include "core/kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int spn__threads(const spn_world *w, uint32_t n)
{
#ifdef _OPENMP
    if (n < w->def.parallel_min) return 1;
    return w->def.threads > 0 ? w->def.threads : omp_get_max_threads();
#else
    (void)w;
    (void)n;
    return 1;
#endif
}

spn_status spn__scratch(spn_world *w, int count)
{
    size_t np = w->np ? w->np : 1;
    for (int i = 0; i < count; i++) {
        if (w->tmp[i]) continue;
        w->tmp[i] = calloc(np, sizeof *w->tmp[i]);
        if (!w->tmp[i]) return spn_error(SPN_ERR_NOMEM, "out of memory for %u particles' scratch", w->np);
    }
    return SPN_OK;
}

void spn__sum_partials(const spn_world *w, uint32_t blocks, double *out)
{
    for (int k = 0; k < SPN_NSUMS; k++) out[k] = 0;
    for (uint32_t b = 0; b < blocks; b++)
        for (int k = 0; k < SPN_NSUMS; k++) out[k] += w->partial[(size_t)b * SPN_NSUMS + k];
}

bool spn__air_active(const spn_world *w) { return w->air_fn && w->any_diam && w->fair; }

/* C_d between Re 0.5 and 2, the blend below, as a polynomial of degree 16
 * in t = ln Re / ln 2 (t in [-1, 1]): the Chebyshev series of the blend's
 * closed form lamb^(1 - s) white^s, taken at 200 Chebyshev points in
 * 40-digit arithmetic (its next term is 1.5e-16 of a C_d of 7 to 19) and
 * turned into powers of t there. It is within 7e-16 of the closed form
 * evaluated in double (tests/test_physics_air.c), with one logarithm and
 * Estrin's scheme (a chain five products deep) where the closed form took a
 * logarithm, a power, a logarithm and an exponential: 13.5 ns a call against
 * 36 (Zen 5). The capture spiral in a 1 m/s breeze sits here (Re ~ 0.7), so
 * this was a sixth of an explicit step in air. */
static const double blend_poly[17] = {
    1.17512546042189783e+01, -5.28300267091567122e+00, 1.16163246071292892e+00,
    -3.78814424684205342e-01, 5.97660432490196430e-02, -1.33125826671900583e-02,
    2.25371541603362757e-03, -2.51398459570129518e-04, 7.64094178828893635e-05,
    2.53063814554623763e-07, 2.51228836897812677e-06, 2.28308417792426334e-07,
    8.32079730198896647e-08, 1.21202834588782657e-08, 3.04249964898525627e-09,
    9.09210488125413742e-10, 2.45590112304863142e-10};

/* blend_poly at t. */
SPN__INLINE double blend(double t)
{
    const double *a = blend_poly, t2 = t * t, t4 = t2 * t2, t8 = t4 * t4;
    double q[8];
    for (int i = 0; i < 8; i++) q[i] = a[2 * i] + a[2 * i + 1] * t;
    const double r0 = q[0] + q[1] * t2, r1 = q[2] + q[3] * t2, r2 = q[4] + q[5] * t2, r3 = q[6] + q[7] * t2;
    return ((r0 + r1 * t4) + (r2 + r3 * t4) * t8) + a[16] * (t8 * t8);
}

/* ln x for a finite x > 0 (subnormal too), in plain operations and bit
 * moves that GCC vectorises, each version to the same bits (libm's log is
 * a call a loop cannot vectorise). x = 2^e m with m in [sqrt(1/2),
 * sqrt(2)), found from x's bits (e as a double by the 2^52 trick: no
 * integer conversion, which AVX2 lacks for 64-bit lanes); ln m = 2
 * atanh(s), s = (m - 1) / (m + 1), |s| < 0.1716, by its series to s^21
 * (the next term is under 1e-18 of the sum); e ln 2 in two parts, the
 * first exact. Within 2 ulp of ln x (tests/test_physics_air.c checks it
 * through Lamb's law against libm's log). */
SPN__INLINE double ln_pos(double x)
{
    const bool sub = x < 0x1p-1022;
    const double y = sub ? x * 0x1p54 : x;
    uint64_t b, eb;
    memcpy(&b, &y, sizeof b);
    eb = (b >> 52) | UINT64_C(0x4330000000000000); /* 2^52 + the biased exponent */
    b = (b & UINT64_C(0x000fffffffffffff)) | UINT64_C(0x3ff0000000000000);
    double m, e2;
    memcpy(&m, &b, sizeof m), memcpy(&e2, &eb, sizeof e2);
    const bool big = m > 1.4142135623730951; /* (sqrt 2) */
    m = big ? 0.5 * m : m;
    const double e = (e2 - 0x1p52) - (sub ? 1077.0 : 1023.0) + (big ? 1.0 : 0.0);
    const double f = m - 1, s = f / (m + 1), z = s * s;
    double p = 1.0 / 21;
    static const double odd[9] = {1.0 / 19, 1.0 / 17, 1.0 / 15, 1.0 / 13, 1.0 / 11,
                                  1.0 / 9,  1.0 / 7,  1.0 / 5,  1.0 / 3};
    for (int i = 0; i < 9; i++) p = odd[i] + z * p;
    const double two_s = 2 * s, ln_m = two_s + two_s * (z * p);
    /* (ln 2 = LN2_HI + LN2_LO; LN2_HI has 32 significant bits, so e LN2_HI is exact) */
    const double LN2_HI = 6.93147180369123816490e-01, LN2_LO = 1.90821492927058770002e-10;
    return e * LN2_HI + (ln_m + e * LN2_LO);
}

/* C_d for 0 < re < 2 (spn_cylinder_drag_coefficient): Lamb's law up to
 * Re 0.5, the blend above. Both are formed and one is selected, so that
 * air_chunk's loop over many segments vectorises. */
SPN__INLINE double drag_coefficient_low(double re)
{
    const double ln_re = ln_pos(re);
    const double lamb = 8 * SPN_PI / (re * (2.002 - ln_re));
    const double mid = blend(ln_re / 0.69314718055994530942); /* (ln 2) */
    return re <= 0.5 ? lamb : mid;
}

double spn_cylinder_drag_coefficient(double re)
{
    /* Re <= 0.5: Lamb's (1911) Oseen solution, C_d = 8 pi / (Re (2.002 - ln Re)).
     * Re >= 2: White's correlation C_d = 1 + 10 Re^(-2/3) (Viscous Fluid
     * Flow, 1-10 <= Re <= 2e5, within about 10% of the measured curve).
     * Between them the logarithms are blended linearly in ln Re, so C_d is
     * continuous (blend_poly); see docs/physics.md. Silk in a breeze sits
     * at Re ~ 0.01-1. */
    if (!(re > 0)) return 0;
    if (re > 2e5) re = 2e5; /* beyond the drag crisis the thread would have snapped */
    if (re >= 2) return 1 + 10 / pow(re, 2.0 / 3.0);
    return drag_coefficient_low(re);
}

/* Air forces on the n segments of a chunk from segment s0 (loaded with
 * the ends' air relative to them, chunk_load_ends; both ends together) and
 * their linear coefficients c (F = c u_n), into w->fair and w->cair: the
 * drag of docs/physics.md on the normal component u_n of the air relative
 * to the segment. Three passes over the chunk, each vectorised: the geometry up
 * to the Reynolds number, the drag coefficient (silk's Re under 2 with
 * ln_pos; libm's power, one segment at a time, for the rare others), then
 * the force.
 * Each operation is the one-segment code's, in its order, so every
 * version gives its bits; a segment without diameter, broken, of zero
 * length or in still relative air gets exact zeros, selected after. One
 * segment at a time (forty-ninth session and before) the chain of two
 * square roots, a division and the drag law took some 20 ns a segment. */
SPN__INLINE void air_chunk(spn_world *w, uint32_t s0, uint32_t n, const chunk *restrict ch)
{
    double re[SPN_CHUNK], len[SPN_CHUNK], speed[SPN_CHUNK], cd[SPN_CHUNK];
    double ux[SPN_CHUNK], uy[SPN_CHUNK], uz[SPN_CHUNK];
    const double rho = w->air_rho, mu = w->air_mu;
    /* (the chunk's arrays from its first segment, so that j indexes them) */
    const double *restrict d = w->sdiam + s0;
    const uint8_t *restrict fl = w->hflags + s0;
    double *restrict f = (double *)w->fair + 3 * (size_t)s0, *restrict c = w->cair + s0;
    for (uint32_t j = 0; j < n; j++) {
        const double lx = ch->lx[j], ly = ch->ly[j], lz = ch->lz[j];
        const double l = sqrt(lx * lx + ly * ly + lz * lz), inv = 1 / l;
        const double tx = lx * inv, ty = ly * inv, tz = lz * inv;
        const double wx = ch->wx[j] * 0.5, wy = ch->wy[j] * 0.5, wz = ch->wz[j] * 0.5;
        const double along = tx * wx + ty * wy + tz * wz;
        const double nx = wx - tx * along, ny = wy - ty * along, nz = wz - tz * along;
        const double sp = sqrt(nx * nx + ny * ny + nz * nz);
        const bool on = (d[j] > 0) & !(fl[j] & SPN_SPRING_BROKEN) & (l > 0) & (sp > 0); /* (no branches) */
        re[j] = on ? rho * sp * d[j] / mu : -1;                                         /* (-1: off) */
        len[j] = l, speed[j] = sp, ux[j] = nx, uy[j] = ny, uz[j] = nz;
    }
    /* (silk's Re, under 2, in a loop GCC vectorises; any other Re, and
     * the segments off, after it, one at a time) */
    for (uint32_t j = 0; j < n; j++)
        cd[j] = drag_coefficient_low(re[j] > 0 && re[j] < 2 ? re[j] : 1);
    for (uint32_t j = 0; j < n; j++)
        if (!(re[j] > 0 && re[j] < 2)) cd[j] = re[j] >= 0 ? spn_cylinder_drag_coefficient(re[j]) : 0;
    for (uint32_t j = 0; j < n; j++) {
        const bool on = re[j] >= 0;
        const double cj = 0.5 * rho * cd[j] * d[j] * len[j] * speed[j];
        c[j] = on ? cj : 0;
        f[3 * j] = on ? ux[j] * cj : 0, f[3 * j + 1] = on ? uy[j] * cj : 0, f[3 * j + 2] = on ? uz[j] * cj : 0;
    }
}

/* air_chunk over segments [lo, hi), a chunk at a time (spn_world_air_power;
 * a step's spring pass does it in spring_range). */
SPN__KERNEL static void air_forces(spn_world *w, uint32_t lo, uint32_t hi, const spn_vec3 *x, const spn_vec3 *v)
{
    chunk c;
    for (uint32_t s0 = lo; s0 < hi; s0 += SPN_CHUNK) {
        const uint32_t n = hi - s0 < SPN_CHUNK ? hi - s0 : SPN_CHUNK;
        chunk_load_ends(&c, w->hs + s0, n, x, v, UINT32_MAX, w->wind, w->np);
        air_chunk(w, s0, n, &c);
    }
}

/* The air at n points at time t: a batch call, or a call a point. */
static void air_at(const spn_world *w, double t, const spn_vec3 *p, spn_vec3 *out, uint32_t n)
{
    if (w->air_batch) w->air_batch(w->air_user, t, p, out, n);
    else
        for (uint32_t i = 0; i < n; i++) out[i] = w->air_fn(w->air_user, t, p[i]);
}

/* What sample_held takes again besides the particles that changed cell:
 * nothing (the interval held), the end of the interval after the one held
 * (its start is the end held), or everything. */
enum { HELD_SAME, HELD_NEXT, HELD_ALL };

/* Samples u[0..nm) as floats into held numbers `dst` (3 a particle) at the
 * particles moved[0..nm). */
SPN__INLINE void held_put(float *restrict dst, const uint32_t *moved, const spn_vec3 *u, uint32_t nm)
{
    for (uint32_t j = 0; j < nm; j++) {
        float *d = dst + 3 * (size_t)moved[j];
        d[0] = (float)u[j].x, d[1] = (float)u[j].y, d[2] = (float)u[j].z;
    }
}

/* The run [lo, hi) at a time in interval k, a fraction f into it, under
 * spn_world_set_air_resolution: each particle's samples held in
 * w->air_held, taken again where its cell of the spacing changed and as
 * `take` says, then blended in time. A particle's samples are at its
 * cell's centre, (q + 1/2) spacing, at k interval and (k + 1) interval,
 * so its air is a function of its position and the time, whatever was held
 * before. (floor, not the nearest whole number: the clones inline it, where
 * nearbyint was a call a coordinate; exact, so every version finds the
 * same cells.) The numbers go as flat arrays, 3 a particle, in loops that
 * vectorise. */
SPN__KERNEL static void sample_held(spn_world *w, uint32_t lo, uint32_t hi, double k, double f, int take,
                                    const spn_vec3 *x)
{
    const double s = w->air_spacing, inv = 1 / s;
    const uint32_t n = hi - lo;
    const size_t n3 = 3 * (size_t)n, np3 = 3 * (size_t)w->np, o = 3 * (size_t)lo;
    float *restrict q = w->air_held + o, *restrict a = q + np3, *restrict b = a + np3;
    const double *restrict xd = (const double *)(x + lo);
    double *restrict wind = (double *)(w->wind + lo);
    double c[3 * SPN__AIR_RUN];
    uint8_t same[3 * SPN__AIR_RUN];
    for (size_t j = 0; j < n3; j++) {
        c[j] = floor(xd[j] * inv);
        /* (a cell past 2^24, where a float no longer tells cells apart, or
         * a NaN, never matches: taken again at every step) */
        same[j] = ((float)c[j] == q[j]) & (fabs(c[j]) < 0x1p24);
    }
    /* the particles that changed cell (all of them with HELD_ALL), listed
     * without a branch a particle */
    uint32_t moved[SPN__AIR_RUN], nm = 0;
    const uint8_t all = take == HELD_ALL;
    for (uint32_t i = 0; i < n; i++) {
        moved[nm] = i;
        nm += all | !(same[3 * i] & same[3 * i + 1] & same[3 * i + 2]);
    }
    if (take == HELD_NEXT) /* the interval's start is the end held (the moved ones' taken below) */
        for (size_t j = 0; j < n3; j++) a[j] = b[j];
    spn_vec3 p[SPN__AIR_RUN], u[SPN__AIR_RUN];
    for (uint32_t j = 0; j < nm; j++) {
        const size_t e = 3 * (size_t)moved[j];
        q[e] = (float)c[e], q[e + 1] = (float)c[e + 1], q[e + 2] = (float)c[e + 2];
        p[j] = spn_v3((c[e] + 0.5) * s, (c[e + 1] + 0.5) * s, (c[e + 2] + 0.5) * s);
    }
    if (nm) { /* the moved ones' start, and with HELD_SAME their end */
        air_at(w, k * w->air_interval, p, u, nm);
        held_put(a, moved, u, nm);
        if (take == HELD_SAME) {
            air_at(w, (k + 1) * w->air_interval, p, u, nm);
            held_put(b, moved, u, nm);
        }
    }
    if (take != HELD_SAME) { /* every end */
        double *restrict pd = (double *)p;
        for (size_t j = 0; j < n3; j++) pd[j] = (c[j] + 0.5) * s;
        air_at(w, (k + 1) * w->air_interval, p, u, n);
        const double *restrict ud = (const double *)u;
        for (size_t j = 0; j < n3; j++) b[j] = (float)ud[j];
    }
    for (size_t j = 0; j < n3; j++) {
        const double aj = a[j];
        wind[j] = aj + ((double)b[j] - aj) * f;
    }
}

/* Air velocity at each particle that ends a tagged segment (w->air_runs):
 * serially in particle order, or, with a pure air function
 * (spn_world_set_air_pure), on `threads` threads (each particle's sample
 * its own, so the same values). With a batch function
 * (spn_world_set_air_batch), a run in one call. Until the fifty-third
 * session the air was sampled at each segment's midpoint: on an orb web
 * about 1.8 samples a particle, and a pass to form the midpoints. With a
 * resolution (spn_world_set_air_resolution), from the held samples. */
static void sample_air(spn_world *w, double t, const spn_vec3 *x, int threads)
{
    (void)threads; /* (used by the OpenMP pragmas only) */
    const uint32_t nr = w->nair_runs, *runs = w->air_runs;
    const bool held = w->air_interval > 0 && w->air_held;
    const double g = held ? t / w->air_interval : 0, k = floor(g), f = g - k;
    const int take = k == w->air_held_k ? HELD_SAME : k == w->air_held_k + 1 ? HELD_NEXT : HELD_ALL;
    if (held) w->air_held_k = k;
#pragma omp parallel for schedule(static) num_threads(threads) if (w->air_pure && threads > 1)
    for (uint32_t r = 0; r < nr; r++) {
        const uint32_t lo = runs[2 * r], hi = runs[2 * r + 1];
        if (held) sample_held(w, lo, hi, k, f, take, x);
        else air_at(w, t, x + lo, w->wind + lo, hi - lo);
    }
}

/* Springs [lo, hi): forces into fs, sums added to sums[0..2], and with
 * `air` the air's forces on them (air_chunk), from the same chunk: the
 * ends' positions and velocities are gathered once for both (fifty-second
 * session; before, the air gathered them again). Compiled for AVX2 too
 * where the compiler can pick at load time (same bits: no FMA). */
SPN__KERNEL static void spring_range(spn_world *w, uint32_t lo, uint32_t hi, const spn_vec3 *restrict x,
                                      const spn_vec3 *restrict v, double *sums, bool air)
{
    chunk c;
    const spn__spring *restrict hs = w->hs;
    spn_vec3 *restrict fs = w->fs;
    for (uint32_t s0 = lo; s0 < hi; s0 += SPN_CHUNK) {
        const uint32_t n = hi - s0 < SPN_CHUNK ? hi - s0 : SPN_CHUNK;
        if (air) chunk_load_ends(&c, hs + s0, n, x, v, UINT32_MAX, w->wind, w->np);
        else chunk_load(&c, hs + s0, n, x, v, UINT32_MAX, w->np);
        chunk_forces(&c, n, fs + s0);
        chunk_sums(&c, n, sums);
        if (air) air_chunk(w, s0, n, &c);
    }
}

void spn__spring_pass(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn__eval *e)
{
    const uint32_t ns = w->ns, nb = spn__blocks(ns);
    const bool air = spn__air_active(w);
    /* (threads as without air: until the fiftieth session a segment in air
     * counted as 8 springs, its sample and drag law then some 80 ns against
     * a spring's 10, so the pass took threads from parallel_min / 8
     * segments; see docs/physics.md, "Air drag on threads") */
    const int threads = spn__threads(w, ns);
    if (air) sample_air(w, t, x, threads);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < ns ? lo + SPN_BLOCK : ns;
        double sums[2] = {0, 0};
        spring_range(w, lo, hi, x, v, sums, air);
        const double energy = sums[0], power = sums[1];
        partial[(size_t)blk * SPN_NSUMS + 0] = energy;
        partial[(size_t)blk * SPN_NSUMS + 1] = power;
    }
    double elastic = 0, damp = 0;
    for (uint32_t blk = 0; blk < nb; blk++) {
        elastic += partial[(size_t)blk * SPN_NSUMS + 0];
        damp += partial[(size_t)blk * SPN_NSUMS + 1];
    }
    e->elastic = elastic;
    e->damp_power = damp;
    e->kinetic = 0;
    e->ext_power = 0;
}

bool spn__external(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v)
{
    if (!spn__external_user(w, t, x, v)) return false;
    if (!spn__air_active(w)) return true;
    const uint32_t np = w->np;
    const spn__gather_ctx c = spn__gather_ctx_of(w);
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) w->fext[i] = spn__air_on(&c, i, w->fext[i]);
    return true;
}

double spn_world_air_power(spn_world *w)
{
    if (spn_world_compile(w) != SPN_OK) return NAN;
    if (!spn__air_active(w)) return 0;
    const uint32_t ns = w->ns, nb = spn__blocks(ns);
    const int threads = spn__threads(w, ns);
    const spn_vec3 *x = w->x, *v = w->v;
    sample_air(w, w->t, x, threads);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < ns ? lo + SPN_BLOCK : ns;
        air_forces(w, lo, hi, x, v);
        double p = 0;
        for (uint32_t s = lo; s < hi; s++) {
            if (!(w->sdiam[s] > 0)) continue;
            const uint32_t a = w->hs[s].a, b = spn__end_b(w->hs[s]);
            /* half the segment's force on each end; a fixed end takes no work */
            const spn_vec3 va = w->inv_mass[a] > 0 ? v[a] : spn_v3(0, 0, 0);
            const spn_vec3 vb = w->inv_mass[b] > 0 ? v[b] : spn_v3(0, 0, 0);
            p += 0.5 * spn_v3_dot(w->fair[s], spn_v3_add(va, vb));
        }
        partial[(size_t)blk * SPN_NSUMS] = p;
    }
    double power = 0;
    for (uint32_t blk = 0; blk < nb; blk++) power += partial[(size_t)blk * SPN_NSUMS];
    return power;
}

bool spn__external_user(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v)
{
    if (!w->force_fn && !spn__air_active(w)) return false;
    memset(w->fext, 0, w->np * sizeof *w->fext);
    if (w->force_fn) w->force_fn(w->force_user, w, t, x, v, w->fext);
    return true;
}

void spn__gather(spn_world *w, const spn_vec3 *x, const spn_vec3 *v, bool has_ext, spn_vec3 *f, spn__eval *e)
{
    (void)x;
    const uint32_t np = w->np, nb = spn__blocks(np);
    const double drag = w->def.drag;
    double *partial = w->partial;
    const spn__gather_ctx ctx = spn__gather_ctx_of(w);
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        const spn__gather_ctx c = ctx;
        double ke = 0, dp = 0, ep = 0;
        for (uint32_t i = lo; i < hi; i++) {
            const spn_vec3 vi = v[i];
            f[i] = spn__force_on(&c, i, vi, has_ext, false);
            if (w->inv_mass[i] == 0) continue;
            const double v2 = spn_v3_dot(vi, vi), m = w->mass[i];
            ke += 0.5 * m * v2;
            dp += drag * m * v2;
            if (has_ext) ep += spn_v3_dot(w->fext[i], vi);
        }
        partial[(size_t)blk * SPN_NSUMS + 0] = ke;
        partial[(size_t)blk * SPN_NSUMS + 1] = dp;
        partial[(size_t)blk * SPN_NSUMS + 2] = ep;
    }
    for (uint32_t blk = 0; blk < nb; blk++) {
        e->kinetic += partial[(size_t)blk * SPN_NSUMS + 0];
        e->damp_power += partial[(size_t)blk * SPN_NSUMS + 1];
        e->ext_power += partial[(size_t)blk * SPN_NSUMS + 2];
    }
}

void spn__eval_forces(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f, spn__eval *e)
{
    spn__spring_pass(w, t, x, v, e);
    bool ext = spn__external(w, t, x, v);
    spn__gather(w, x, v, ext, f, e);
}

double spn__kinetic_energy(const spn_world *w, const spn_vec3 *v)
{
    double e = 0;
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) e += 0.5 * w->mass[i] * spn_v3_dot(v[i], v[i]);
    return e;
}

double spn__elastic_energy(const spn_world *w, const spn_vec3 *x)
{
    double e = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        double d = spn_v3_len(spn_v3_sub(x[w->sa[s]], x[w->sb[s]])) - w->rest[s];
        if (d < 0 && (w->sflags[s] & SPN_SPRING_TENSION_ONLY)) continue;
        e += 0.5 * w->k[s] * d * d;
    }
    return e;
}

double spn__gravity_energy(const spn_world *w, const spn_vec3 *x)
{
    double e = 0;
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) e -= w->mass[i] * spn_v3_dot(w->def.gravity, x[i]);
    return e;
}

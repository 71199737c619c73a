/* A turbulent air velocity field U(x, t) for aerodynamic drag on threads.
 *
 *   U(x, t) = s(t) d + u'(x - d X(t), t)
 *
 * Mean wind: speed s(t) = S (1 + gust G(t)) along d, where G is a sum of six
 * sines of random phase and periods spread around `gust_period` (zero mean,
 * unit variance, smooth), and X(t) = integral of s, known in closed form.
 * Turbulence u': random Fourier modes (Kraichnan's method),
 *   u' = sum_n a_n xi_n cos(k_n . y + w_n t + phi_n),
 * with |k_n| log-spaced between 2 pi / integral_scale and 2 pi / small_scale,
 * random directions, xi_n a unit vector normal to k_n (so div u' = 0), and
 * a_n^2 proportional to E(k) dk = k^(-5/3) k dln k: the Kolmogorov inertial
 * range. The amplitudes are scaled so each component has rms turbulence * S.
 * The field is carried along by the mean wind (Taylor's frozen turbulence)
 * and each mode also decorrelates at the eddy turnover rate
 * w_n = sigma k_n^(2/3) L^(-1/3). Chosen over moving noise octaves because
 * its spectrum and divergence are exact and it needs no lattice.
 *
 * Cost: the exact sum is `modes` cosines per point. For a web of thousands of
 * segments per step the turbulent part is cached on a coarse grid at time
 * slices and interpolated (trilinear, then linear in time); the mean wind is
 * always exact. spn_air_prepare fills slices before a step, sampling only
 * reads, so the world may sample from several threads. A slice is filled
 * without a cosine per node and mode: on the grid a mode's phase is a sum
 * a_i + b_j + c_k over the three axes, so its cosine is the real part of
 * e^(i a_i) e^(i b_j) e^(i c_k), factors taken once per axis node (fill_rows). */
#include "anim_internal.h"

#include "core/kernel.h"

#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define GUST_SINES 6
/* Grid rows a slice fills beyond those the samples have touched (see
 * air_rows). */
#define ROW_MARGIN 2
#define MAX_SLICES 8

typedef struct air_mode {
    spn_vec3 k, xi;   /* wave vector [1/m], amplitude vector [m/s] */
    double omega, phi;
} air_mode;

/* A time a step samples at, taken once for all its samples: the mean wind
 * (six sines, a fifth of an explicit step in air before it was kept) and the
 * two slices around it (NULL: not both ready) with the fraction between. */
typedef struct air_time {
    double t; /* NaN: none */
    spn_vec3 mean;
    const struct air_slice *a, *b;
    double f;
} air_time;

/* A rectangle of grid rows (j along y, k along z; a row is every node
 * along x): j0..j1, k0..k1, inclusive; empty when j0 > j1. */
typedef struct air_rows {
    int j0, j1, k0, k1;
} air_rows;

/* Whether r holds every row of s (a non-empty s). */
static inline bool rows_hold(air_rows r, air_rows s)
{
    return s.j0 >= r.j0 && s.j1 <= r.j1 && s.k0 >= r.k0 && s.k1 <= r.k1;
}

/* The smallest rectangle holding the rows of both (rows_span), and the rows
 * both hold (rows_meet). */
static inline air_rows rows_span(air_rows a, air_rows b)
{
    return (air_rows){a.j0 < b.j0 ? a.j0 : b.j0, a.j1 > b.j1 ? a.j1 : b.j1, a.k0 < b.k0 ? a.k0 : b.k0,
                      a.k1 > b.k1 ? a.k1 : b.k1};
}

static inline air_rows rows_meet(air_rows a, air_rows b)
{
    return (air_rows){a.j0 > b.j0 ? a.j0 : b.j0, a.j1 < b.j1 ? a.j1 : b.j1, a.k0 > b.k0 ? a.k0 : b.k0,
                      a.k1 < b.k1 ? a.k1 : b.k1};
}

typedef struct air_slice {
    int64_t index;    /* time = index * slice_dt; INT64_MIN when empty */
    spn_vec3 *u;      /* turbulent velocity at the grid nodes */
    air_rows have;    /* the rows filled (the others hold nothing) */
} air_slice;

struct spn_air_field {
    spn_air_def def;
    spn_vec3 dir;
    air_mode *modes;
    int nmodes;
    double gust_amp[GUST_SINES], gust_omega[GUST_SINES], gust_phase[GUST_SINES];
    /* grid cache */
    bool grid;
    spn_vec3 lo, hi;
    int n[3];
    double slice_dt;
    air_slice slices[MAX_SLICES];
    /* fill_rows' scratch: per mode cos and sin of its phase along each
     * axis (axis_stride: n[0] rounded up to eight, zeros past it, then
     * n[1] + n[2]), and a grid row's sums */
    double *axis_cos, *axis_sin, *row;
    /* the times spn_air_prepare was last told of (t0, t1 and their
     * midpoint), at which a step samples the air at its particles */
    air_time times[3];
    /* The rows the samples have touched (their cells' corners): the lowest
     * and highest j and k, kept by the samplers (several threads) and read
     * by spn_air_prepare, which fills those rows, ROW_MARGIN more on each
     * side, and no others. A web is a sheet in a box grown by half its
     * size on every side: in 0.3 s of --wind air the README's physical web
     * touched 390 of its 48 x 48 x 30 grid's 1,440 rows, the Araneus web
     * in 2 s 108 of its 26 x 14 = 364. Empty (INT_MAX, INT_MIN, ...) until the first
     * sample; the first slices are filled whole. */
    atomic_int seen[4];
};

spn_air_def spn_air_def_default(void)
{
    spn_air_def d;
    d.speed = 1;
    d.direction = spn_v3(0, 0, -1);
    d.gust = 0.3;
    d.gust_period = 4;
    d.turbulence = 0.15;
    d.integral_scale = 1;
    d.small_scale = 0.15;
    d.modes = 64;
    d.rho = 1.204;
    d.mu = 1.81e-5;
    d.seed = 1;
    d.stop = INFINITY;
    return d;
}

static spn_status check_def(const spn_air_def *d)
{
    if (!(d->speed >= 0) || !isfinite(d->speed)) return spn_error(SPN_ERR_INVALID, "air: wind speed must be >= 0");
    if (!spn_v3_finite(d->direction) || !(spn_v3_len(d->direction) > 0))
        return spn_error(SPN_ERR_INVALID, "air: wind direction must be a non-zero vector");
    if (!(d->gust >= 0) || !(d->gust <= 1)) return spn_error(SPN_ERR_INVALID, "air: gust must be in [0, 1]");
    if (!(d->gust_period > 0) || !isfinite(d->gust_period))
        return spn_error(SPN_ERR_INVALID, "air: gust period must be > 0");
    if (!(d->turbulence >= 0) || !(d->turbulence <= 2))
        return spn_error(SPN_ERR_INVALID, "air: turbulence must be in [0, 2]");
    if (!(d->small_scale > 0) || !(d->integral_scale >= d->small_scale) || !isfinite(d->integral_scale))
        return spn_error(SPN_ERR_INVALID, "air: need 0 < small scale <= integral scale");
    if (d->modes < 1 || d->modes > 4096) return spn_error(SPN_ERR_INVALID, "air: modes must be in [1, 4096]");
    if (!(d->rho > 0) || !(d->mu > 0) || !isfinite(d->rho) || !isfinite(d->mu))
        return spn_error(SPN_ERR_INVALID, "air: density and viscosity must be > 0");
    if (isnan(d->stop)) return spn_error(SPN_ERR_INVALID, "air: stop time must be a number");
    return SPN_OK;
}

static spn_vec3 random_unit(spn_rng *rng)
{
    double z = spn_rng_range(rng, -1, 1), a = spn_rng_range(rng, 0, 2 * SPN_PI);
    double r = sqrt(fmax(0, 1 - z * z));
    return spn_v3(r * cos(a), r * sin(a), z);
}

static void make_modes(spn_air_field *air, spn_rng *rng)
{
    const spn_air_def *d = &air->def;
    double kmin = 2 * SPN_PI / d->integral_scale, kmax = 2 * SPN_PI / d->small_scale;
    double sigma = d->turbulence * d->speed, sum = 0;
    for (int n = 0; n < air->nmodes; n++) {
        double f = air->nmodes > 1 ? (double)n / (air->nmodes - 1) : 0;
        double kn = kmin * pow(kmax / kmin, f);
        spn_vec3 khat = random_unit(rng), xi;
        do {
            xi = spn_v3_cross(khat, random_unit(rng));
        } while (spn_v3_len(xi) < 1e-3);
        air_mode *m = &air->modes[n];
        m->k = spn_v3_scale(khat, kn);
        m->xi = spn_v3_scale(spn_v3_norm(xi), pow(kn, -1.0 / 3));
        m->omega = sigma * pow(kn, 2.0 / 3) * pow(d->integral_scale, -1.0 / 3);
        m->phi = spn_rng_range(rng, 0, 2 * SPN_PI);
        sum += pow(kn, -2.0 / 3);
    }
    /* Each mode gives each component a variance of |a|^2 / 6 on average. */
    double c = sum > 0 ? sigma * sqrt(6 / sum) : 0;
    for (int n = 0; n < air->nmodes; n++) air->modes[n].xi = spn_v3_scale(air->modes[n].xi, c);
}

static void make_gusts(spn_air_field *air, spn_rng *rng)
{
    for (int j = 0; j < GUST_SINES; j++) {
        double period = air->def.gust_period * exp(spn_rng_range(rng, -0.7, 0.7));
        air->gust_omega[j] = 2 * SPN_PI / period;
        air->gust_phase[j] = spn_rng_range(rng, 0, 2 * SPN_PI);
        air->gust_amp[j] = sqrt(2.0 / GUST_SINES);
    }
}

spn_status spn_air_create(const spn_air_def *def, spn_air_field **out)
{
    *out = NULL;
    spn_air_def d = def ? *def : spn_air_def_default();
    spn_status st = check_def(&d);
    if (st != SPN_OK) return st;
    spn_air_field *air = calloc(1, sizeof *air);
    if (air) air->modes = calloc((size_t)d.modes, sizeof *air->modes);
    if (!air || !air->modes) {
        free(air);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    air->def = d;
    air->dir = spn_v3_norm(d.direction);
    air->nmodes = d.modes;
    spn_rng rng;
    spn_rng_seed(&rng, d.seed);
    make_gusts(air, &rng);
    make_modes(air, &rng);
    for (int i = 0; i < MAX_SLICES; i++) air->slices[i].index = INT64_MIN;
    for (int i = 0; i < 3; i++) air->times[i].t = NAN;
    *out = air;
    return SPN_OK;
}

void spn_air_destroy(spn_air_field *air)
{
    if (!air) return;
    for (int i = 0; i < MAX_SLICES; i++) free(air->slices[i].u);
    free(air->axis_cos), free(air->axis_sin), free(air->row);
    free(air->modes);
    free(air);
}

static double gust_factor(const spn_air_field *air, double t)
{
    if (air->def.gust == 0) return 1;
    double g = 0;
    for (int j = 0; j < GUST_SINES; j++) g += air->gust_amp[j] * sin(air->gust_omega[j] * t + air->gust_phase[j]);
    return 1 + air->def.gust * g;
}

/* X(t) = integral from 0 to t of the mean speed. */
static double advection(const spn_air_field *air, double t)
{
    double x = t;
    for (int j = 0; j < GUST_SINES; j++) {
        double w = air->gust_omega[j], p = air->gust_phase[j];
        x += air->def.gust * air->gust_amp[j] * (cos(p) - cos(w * t + p)) / w;
    }
    return air->def.speed * x;
}

/* Whether the air is still at time t (spn_air_def.stop). */
static bool stopped(const spn_air_field *air, double t) { return t >= air->def.stop; }

spn_vec3 spn_air_mean(const spn_air_field *air, double t)
{
    if (stopped(air, t)) return spn_v3(0, 0, 0);
    return spn_v3_scale(air->dir, air->def.speed * gust_factor(air, t));
}

static spn_vec3 turbulence_at(const spn_air_field *air, double t, double shift, spn_vec3 p)
{
    spn_vec3 y = spn_v3_sub(p, spn_v3_scale(air->dir, shift)), u = spn_v3(0, 0, 0);
    if (air->def.turbulence == 0) return u;
    for (int n = 0; n < air->nmodes; n++) {
        const air_mode *m = &air->modes[n];
        u = spn_v3_add(u, spn_v3_scale(m->xi, cos(spn_v3_dot(m->k, y) + m->omega * t + m->phi)));
    }
    return u;
}

spn_vec3 spn_air_velocity(const spn_air_field *air, double t, spn_vec3 p)
{
    spn_vec3 mean = spn_air_mean(air, t);
    if (air->def.turbulence == 0 || air->def.speed == 0 || stopped(air, t)) return mean;
    return spn_v3_add(mean, turbulence_at(air, t, advection(air, t), p));
}

/* Numbers per mode in axis_cos and axis_sin: the x axis padded to a
 * multiple of eight (slice_row reads eight at a time), then y and z. */
static size_t axis_stride(int nx, int ny, int nz) { return ((size_t)nx + 7) / 8 * 8 + (size_t)ny + nz; }

static spn_vec3 node_position(const spn_air_field *air, int i, int j, int k)
{
    return spn_v3(air->lo.x + (air->hi.x - air->lo.x) * i / (air->n[0] - 1),
                  air->lo.y + (air->hi.y - air->lo.y) * j / (air->n[1] - 1),
                  air->lo.z + (air->hi.z - air->lo.z) * k / (air->n[2] - 1));
}

/* No rows touched yet (air_rows: empty). */
static void forget_rows(spn_air_field *air)
{
    atomic_store_explicit(&air->seen[0], INT_MAX, memory_order_relaxed);
    atomic_store_explicit(&air->seen[1], INT_MIN, memory_order_relaxed);
    atomic_store_explicit(&air->seen[2], INT_MAX, memory_order_relaxed);
    atomic_store_explicit(&air->seen[3], INT_MIN, memory_order_relaxed);
}

/* Each mode's cosines and sines of its phase along x and y (fill_rows):
 * they do not depend on time, so they are taken once per grid; along z the
 * phase holds the time's part too (fill_rows). */
static void axis_factors_xy(spn_air_field *air)
{
    const int nx = air->n[0], ny = air->n[1], nz = air->n[2];
    const size_t per = axis_stride(nx, ny, nz), y0 = per - ny - nz;
    for (int n = 0; n < air->nmodes; n++) {
        const air_mode *m = &air->modes[n];
        double *c = air->axis_cos + (size_t)n * per, *sn = air->axis_sin + (size_t)n * per;
        for (int i = 0; i < nx; i++) {
            const double a = m->k.x * node_position(air, i, 0, 0).x;
            c[i] = cos(a), sn[i] = sin(a);
        }
        for (size_t i = (size_t)nx; i < y0; i++) c[i] = sn[i] = 0; /* padding */
        for (int j = 0; j < ny; j++) {
            const double b = m->k.y * node_position(air, 0, j, 0).y;
            c[y0 + j] = cos(b), sn[y0 + j] = sin(b);
        }
    }
}

spn_status spn_air_set_grid(spn_air_field *air, spn_vec3 lo, spn_vec3 hi, int nx, int ny, int nz, double slice_dt)
{
    if (nx < 2 || ny < 2 || nz < 2 || (int64_t)nx * ny * nz > 1 << 22)
        return spn_error(SPN_ERR_INVALID, "air grid: need 2..4M nodes with at least 2 per axis");
    if (!(slice_dt > 0) || !spn_v3_finite(lo) || !spn_v3_finite(hi) || !(hi.x > lo.x) || !(hi.y > lo.y) ||
        !(hi.z > lo.z))
        return spn_error(SPN_ERR_INVALID, "air grid: need a non-empty box and slice_dt > 0");
    size_t nodes = (size_t)nx * ny * nz;
    for (int i = 0; i < MAX_SLICES; i++) {
        /* (one number past the nodes: the last node's along_x reads it) */
        spn_vec3 *u = realloc(air->slices[i].u, nodes * sizeof *u + sizeof(double));
        if (!u) return spn_error(SPN_ERR_NOMEM, "out of memory");
        ((double *)u)[3 * nodes] = 0;
        air->slices[i].u = u;
        air->slices[i].index = INT64_MIN;
        air->slices[i].have = (air_rows){0, -1, 0, -1};
    }
    const size_t axes = (size_t)air->nmodes * axis_stride(nx, ny, nz);
    double *c = realloc(air->axis_cos, axes * sizeof *c);
    if (c) air->axis_cos = c;
    double *sn = c ? realloc(air->axis_sin, axes * sizeof *sn) : NULL;
    if (sn) air->axis_sin = sn;
    double *row = sn ? realloc(air->row, 2 * (size_t)air->nmodes * sizeof *row) : NULL;
    if (!row) return spn_error(SPN_ERR_NOMEM, "out of memory");
    air->row = row;
    for (int i = 0; i < 3; i++) air->times[i].t = NAN; /* their slices are gone */
    air->grid = true;
    air->lo = lo;
    air->hi = hi;
    air->n[0] = nx;
    air->n[1] = ny;
    air->n[2] = nz;
    air->slice_dt = slice_dt;
    forget_rows(air);
    axis_factors_xy(air);
    return SPN_OK;
}

/* Eight numbers on one vector (GCC vector extension: AVX-512, AVX pairs,
 * SSE2 fours; elementwise IEEE operations, so each lane has the scalar
 * code's bits). */
typedef double air_v8 __attribute__((vector_size(8 * sizeof(double))));

/* Grid row (j, k) of a slice into `out`: each node's turbulent velocity,
 * the modes added in their order (see fill_rows); `w` is 2 nmodes doubles
 * of scratch. Eight nodes at a time, their sums held in vectors through
 * all the modes (a node's sum is the same sequence of operations as one
 * node at a time; the row's last eight may reach into the x axis'
 * padding, whose sums are not stored); vectorised for each
 * instruction set (CMakeLists.txt compiles this file with the physics
 * kernels' flags); no contraction, so every version gives the same bits. */
SPN__KERNEL static void slice_row(const spn_air_field *air, int j, int k, double *restrict w, spn_vec3 *restrict out)
{
    const int nx = air->n[0], ny = air->n[1], nm = air->nmodes;
    const size_t per = axis_stride(nx, ny, air->n[2]), y0 = per - ny - air->n[2];
    if (air->def.turbulence == 0) {
        for (int i = 0; i < nx; i++) out[i] = spn_v3(0, 0, 0);
        return;
    }
    /* each mode's e^(i (B_j + C_k)) */
    double *restrict re = w, *restrict im = w + nm;
    for (int n = 0; n < nm; n++) {
        const double *ca = air->axis_cos + (size_t)n * per, *sa = air->axis_sin + (size_t)n * per;
        const double cb = ca[y0 + j], sb = sa[y0 + j], cc = ca[y0 + ny + k], sc = sa[y0 + ny + k];
        re[n] = cb * cc - sb * sc, im[n] = sb * cc + cb * sc;
    }
    for (int i = 0; i < nx; i += 8) {
        air_v8 ux = {0}, uy = {0}, uz = {0};
        for (int n = 0; n < nm; n++) {
            air_v8 c, s;
            memcpy(&c, air->axis_cos + (size_t)n * per + i, sizeof c);
            memcpy(&s, air->axis_sin + (size_t)n * per + i, sizeof s);
            const air_v8 v = c * re[n] - s * im[n];
            const spn_vec3 xi = air->modes[n].xi;
            ux += xi.x * v, uy += xi.y * v, uz += xi.z * v;
        }
        const int lanes = nx - i < 8 ? nx - i : 8; /* (the last eight may run past the row: padding) */
        for (int l = 0; l < lanes; l++) out[i + l] = spn_v3(ux[l], uy[l], uz[l]);
    }
}

/* Slice `index`'s rows r (a slice of another index is emptied first): the
 * turbulent velocity at their nodes, the rows it has left as they are; r
 * holds the rows it has (spn_air_prepare). Mode n's phase
 * at node (i, j, k) is k_n . (p - d X(t)) + w_n t + phi_n = A_i + B_j + C_k,
 * with A_i = k_x x_i, B_j = k_y y_j and C_k = k_z z_k plus the constant part.
 * Its cosine is cos A cos(B + C) - sin A sin(B + C), the angle sum B + C
 * by the same rule, from each axis' cosines and sines, which libm gives
 * once per node of each axis: n0 + n1 + n2 of each per mode instead of
 * n0 n1 n2 cosines.
 * The factors are within an ulp each, so a node's value is within a few ulp
 * of |xi_n| per mode of turbulence_at's (tests/test_anim_air.c checks the
 * nodes against it). The modes add in their order, as turbulence_at adds
 * them. 48^3 nodes of 64 modes, the runner's largest grid: 137 ms a slice
 * with a cosine each, 10.7 ms with the factors; 16^3: 5.7 and 0.26 ms (Zen
 * 5, bench/bench_air.c, which then timed the first touches of the slice
 * buffers too). Since the rows are a vectorised kernel (slice_row) a 48^3
 * slice takes 3.3-3.7 ms against 4.2-4.3 in steady use; since slice_row
 * keeps eight nodes' sums in vectors through the modes (forty-ninth
 * session), 1.65 (16^3: 0.184 -> 0.101), with the same bits. Since the
 * fifty-second session the x and y factors are taken once per grid and a
 * slice fills the rows its samples need (air_rows): a value is the same
 * bits as in a slice filled whole. */
static void fill_rows(spn_air_field *air, air_slice *s, int64_t index, air_rows r)
{
    if (s->index != index) s->index = index, s->have = (air_rows){0, -1, 0, -1};
    const air_rows h = s->have;
    if (rows_hold(h, r)) return;
    const double t = (double)index * air->slice_dt, shift = advection(air, t);
    const int nx = air->n[0], ny = air->n[1], nz = air->n[2], nm = air->nmodes;
    const size_t per = axis_stride(nx, ny, nz), y0 = per - ny - nz;
    for (int n = 0; n < nm; n++) {
        const air_mode *m = &air->modes[n];
        double *c = air->axis_cos + (size_t)n * per, *sn = air->axis_sin + (size_t)n * per;
        const double c0 = m->omega * t + m->phi - shift * spn_v3_dot(m->k, air->dir);
        for (int k = r.k0; k <= r.k1; k++) {
            const double g = m->k.z * node_position(air, 0, 0, k).z + c0;
            c[y0 + ny + k] = cos(g), sn[y0 + ny + k] = sin(g);
        }
    }
    for (int k = r.k0; k <= r.k1; k++)
        for (int j = r.j0; j <= r.j1; j++)
            if (!rows_hold(h, (air_rows){j, j, k, k}))
                slice_row(air, j, k, air->row, s->u + ((size_t)k * ny + j) * nx);
    s->have = r;
}

static const air_slice *find_slice(const spn_air_field *air, int64_t index)
{
    for (int i = 0; i < MAX_SLICES; i++)
        if (air->slices[i].index == index) return &air->slices[i];
    return NULL;
}

/* Time t taken for sampling: its mean wind and the slices around it. */
static air_time time_of(const spn_air_field *air, double t)
{
    air_time at = {t, spn_air_mean(air, t), NULL, NULL, 0};
    if (!air->grid) return at;
    const double g = t / air->slice_dt;
    const int64_t idx = (int64_t)floor(g);
    at.f = g - (double)idx;
    at.a = find_slice(air, idx), at.b = at.f == 0 ? at.a : find_slice(air, idx + 1); /* (f 0: sample_cell reads a) */
    return at;
}

static void prepare_times(spn_air_field *air, double t0, double t1)
{
    const double at[3] = {t0, t1, 0.5 * (t0 + t1)};
    for (int i = 0; i < 3; i++) air->times[i] = time_of(air, at[i]);
}

/* The rows a slice is to have: those the samples have touched and
 * ROW_MARGIN more on each side, or, before the first sample, all. */
static air_rows rows_wanted(const spn_air_field *air)
{
    const int ny = air->n[1], nz = air->n[2];
    int sj0 = atomic_load_explicit(&air->seen[0], memory_order_relaxed);
    int sj1 = atomic_load_explicit(&air->seen[1], memory_order_relaxed);
    int sk0 = atomic_load_explicit(&air->seen[2], memory_order_relaxed);
    int sk1 = atomic_load_explicit(&air->seen[3], memory_order_relaxed);
    if (sj0 > sj1 || sk0 > sk1) return (air_rows){0, ny - 1, 0, nz - 1};
    const int j0 = sj0 - ROW_MARGIN, j1 = sj1 + ROW_MARGIN, k0 = sk0 - ROW_MARGIN, k1 = sk1 + ROW_MARGIN;
    return (air_rows){j0 > 0 ? j0 : 0, j1 < ny - 1 ? j1 : ny - 1, k0 > 0 ? k0 : 0, k1 < nz - 1 ? k1 : nz - 1};
}

spn_status spn_air_prepare(spn_air_field *air, double t0, double t1)
{
    /* (without a grid a sample is exact, and still air is zero: no slices) */
    if (!air->grid || stopped(air, t0)) return SPN_OK;
    int64_t a = (int64_t)floor(t0 / air->slice_dt), b = (int64_t)floor(t1 / air->slice_dt) + 1;
    if (b - a + 1 > MAX_SLICES) b = a + MAX_SLICES - 1;
    const air_rows want = rows_wanted(air);
    for (int64_t idx = a; idx <= b; idx++) {
        air_slice *s = (air_slice *)find_slice(air, idx);
        if (!s) /* evict a slice outside [a, b], the oldest first */
            for (int i = 0; i < MAX_SLICES; i++) {
                air_slice *o = &air->slices[i];
                if (o->index >= a && o->index <= b) continue;
                if (!s || o->index < s->index) s = o;
            }
        if (!s) continue;
        /* (the rows wanted and those it has: want only grows, but a slice
         * filled whole at first has more) */
        fill_rows(air, s, idx, s->index == idx ? rows_span(want, s->have) : want);
    }
    prepare_times(air, t0, t1);
    return SPN_OK;
}

/* Time t as a sample takes it: one of the prepared times, or found now. */
static air_time sample_time(const spn_air_field *air, double t)
{
    for (int i = 0; i < 3; i++)
        if (air->times[i].t == t) return air->times[i];
    return time_of(air, t);
}

/* What a sample between the slices of a time reads: the slices as
 * numbers, the time's fraction between them and its mean wind, the grid. */
typedef struct air_points {
    const double *a, *b;
    double f;
    spn_vec3 mean;
    int nx, ny, nz, sy, sz; /* (sy, sz: numbers from a node to the next along y and z) */
    double lx, ly, lz, wx, wy, wz;
    air_rows rows; /* the rows both slices have: a cell outside is sampled exactly */
    spn_air_field *air;
    double t;
} air_points;

_Static_assert(sizeof(spn_vec3) == 3 * sizeof(double), "sample_cell reads a slice's nodes as numbers");
static air_points points_of(spn_air_field *air, const air_time *at)
{
    const int nx = air->n[0], ny = air->n[1];
    const air_rows both = rows_meet(at->a->have, at->b->have);
    return (air_points){(const double *)at->a->u, (const double *)at->b->u, at->f, at->mean, nx, ny, air->n[2],
                        3 * nx, 3 * nx * ny, air->lo.x, air->lo.y, air->lo.z, air->hi.x - air->lo.x,
                        air->hi.y - air->lo.y, air->hi.z - air->lo.z, both, air, at->t};
}

/* Where *p falls in the grid: its cell's first number `b` in a slice (node
 * (ix, iy, iz), the cell's low corner; the box clamps p, NaN goes to its
 * low corner) and the fractions fx, fy, fz across the cell. Node indices
 * are ints: a grid has at most 2^22 nodes (spn_air_set_grid), 3 * 2^22
 * numbers. */
typedef struct air_cell {
    int b, j, k; /* (j, k: the cell's low row, iy and iz) */
    double fx, fy, fz;
} air_cell;

SPN__INLINE air_cell cell_of(const air_points *g, const spn_vec3 *p)
{
    const int nx = g->nx, ny = g->ny, nz = g->nz;
    double gx = (p->x - g->lx) / g->wx * (nx - 1), gy = (p->y - g->ly) / g->wy * (ny - 1),
           gz = (p->z - g->lz) / g->wz * (nz - 1);
    gx = gx > 0 ? gx : 0, gy = gy > 0 ? gy : 0, gz = gz > 0 ? gz : 0;
    gx = gx > nx - 1 ? nx - 1 : gx, gy = gy > ny - 1 ? ny - 1 : gy, gz = gz > nz - 1 ? nz - 1 : gz;
    int ix = (int)gx, iy = (int)gy, iz = (int)gz;
    ix = ix > nx - 2 ? nx - 2 : ix, iy = iy > ny - 2 ? ny - 2 : iy, iz = iz > nz - 2 ? nz - 2 : iz;
    return (air_cell){3 * ix + g->sy * iy + g->sz * iz, iy, iz, gx - ix, gy - iy, gz - iz};
}

/* Four numbers on one vector (AVX, SSE2 pairs; elementwise IEEE
 * operations, as air_v8). */
typedef double air_v4 __attribute__((vector_size(4 * sizeof(double))));

/* a + (b - a) f in each lane, the interpolation's one rule (vectors pass
 * by pointer or in macros: the default version has no AVX registers to
 * pass them in, -Wpsabi) */
#define AIR_LERP4(a, b, f) ((a) + ((b) - (a)) * (f))

/* The three components of node q and of its neighbour along x (q + 3)
 * interpolated by fx, in lanes 0-2 of *r (lane 3 is the next node's x, or
 * a slice's padding at its end, and is never used). */
SPN__INLINE void along_x(const double *S, int q, double fx, air_v4 *r)
{
    air_v4 a, b;
    memcpy(&a, S + q, sizeof a), memcpy(&b, S + q + 3, sizeof b);
    *r = AIR_LERP4(a, b, fx);
}

/* Slice S trilinearly at cell c into *r: along x, then y, then z, each
 * component in a lane. */
SPN__INLINE void in_slice(const air_points *g, const double *S, const air_cell *c, air_v4 *r)
{
    const int q = c->b, sy = g->sy, sz = g->sz;
    air_v4 x00, x10, x01, x11;
    along_x(S, q, c->fx, &x00), along_x(S, q + sy, c->fx, &x10);
    along_x(S, q + sz, c->fx, &x01), along_x(S, q + sz + sy, c->fx, &x11);
    const air_v4 y0 = AIR_LERP4(x00, x10, c->fy), y1 = AIR_LERP4(x01, x11, c->fy);
    *r = AIR_LERP4(y0, y1, c->fz);
}

/* The field at cell c into *out: the two slices interpolated in it, then
 * linearly between them by f, and the mean wind added. A point's 48
 * numbers are 16 runs of four (each node's three components and the next
 * number), read as vectors: a point's components are the lanes. At a
 * slice's own time (f 0: the times a world at the field's resolution
 * samples, spn_world_set_air_resolution) the first slice alone, the same
 * numbers but for the sign of a zero. */
SPN__INLINE void sample_cell(const air_points *g, const air_cell *c, spn_vec3 *out)
{
    air_v4 u;
    in_slice(g, g->a, c, &u);
    if (g->f != 0) {
        air_v4 ub;
        in_slice(g, g->b, c, &ub);
        u = AIR_LERP4(u, ub, g->f);
    }
    out->x = g->mean.x + u[0], out->y = g->mean.y + u[1], out->z = g->mean.z + u[2];
}

/* Whether cell c's rows (j and j + 1, k and k + 1) are in r. */
SPN__INLINE bool cell_in(const air_cell *c, air_rows r)
{
    return rows_hold(r, (air_rows){c->j, c->j + 1, c->k, c->k + 1});
}

/* *a lowered to v, or raised to v, where v is past it (several threads may
 * update *a at once). */
static void lower_to(atomic_int *a, int v)
{
    int o = atomic_load_explicit(a, memory_order_relaxed);
    while (v < o && !atomic_compare_exchange_weak_explicit(a, &o, v, memory_order_relaxed, memory_order_relaxed)) {}
}

static void raise_to(atomic_int *a, int v)
{
    int o = atomic_load_explicit(a, memory_order_relaxed);
    while (v > o && !atomic_compare_exchange_weak_explicit(a, &o, v, memory_order_relaxed, memory_order_relaxed)) {}
}

/* Rows j0..j1, k0..k1 touched: into the field's record (air->seen). */
static void touched(spn_air_field *air, int j0, int j1, int k0, int k1)
{
    lower_to(&air->seen[0], j0), raise_to(&air->seen[1], j1);
    lower_to(&air->seen[2], k0), raise_to(&air->seen[3], k1);
}

/* The field at n points: their cells in one loop, which GCC vectorises
 * (the points in its lanes), then each point's interpolation on its own
 * vectors; a batch at a time, its cells on the stack. A point whose cell
 * reaches rows the slices do not have (the web moved more than
 * ROW_MARGIN rows since the last step) takes the field itself,
 * spn_air_velocity; the rows every cell touched go into the field's record
 * for the next spn_air_prepare. spn_air_sample takes one point the same
 * way (sample_one), so the two give the same bits. On the Zen 5
 * (bench_air, random points, alternating runs) a point takes 14.1-14.4 ns
 * on a 48^3 grid and 8.4-8.6 on 16^3; with the points in the lanes of one
 * loop and their 48 numbers gathered (until the fifty-second session) it
 * took 25.5-28.2 and 14.6-20.9 ns. */
#define AIR_CELLS 64
SPN__KERNEL static void sample_points(air_points g, const spn_vec3 *restrict p, spn_vec3 *restrict out, size_t n)
{
    air_cell c[AIR_CELLS];
    int j0 = INT_MAX, j1 = INT_MIN, k0 = INT_MAX, k1 = INT_MIN;
    for (size_t i0 = 0; i0 < n; i0 += AIR_CELLS) {
        const size_t m = n - i0 < AIR_CELLS ? n - i0 : AIR_CELLS;
        int b0 = INT_MAX, b1 = INT_MIN, d0 = INT_MAX, d1 = INT_MIN; /* (the batch's rows) */
        for (size_t i = 0; i < m; i++) {
            c[i] = cell_of(&g, p + i0 + i);
            b0 = c[i].j < b0 ? c[i].j : b0, b1 = c[i].j > b1 ? c[i].j : b1;
            d0 = c[i].k < d0 ? c[i].k : d0, d1 = c[i].k > d1 ? c[i].k : d1;
        }
        if (rows_hold(g.rows, (air_rows){b0, b1 + 1, d0, d1 + 1}))
            for (size_t i = 0; i < m; i++) sample_cell(&g, &c[i], out + i0 + i);
        else
            for (size_t i = 0; i < m; i++)
                if (cell_in(&c[i], g.rows)) sample_cell(&g, &c[i], out + i0 + i);
                else out[i0 + i] = spn_air_velocity(g.air, g.t, p[i0 + i]);
        j0 = b0 < j0 ? b0 : j0, j1 = b1 > j1 ? b1 : j1, k0 = d0 < k0 ? d0 : k0, k1 = d1 > k1 ? d1 : k1;
    }
    if (n) touched(g.air, j0, j1 + 1, k0, k1 + 1);
}

/* One point, as sample_points takes it (a batch of one costs twice as
 * much: the cell loop's vector set-up). */
SPN__KERNEL static void sample_one(const air_points *g, const spn_vec3 *p, spn_vec3 *out)
{
    const air_cell c = cell_of(g, p);
    if (cell_in(&c, g->rows)) sample_cell(g, &c, out);
    else *out = spn_air_velocity(g->air, g->t, *p);
    touched(g->air, c.j, c.j + 1, c.k, c.k + 1);
}

void spn_air_sample_batch(void *user, double t, const spn_vec3 *p, spn_vec3 *out, size_t n)
{
    spn_air_field *air = user;
    const air_time at = air->grid && !stopped(air, t) ? sample_time(air, t) : (air_time){0};
    if (!at.a || !at.b) { /* no grid, its slices not ready, or still air: the field itself */
        for (size_t i = 0; i < n; i++) out[i] = spn_air_velocity(air, t, p[i]);
        return;
    }
    const air_points g = points_of(air, &at);
    sample_points(g, p, out, n);
}

spn_vec3 spn_air_sample(void *user, double t, spn_vec3 p)
{
    spn_air_field *air = user;
    const air_time at = air->grid && !stopped(air, t) ? sample_time(air, t) : (air_time){0};
    if (!at.a || !at.b) return spn_air_velocity(air, t, p);
    const air_points g = points_of(air, &at);
    spn_vec3 u;
    sample_one(&g, &p, &u);
    return u;
}

/* A sixteenth of the grid's smallest cell: a sample there is off the
 * point's own by at most a thirty-second of a cell in each coordinate,
 * beside the trilinear interpolation's own error across the cell
 * (docs/physics.md, "Air drag on threads", has the measurements). */
#define HELD_CELL_PART 16

bool spn_air_resolution(const spn_air_field *air, double *interval, double *spacing)
{
    double dt = 0, h = 0;
    if (air->grid) {
        const double cx = (air->hi.x - air->lo.x) / (air->n[0] - 1), cy = (air->hi.y - air->lo.y) / (air->n[1] - 1),
                     cz = (air->hi.z - air->lo.z) / (air->n[2] - 1);
        dt = air->slice_dt, h = fmin(cx, fmin(cy, cz)) / HELD_CELL_PART;
    }
    if (interval) *interval = dt;
    if (spacing) *spacing = h;
    return air->grid;
}

spn_status spn_air_prepare_held(spn_air_field *air, double t0, double t1)
{
    if (!air->grid) return SPN_OK;
    const double dt = air->slice_dt;
    return spn_air_prepare(air, floor(t0 / dt) * dt, (floor(t1 / dt) + 1) * dt);
}

void spn_air_attach(spn_air_field *air, spn_world *w)
{
    spn_world_set_air(w, spn_air_sample, air, air->def.rho, air->def.mu);
    spn_world_set_air_batch(w, spn_air_sample_batch);
    spn_world_set_air_pure(w, true); /* sampling reads the field (its record of the rows touched is atomic) */
    double dt, h;
    if (spn_air_resolution(air, &dt, &h)) spn_world_set_air_resolution(w, dt, h);
    for (uint32_t tag = 0; tag < 64; tag++) {
        double d = spn_thread_diameter(tag);
        if (d > 0) spn_world_set_tag_diameter(w, tag, d);
    }
}

/* A batched complex FFT (fft.h) in the Stockham autosort form.
 *
 * n = r_1 r_2 ... r_S. Before the stage of radix r the data are s = r_1 ...
 * (the radices so far) interleaved sequences of length N = n / s; with
 * m = N / r, w_N = exp(sign 2 pi i / N) and p < m, q < s, j < r the stage
 * writes, out of place,
 *     y[q + s (r p + j)] = w_N^(p j) sum_{k<r} x[q + s (p + k m)] w_r^(j k),
 * which leaves s r sequences of length m; after the last stage the result
 * stands in natural order, without a bit-reversal pass.
 *
 * A length whose mixed-radix plan would cost more (a large prime factor,
 * which that plan takes by a direct DFT of p operations an element) is done
 * by Bluestein's chirp transform instead: with j k = (j^2 + k^2 - (j - k)^2)
 * / 2 and a_k = exp(-pi i k^2 / n),
 *     X_j = sum_k x_k w_n^(-j k) = a_j sum_k (a_k x_k) conj(a_(j - k)),
 * a convolution, which is done circularly at a length M >= 2 n - 1 with no
 * prime factor above 5 by two mixed-radix transforms of length M and a
 * product with the precomputed spectrum of conj(a) (symmetric, so wrapped
 * to M as conj(a_m) at m and at M - m). Sign +1 is the conjugate of sign -1
 * on the conjugated input.
 *
 * An element x[e] here is a row of the batch, re[e * stride + b] for the
 * columns b, and every loop runs along the columns of a row doing the same
 * scalar operations for each (no fused multiply-adds: the project builds
 * with -ffp-contract=off), so a column's bits do not depend on which other
 * columns a call covers, nor on the vector width. */
#include "physics/fft.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* 32 stages: every factor is at least 2 (and a radix 4 takes two of them).
 * CHUNK columns at a time, so that a butterfly's output rows are still in
 * the first-level cache when the twiddles are applied to them. */
enum { MAX_STAGES = 32, CHUNK = 128 };

typedef struct {
    uint32_t r, m, s;   /* radix, length after the stage (N / r), sequences before it */
    const double *w;    /* (cos, sin) of 2 pi p j s / n for p < m, 1 <= j < r: 2 (r - 1) m doubles */
    const double *root; /* (cos, sin) of 2 pi k / r for k < r, for a radix above 5; else NULL */
} stage;

struct spn__fft {
    uint32_t n, nstages;
    stage st[MAX_STAGES];
    double *tab; /* every stage's w and root */
    /* Bluestein (chirp != NULL; then nstages is 0): the transform of length m */
    spn__fft *inner;
    uint32_t m;
    double *chirp; /* (cos, sin) of -pi k^2 / n, k < n: a_k */
    double *spec;  /* (re, im) of the length-m sign -1 transform of conj(a), wrapped, divided by m */
};

/* cos and sin of 2 pi m / n, from the octant of the angle (an integer
 * division) and cos, sin of an angle of at most pi / 4 measured from the
 * nearer end of the octant: the values at multiples of pi / 2 are exact
 * and the symmetries of the circle hold exactly. */
static void unit_root(uint64_t m, uint64_t n, double *c, double *s)
{
    const uint64_t u = 8 * (m % n), o = u / n;
    uint64_t f = u % n;
    if (o & 1) f = n - f;
    const double phi = 0.78539816339744830962 * (double)f / (double)n, x = cos(phi), y = sin(phi);
    /* per octant: swap x and y, the sign of cos, the sign of sin */
    static const signed char sc[8][3] = {{0, 1, 1},   {1, 1, 1},   {1, -1, 1}, {0, -1, 1},
                                         {0, -1, -1}, {1, -1, -1}, {1, 1, -1}, {0, 1, -1}};
    *c = sc[o][1] * (sc[o][0] ? y : x);
    *s = sc[o][2] * (sc[o][0] ? x : y);
}

/* The radices in stage order (4s, a 2, then odd primes rising); their count. */
static uint32_t factor(uint32_t n, uint32_t f[MAX_STAGES])
{
    uint32_t k = 0;
    for (; n % 4 == 0; n /= 4) f[k++] = 4;
    if (n % 2 == 0) f[k++] = 2, n /= 2;
    for (uint32_t p = 3; n > 1; p += 2) {
        if ((uint64_t)p * p > n) p = n; /* what is left is prime */
        for (; n % p == 0; n /= p) f[k++] = p;
    }
    return k;
}

/* The mixed-radix plan of n. */
static spn__fft *radix_plan(uint32_t n)
{
    spn__fft *plan = calloc(1, sizeof *plan);
    if (!plan) return NULL;
    uint32_t f[MAX_STAGES];
    plan->n = n;
    plan->nstages = factor(n, f);
    size_t size = 1, s = 1;
    for (uint32_t t = 0; t < plan->nstages; t++) {
        size += 2 * (size_t)(f[t] - 1) * (n / (s * f[t])) + (f[t] > 5 ? 2 * (size_t)f[t] : 0);
        s *= f[t];
    }
    double *w = plan->tab = malloc(size * sizeof *w);
    if (!w) {
        free(plan);
        return NULL;
    }
    s = 1;
    for (uint32_t t = 0; t < plan->nstages; t++) {
        stage *g = &plan->st[t];
        g->r = f[t], g->s = (uint32_t)s, g->m = (uint32_t)(n / (s * f[t]));
        g->w = w;
        for (uint32_t p = 0; p < g->m; p++)
            for (uint32_t j = 1; j < g->r; j++, w += 2) unit_root((uint64_t)p * j * s, n, w, w + 1);
        g->root = NULL;
        if (g->r > 5) {
            g->root = w;
            for (uint32_t k = 0; k < g->r; k++, w += 2) unit_root(k, g->r, w, w + 1);
        }
        s *= f[t];
    }
    return plan;
}

/* The smallest length >= n with no prime factor above 5. */
static uint32_t smooth_above(uint32_t n)
{
    for (uint32_t m = n;; m++) {
        uint32_t r = m;
        while (r % 2 == 0)
            r /= 2;
        while (r % 3 == 0)
            r /= 3;
        while (r % 5 == 0)
            r /= 5;
        if (r == 1) return m;
    }
}

static spn__fft *chirp_plan(uint32_t n)
{
    spn__fft *plan = calloc(1, sizeof *plan);
    if (!plan) return NULL;
    plan->n = n;
    plan->m = smooth_above(2 * n - 1);
    const uint32_t m = plan->m;
    plan->inner = radix_plan(m);
    plan->chirp = malloc(2 * (size_t)n * sizeof *plan->chirp);
    plan->spec = malloc(2 * (size_t)m * sizeof *plan->spec);
    double *br = calloc(4 * (size_t)m, sizeof *br), *bi = br + m, *tr = br + 2 * (size_t)m, *ti = br + 3 * (size_t)m;
    if (!plan->inner || !plan->chirp || !plan->spec || !br) {
        free(br);
        spn__fft_free(plan);
        return NULL;
    }
    for (uint32_t k = 0; k < n; k++) { /* k^2 mod 2n exactly: the angle -pi k^2 / n reduced */
        const uint64_t e = (uint64_t)k * k % (2 * (uint64_t)n);
        double c, sn;
        unit_root(e, 2 * (uint64_t)n, &c, &sn);
        plan->chirp[2 * k] = c, plan->chirp[2 * k + 1] = -sn;
        br[k] = c, bi[k] = sn; /* conj(a_k) */
        if (k) br[m - k] = c, bi[m - k] = sn;
    }
    spn__fft_run(plan->inner, -1, br, bi, 1, 0, 1, tr, ti);
    for (uint32_t j = 0; j < m; j++)
        plan->spec[2 * j] = br[j] / m, plan->spec[2 * j + 1] = bi[j] / m;
    free(br);
    return plan;
}

/* Cost estimates per element and column, in units of one radix (2-5)
 * stage's element with its twiddle: a direct DFT of a prime p costs
 * DFT_COST p of them; Bluestein does two transforms of length m ~ 2n and
 * three complex products (CHIRP_COST) per element of m. Measured on a Zen 1
 * (150 columns, ns an element, mixed radix / chirp): a radix stage ~1.4-2.5,
 * a prime p ~0.41 p (p = 127: 48.6 / 19.8; 997: 412 / 50.6); the two meet
 * near p = 50 (47: 19.2 / 19.2), and the estimate switches at 61 (23.8 /
 * 21.5). For 316 = 4 x 79 they are near even (32.3 / 29.7); the estimate
 * keeps the mixed radix. */
#define DFT_COST 0.25
#define CHIRP_COST 1.0
static double radix_cost(uint32_t n)
{
    uint32_t f[MAX_STAGES];
    const uint32_t k = factor(n, f);
    double c = 0;
    for (uint32_t t = 0; t < k; t++)
        c += f[t] <= 5 ? 1.0 : DFT_COST * f[t];
    return c;
}

static double chirp_cost(uint32_t n)
{
    const uint32_t m = smooth_above(2 * n - 1);
    return (double)m / n * (2 * radix_cost(m) + CHIRP_COST);
}

spn__fft *spn__fft_plan_kind(uint32_t n, spn__fft_kind kind)
{
    if (n == 0) return NULL;
    if (kind == SPN__FFT_AUTO) kind = chirp_cost(n) < radix_cost(n) ? SPN__FFT_CHIRP : SPN__FFT_RADIX;
    return kind == SPN__FFT_CHIRP ? chirp_plan(n) : radix_plan(n);
}

spn__fft *spn__fft_plan(uint32_t n) { return spn__fft_plan_kind(n, SPN__FFT_AUTO); }

void spn__fft_free(spn__fft *plan)
{
    if (!plan) return;
    spn__fft_free(plan->inner);
    free(plan->chirp);
    free(plan->spec);
    free(plan->tab);
    free(plan);
}

uint32_t spn__fft_length(const spn__fft *plan) { return plan->n; }

bool spn__fft_is_chirp(const spn__fft *plan) { return plan->chirp != NULL; }

size_t spn__fft_scratch_rows(const spn__fft *plan) { return plan->chirp ? 2 * (size_t)plan->m : plan->n; }

/* The butterflies: inputs k < r at rows x + k xs, outputs j < r at rows
 * y + j ys, columns c0..c1-1; sg is the transform's sign, +1 or -1.
 * The rows a loop writes never overlap each other (stride >= b1), nor what
 * it reads, which the compiler cannot see through offsets known only at
 * run time: ROWS_APART tells it, so the loops vectorise without checks. */
#if defined(__clang__)
#define ROWS_APART _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define ROWS_APART _Pragma("GCC ivdep")
#else
#define ROWS_APART
#endif

static void bf2(const double *restrict xr, const double *restrict xi, size_t xs, double *restrict yr,
                double *restrict yi, size_t ys, size_t c0, size_t c1)
{
    ROWS_APART
    for (size_t c = c0; c < c1; c++) {
        const double ar = xr[c], ai = xi[c], br = xr[xs + c], bi = xi[xs + c];
        yr[c] = ar + br, yi[c] = ai + bi;
        yr[ys + c] = ar - br, yi[ys + c] = ai - bi;
    }
}

static void bf3(const double *restrict xr, const double *restrict xi, size_t xs, double *restrict yr,
                double *restrict yi, size_t ys, double sg, size_t c0, size_t c1)
{
    /* y_0 = x_0 + t, y_1,2 = x_0 - t / 2 +- sg i sin(2 pi / 3) d, t = x_1 + x_2, d = x_1 - x_2 */
    const double h = sg * 0.86602540378443864676;
    ROWS_APART
    for (size_t c = c0; c < c1; c++) {
        const double x0r = xr[c], x0i = xi[c], x1r = xr[xs + c], x1i = xi[xs + c], x2r = xr[2 * xs + c],
                     x2i = xi[2 * xs + c];
        const double tr = x1r + x2r, ti = x1i + x2i, ur = x0r - 0.5 * tr, ui = x0i - 0.5 * ti;
        const double vr = h * (x1r - x2r), vi = h * (x1i - x2i);
        yr[c] = x0r + tr, yi[c] = x0i + ti;
        yr[ys + c] = ur - vi, yi[ys + c] = ui + vr;
        yr[2 * ys + c] = ur + vi, yi[2 * ys + c] = ui - vr;
    }
}

static void bf4(const double *restrict xr, const double *restrict xi, size_t xs, double *restrict yr,
                double *restrict yi, size_t ys, double sg, size_t c0, size_t c1)
{
    /* with a = x_0 - x_2, d = x_1 - x_3: y_1 = a - i d, y_3 = a + i d for
     * sign -1, the other way round for +1 (the rows swap) */
    const size_t o1 = sg < 0 ? ys : 3 * ys, o3 = sg < 0 ? 3 * ys : ys;
    ROWS_APART
    for (size_t c = c0; c < c1; c++) {
        const double x0r = xr[c], x0i = xi[c], x1r = xr[xs + c], x1i = xi[xs + c], x2r = xr[2 * xs + c],
                     x2i = xi[2 * xs + c], x3r = xr[3 * xs + c], x3i = xi[3 * xs + c];
        const double sr = x0r + x2r, si = x0i + x2i, ar = x0r - x2r, ai = x0i - x2i;
        const double tr = x1r + x3r, ti = x1i + x3i, dr = x1r - x3r, di = x1i - x3i;
        yr[c] = sr + tr, yi[c] = si + ti;
        yr[2 * ys + c] = sr - tr, yi[2 * ys + c] = si - ti;
        yr[o1 + c] = ar + di, yi[o1 + c] = ai - dr;
        yr[o3 + c] = ar - di, yi[o3 + c] = ai + dr;
    }
}

static void bf5(const double *restrict xr, const double *restrict xi, size_t xs, double *restrict yr,
                double *restrict yi, size_t ys, double sg, size_t c0, size_t c1)
{
    /* t_k = x_k + x_{5-k}, d_k = x_k - x_{5-k}; y_1,4 = a_1 +- i b_1, y_2,3 = a_2 +- i b_2 with
     * a_1 = x_0 + k1 t_1 + k2 t_2, b_1 = s1 d_1 + s2 d_2, a_2 = x_0 + k2 t_1 + k1 t_2, b_2 = s2 d_1 - s1 d_2 */
    /* cos(2 pi / 5), cos(4 pi / 5); sg sin(2 pi / 5), sg sin(4 pi / 5) */
    const double k1 = 0.30901699437494742410, k2 = -0.80901699437494742410;
    const double s1 = sg * 0.95105651629515357212, s2 = sg * 0.58778525229247312917;
    ROWS_APART
    for (size_t c = c0; c < c1; c++) {
        const double x0r = xr[c], x0i = xi[c];
        const double t1r = xr[xs + c] + xr[4 * xs + c], t1i = xi[xs + c] + xi[4 * xs + c];
        const double d1r = xr[xs + c] - xr[4 * xs + c], d1i = xi[xs + c] - xi[4 * xs + c];
        const double t2r = xr[2 * xs + c] + xr[3 * xs + c], t2i = xi[2 * xs + c] + xi[3 * xs + c];
        const double d2r = xr[2 * xs + c] - xr[3 * xs + c], d2i = xi[2 * xs + c] - xi[3 * xs + c];
        const double a1r = x0r + k1 * t1r + k2 * t2r, a1i = x0i + k1 * t1i + k2 * t2i;
        const double a2r = x0r + k2 * t1r + k1 * t2r, a2i = x0i + k2 * t1i + k1 * t2i;
        const double b1r = s1 * d1r + s2 * d2r, b1i = s1 * d1i + s2 * d2i;
        const double b2r = s2 * d1r - s1 * d2r, b2i = s2 * d1i - s1 * d2i;
        yr[c] = x0r + t1r + t2r, yi[c] = x0i + t1i + t2i;
        yr[ys + c] = a1r - b1i, yi[ys + c] = a1i + b1r;
        yr[4 * ys + c] = a1r + b1i, yi[4 * ys + c] = a1i - b1r;
        yr[2 * ys + c] = a2r - b2i, yi[2 * ys + c] = a2i + b2r;
        yr[3 * ys + c] = a2r + b2i, yi[3 * ys + c] = a2i - b2r;
    }
}

/* Any odd prime r, directly: t_k = x_k + x_{r-k}, d_k = x_k - x_{r-k} and for
 * 1 <= j <= h = (r - 1) / 2, a = x_0 + sum_k cos(2 pi j k / r) t_k (summed in
 * row j) and b = sg sum_k sin(2 pi j k / r) d_k (in row r - j), k = 1..h; then
 * y_j = a + i b, y_{r-j} = a - i b, and y_0 = x_0 + t_1 + ... + t_h. */
static void dft(const double *restrict xr, const double *restrict xi, size_t xs, double *restrict yr,
                double *restrict yi, size_t ys, uint32_t r, const double *root, double sg, size_t c0, size_t c1)
{
    const uint32_t h = (r - 1) / 2;
    for (size_t c = c0; c < c1; c++) yr[c] = xr[c], yi[c] = xi[c];
    for (uint32_t k = 1; k <= h; k++) {
        const size_t u = k * xs, v = (r - k) * xs;
        for (size_t c = c0; c < c1; c++) yr[c] += xr[u + c] + xr[v + c], yi[c] += xi[u + c] + xi[v + c];
    }
    for (uint32_t j = 1; j <= h; j++) {
        const size_t a = j * ys, b = (r - j) * ys;
        ROWS_APART
        for (size_t c = c0; c < c1; c++) yr[a + c] = xr[c], yi[a + c] = xi[c], yr[b + c] = 0, yi[b + c] = 0;
        for (uint32_t k = 1; k <= h; k++) {
            const size_t u = k * xs, v = (r - k) * xs, e = 2 * ((uint64_t)j * k % r);
            const double cs = root[e], sn = sg * root[e + 1];
            ROWS_APART
            for (size_t c = c0; c < c1; c++) {
                yr[a + c] += cs * (xr[u + c] + xr[v + c]), yi[a + c] += cs * (xi[u + c] + xi[v + c]);
                yr[b + c] += sn * (xr[u + c] - xr[v + c]), yi[b + c] += sn * (xi[u + c] - xi[v + c]);
            }
        }
        ROWS_APART
        for (size_t c = c0; c < c1; c++) {
            const double ar = yr[a + c], ai = yi[a + c], br = yr[b + c], bi = yi[b + c];
            yr[a + c] = ar - bi, yi[a + c] = ai + br;
            yr[b + c] = ar + bi, yi[b + c] = ai - br;
        }
    }
}

/* Output rows 1..r-1 times their twiddles w (cos, sin pairs), conjugated for sign -1. */
static void twiddle(double *restrict yr, double *restrict yi, size_t ys, uint32_t r, const double *w, double sg,
                    size_t c0, size_t c1)
{
    for (uint32_t j = 1; j < r; j++) {
        const size_t a = j * ys;
        const double cs = w[2 * j - 2], sn = sg * w[2 * j - 1];
        for (size_t c = c0; c < c1; c++) {
            const double pr = yr[a + c], pi = yi[a + c];
            yr[a + c] = pr * cs - pi * sn, yi[a + c] = pr * sn + pi * cs;
        }
    }
}

static void run_stage(const stage *g, double sg, const double *xr, const double *xi, double *yr, double *yi,
                      size_t stride, size_t b0, size_t b1)
{
    const uint32_t r = g->r;
    const size_t s = g->s, xs = s * g->m * stride, ys = s * stride; /* rows between inputs, outputs */
    for (uint32_t p = 0; p < g->m; p++)
        for (size_t q = 0; q < s; q++) {
            const double *ar = xr + (q + s * p) * stride, *ai = xi + (q + s * p) * stride;
            double *br = yr + (q + s * r * p) * stride, *bi = yi + (q + s * r * p) * stride;
            for (size_t c0 = b0; c0 < b1; c0 += CHUNK) {
                const size_t c1 = b1 - c0 > CHUNK ? c0 + CHUNK : b1;
                switch (r) {
                case 2: bf2(ar, ai, xs, br, bi, ys, c0, c1); break;
                case 3: bf3(ar, ai, xs, br, bi, ys, sg, c0, c1); break;
                case 4: bf4(ar, ai, xs, br, bi, ys, sg, c0, c1); break;
                case 5: bf5(ar, ai, xs, br, bi, ys, sg, c0, c1); break;
                default: dft(ar, ai, xs, br, bi, ys, r, g->root, sg, c0, c1); break;
                }
                if (p) twiddle(br, bi, ys, r, g->w + 2 * (size_t)(r - 1) * p, sg, c0, c1);
            }
        }
}

/* Rows k < rows, columns b0..b1-1: y_k = tab_k (x_k with its imaginary part
 * times cin), the imaginary part of the product times cout (each +-1). y may
 * be x: every element is read before it is written. */
static void times_table(const double *xr, const double *xi, double *yr, double *yi, size_t stride, uint32_t rows,
                        const double *tab, double cin, double cout, size_t b0, size_t b1)
{
    for (uint32_t k = 0; k < rows; k++) {
        const double c = tab[2 * k], s = tab[2 * k + 1];
        const double *ar = xr + k * stride, *ai = xi + k * stride;
        double *br = yr + k * stride, *bi = yi + k * stride;
        ROWS_APART
        for (size_t b = b0; b < b1; b++) {
            const double pr = ar[b], pi = cin * ai[b];
            br[b] = pr * c - pi * s, bi[b] = cout * (pr * s + pi * c);
        }
    }
}

/* Bluestein, columns b0..b1-1: u = a x (conj(x) for sign +1) in the first m
 * rows of the scratch, zero past n; its transform times spec; back; a times
 * that (conjugated for sign +1) into x. The inner transforms use the next m
 * rows of the scratch as theirs. */
static void run_chirp(const spn__fft *plan, double sg, double *re, double *im, size_t stride, size_t b0, size_t b1,
                      double *tre, double *tim)
{
    const uint32_t n = plan->n, m = plan->m;
    const double cj = -sg; /* the sign of the imaginary parts in and out */
    double *ur = tre, *ui = tim, *sr = tre + (size_t)m * stride, *si = tim + (size_t)m * stride;
    times_table(re, im, ur, ui, stride, n, plan->chirp, cj, 1, b0, b1);
    for (uint32_t k = n; k < m; k++) {
        memset(ur + k * stride + b0, 0, (b1 - b0) * sizeof *ur);
        memset(ui + k * stride + b0, 0, (b1 - b0) * sizeof *ui);
    }
    spn__fft_run(plan->inner, -1, ur, ui, stride, b0, b1, sr, si);
    times_table(ur, ui, ur, ui, stride, m, plan->spec, 1, 1, b0, b1);
    spn__fft_run(plan->inner, 1, ur, ui, stride, b0, b1, sr, si);
    times_table(ur, ui, re, im, stride, n, plan->chirp, 1, cj, b0, b1);
}

void spn__fft_run(const spn__fft *plan, int sign, double *re, double *im, size_t stride, size_t b0, size_t b1,
                  double *tre, double *tim)
{
    if (b0 >= b1) return;
    const double sg = sign < 0 ? -1.0 : 1.0;
    if (plan->chirp) {
        run_chirp(plan, sg, re, im, stride, b0, b1, tre, tim);
        return;
    }
    double *xr = re, *xi = im, *yr = tre, *yi = tim;
    for (uint32_t t = 0; t < plan->nstages; t++) {
        run_stage(&plan->st[t], sg, xr, xi, yr, yi, stride, b0, b1);
        double *tr = xr, *ti = xi;
        xr = yr, xi = yi, yr = tr, yi = ti;
    }
    if (plan->nstages % 2)
        for (size_t k = 0; k < plan->n; k++) {
            memcpy(re + k * stride + b0, tre + k * stride + b0, (b1 - b0) * sizeof *re);
            memcpy(im + k * stride + b0, tim + k * stride + b0, (b1 - b0) * sizeof *im);
        }
}

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
 * An element x[e] here is a row of the batch, re[e * stride + b] for the
 * columns b, and every loop runs along the columns of a row doing the same
 * scalar operations for each (no fused multiply-adds: the project builds
 * with -ffp-contract=off), so a column's bits do not depend on which other
 * columns a call covers, nor on the vector width. */
#include "physics/fft.h"

#include <math.h>
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

uint32_t spn__fft_largest_factor(uint32_t n)
{
    if (n == 0) return 0;
    uint32_t f[MAX_STAGES], k = factor(n, f), big = 1;
    for (uint32_t i = 0; i < k; i++) {
        const uint32_t prime = f[i] == 4 ? 2 : f[i];
        if (prime > big) big = prime;
    }
    return big;
}

spn__fft *spn__fft_plan(uint32_t n)
{
    if (n == 0) return NULL;
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

void spn__fft_free(spn__fft *plan)
{
    if (!plan) return;
    free(plan->tab);
    free(plan);
}

uint32_t spn__fft_length(const spn__fft *plan) { return plan->n; }

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

void spn__fft_run(const spn__fft *plan, int sign, double *re, double *im, size_t stride, size_t b0, size_t b1,
                  double *tre, double *tim)
{
    if (b0 >= b1) return;
    const double sg = sign < 0 ? -1.0 : 1.0;
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

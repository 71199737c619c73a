/* The JSON web file's numbers: each float as the first of %.15g, %.16g and
 * %.17g that strtod reads back to the same bits (the web file's contract,
 * docs/web-format.md, "Numbers").
 *
 * The direct way, printing each precision and reading it back, costs about
 * 1-1.5 us a number (two or three printf and strtod calls for a typical
 * coordinate) and was most of the time saving a big web. For |v| in
 * [1e-25, 1e14), which holds every length, mass and stiffness of a real web,
 * the same text is found here by exact integer arithmetic: v = m 2^-s
 * exactly, so m 10^k / 2^s, one product and a shift, gives v's first 17
 * digits and what the bits shifted out say of the rest (above, at or below
 * half; zero or not), from which the 15-, 16- and 17-digit roundings follow
 * (half to even, as printf rounds); and a p-digit decimal reads back to v
 * exactly when it lies strictly between the midpoints to v's neighbours,
 * made once for the three. Every side is an integer below 2^200 once
 * scaled by 10^k 2^(s+2). Outside that range (and for 0, subnormals, huge
 * values) the direct way is used.
 * tests/test_io_shortest.c holds the two to the same text on millions of
 * values of every kind. */
#include "io_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- unsigned integers of 256 bits, 32-bit limbs, least significant first */

enum { LIMBS = 8 };
typedef struct big {
    uint32_t w[LIMBS];
} big;

static big big_of(uint64_t v)
{
    big b = {{(uint32_t)v, (uint32_t)(v >> 32)}};
    return b;
}

static void big_mul(big *a, uint32_t m)
{
    uint64_t carry = 0;
    for (int i = 0; i < LIMBS; i++) {
        const uint64_t t = (uint64_t)a->w[i] * m + carry;
        a->w[i] = (uint32_t)t, carry = t >> 32;
    }
}

static void big_mul_pow10(big *a, int k)
{
    static const uint32_t p10[9] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000};
    for (; k >= 9; k -= 9) big_mul(a, 1000000000u);
    if (k) big_mul(a, p10[k]);
}

static void big_shl(big *a, int s)
{
    const int limbs = s / 32, bits = s % 32;
    for (int i = LIMBS - 1; i >= 0; i--) {
        const uint32_t hi = i >= limbs ? a->w[i - limbs] : 0, lo = i >= limbs + 1 ? a->w[i - limbs - 1] : 0;
        a->w[i] = bits ? (hi << bits | lo >> (32 - bits)) : hi;
    }
}

static int big_cmp(const big *a, const big *b)
{
    for (int i = LIMBS - 1; i >= 0; i--)
        if (a->w[i] != b->w[i]) return a->w[i] < b->w[i] ? -1 : 1;
    return 0;
}

/* a >> s (s >= 1; the caller knows the quotient fits in 64 bits); *rest is
 * -1, 0 or 1 as the bits shifted out are below, at or above half of 2^s, and
 * *zero whether they are all zero. */
static uint64_t big_shr(const big *a, int s, int *rest, bool *zero)
{
    const int limb = s / 32, bit = s % 32, hb = s - 1;
    const uint64_t w0 = a->w[limb], w1 = limb + 1 < LIMBS ? a->w[limb + 1] : 0,
                   w2 = limb + 2 < LIMBS ? a->w[limb + 2] : 0;
    const uint64_t q = bit ? (w0 >> bit) | (w1 << (32 - bit)) | (w2 << (64 - bit)) : (w0 | w1 << 32);
    const unsigned half = a->w[hb / 32] >> (hb % 32) & 1u;
    bool low = (a->w[hb / 32] & ((1u << (hb % 32)) - 1u)) != 0;
    for (int i = 0; i < hb / 32 && !low; i++) low = a->w[i] != 0;
    *rest = !half ? -1 : low ? 1 : 0;
    *zero = !half && !low;
    return q;
}

/* ---- the digits ----------------------------------------------------------- */

static const uint64_t POW10[19] = {1ull,
                                   10ull,
                                   100ull,
                                   1000ull,
                                   10000ull,
                                   100000ull,
                                   1000000ull,
                                   10000000ull,
                                   100000000ull,
                                   1000000000ull,
                                   10000000000ull,
                                   100000000000ull,
                                   1000000000000ull,
                                   10000000000000ull,
                                   100000000000000ull,
                                   1000000000000000ull,
                                   10000000000000000ull,
                                   100000000000000000ull,
                                   1000000000000000000ull};

/* v = m 2^-s as its first 17 significant digits, truncated: q in [10^16,
 * 10^17) with v = (q + f) 10^(x - 16), 0 <= f < 1, and f against one half
 * (*rest: -1, 0, 1) and zero (*zero). *x, the power of ten of the first
 * digit, is a guess on entry, put right here. One big product serves every
 * precision: rounding q to fewer digits needs only q and f's two facts. */
static uint64_t first_digits(uint64_t m, int s, int *x, int *rest, bool *zero)
{
    for (;;) {
        big n = big_of(m);
        big_mul_pow10(&n, 16 - *x);
        const uint64_t q = big_shr(&n, s, rest, zero);
        if (q >= POW10[17]) ++*x;
        else if (q < POW10[16]) --*x;
        else return q;
    }
}

/* q + f (above) rounded half to even to p <= 17 digits; *xp the power of
 * ten of the result's first digit (x, or x + 1 after 9.99... -> 10.0...). */
static uint64_t round_to(uint64_t q, int rest, bool zero, int p, int x, int *xp)
{
    const uint64_t div = POW10[17 - p], half = div / 2;
    uint64_t t = q / div;
    const uint64_t r = q % div;
    bool up;
    if (p == 17) up = rest > 0 || (rest == 0 && (t & 1));
    else up = r > half || (r == half && (!zero || (t & 1))); /* r + f against half, f in [0, 1) */
    *xp = x;
    if (up && ++t == POW10[p]) t = POW10[p - 1], ++*xp;
    return t;
}

/* The midpoints between v = m 2^-s and its neighbours, times 10^(16 - x)
 * 2^(s+2): (2m +- 1) 2 10^k, or (4m - 1) 10^k below a power of two, whose
 * lower neighbour is half as far. */
static void midpoints(uint64_t m, int x, big *lo, big *hi)
{
    const bool pow2 = m == (1ull << 52);
    *hi = big_of(2 * m + 1), *lo = big_of(pow2 ? 4 * m - 1 : 2 * m - 1);
    big_mul_pow10(hi, 16 - x);
    big_mul(hi, 2);
    big_mul_pow10(lo, 16 - x);
    if (!pow2) big_mul(lo, 2);
}

/* Does d 10^(xp - p + 1) read back to v? On the midpoints' scale it is d
 * 10^(17 - p + xp - x) 2^(s+2) (below 10^18: fits), strictly between them.
 * The decimal is never a midpoint itself, so no tie is left to strtod's
 * rounding: a midpoint below 2^47 has 54 - ex >= 7 binary fraction digits,
 * so as many decimal ones, more than 21 significant digits in all (55 - 0.7
 * ex of them), where d has at most 17. */
static bool reads_back(const big *lo, const big *hi, int s, uint64_t d, int p, int x, int xp)
{
    big w = big_of(d * POW10[17 - p + xp - x]);
    big_shl(&w, s + 2);
    return big_cmp(&w, hi) < 0 && big_cmp(&w, lo) > 0;
}

/* What %.{prec}g prints for the value whose prec significant digits are
 * d[0..prec) and whose first digit stands for 10^x: trailing zeros and a
 * bare point dropped; exponent form below 1e-4 or from 10^prec. */
static void g_style(char *o, bool negative, const char *d, int prec, int x)
{
    int n = prec;
    while (n > 1 && d[n - 1] == '0') n--;
    if (negative) *o++ = '-';
    if (x < -4 || x >= prec) {
        *o++ = d[0];
        if (n > 1) {
            *o++ = '.';
            memcpy(o, d + 1, (size_t)n - 1), o += n - 1;
        }
        const int ax = x < 0 ? -x : x; /* at least two digits, as printf */
        *o++ = 'e', *o++ = x < 0 ? '-' : '+';
        if (ax >= 100) *o++ = (char)('0' + ax / 100);
        *o++ = (char)('0' + ax / 10 % 10), *o++ = (char)('0' + ax % 10), *o = 0;
        return;
    }
    if (x < 0) {
        *o++ = '0', *o++ = '.';
        for (int i = -1; i > x; i--) *o++ = '0';
        memcpy(o, d, (size_t)n), o += n;
    } else {
        for (int i = 0; i <= x; i++) *o++ = i < n ? d[i] : '0';
        if (n > x + 1) {
            *o++ = '.';
            memcpy(o, d + x + 1, (size_t)(n - x - 1)), o += n - x - 1;
        }
    }
    *o = 0;
}

void spn__format_double_printf(char out[40], double v)
{
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(out, 40, "%.*g", digits, v);
        double back = strtod(out, NULL);
        if (memcmp(&back, &v, sizeof v) == 0) return;
    }
}

void spn__format_double(char out[40], double v)
{
    const double a = fabs(v);
    if (a == 0) { /* velocities at rest, unused break lengths: common, and %g's "0", "-0" */
        strcpy(out, signbit(v) ? "-0" : "0");
        return;
    }
    if (!(a >= 1e-25 && a < 1e14)) {
        spn__format_double_printf(out, v);
        return;
    }
    int ex;
    const uint64_t m = (uint64_t)ldexp(frexp(a, &ex), 53); /* a = m 2^(ex - 53), m in [2^52, 2^53) */
    const int s = 53 - ex;                                 /* >= 7 in this range */
    int x = (int)floor(log10(a)), rest;
    bool zero;
    const uint64_t q = first_digits(m, s, &x, &rest, &zero);
    big lo, hi;
    midpoints(m, x, &lo, &hi);
    for (int p = 15; p <= 17; p++) {
        int xp;
        const uint64_t d = round_to(q, rest, zero, p, x, &xp);
        if (p == 17 || reads_back(&lo, &hi, s, d, p, x, xp)) { /* 17 digits always read back */
            char digits[17];
            uint64_t r = d;
            for (int i = p - 1; i >= 0; i--, r /= 10) digits[i] = (char)('0' + r % 10);
            g_style(out, v < 0, digits, p, xp);
            return;
        }
    }
}

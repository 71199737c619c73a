/* The big columns of a JSON web file, read straight from the text.
 *
 * Why: cJSON makes a node of about 64 bytes for every number, so a web of a
 * million particles (20 million numbers, 309 MB of text) became 1.6 GB of
 * nodes, and most of its 12 s load was the allocator and the guest clearing
 * fresh pages for them (docs/web-format.md, "Reading big files").
 *
 * How: one pass over the text finds each array that is the value of a field
 * of the top-level "particles" or "springs" object and holds only numbers
 * and nulls. Such an array is parsed here into doubles (null as NaN, which
 * no JSON number can give) and replaced by "[]" in a copy of the rest of the
 * text, the skeleton, which cJSON parses as before; the reader then takes the
 * column from here (web_read.c).
 *
 * The same answer as cJSON, always:
 * - An array is taken only if every entry is a number in JSON's own grammar
 *   (no leading zeros, no '+', no bare '.'), at most 63 characters (cJSON
 *   reads a number through a 63-character buffer), or null, with only
 *   JSON's four blanks between. Anything else (true, a string, "01", a
 *   stray character) leaves the array in the text for cJSON and its
 *   messages, as if this file did not exist.
 * - A number's value is the correctly rounded double of its decimal, which
 *   is what cJSON's strtod gives: exactly by Clinger's fast path (a
 *   mantissa below 2^53 and a power of ten below 10^23 are exact doubles,
 *   so one multiplication or division rounds once), else through the
 *   64-bit long double when that rounding provably agrees, else strtod
 *   itself with the locale's decimal point, as cJSON calls it.
 * - Replacing an array of numbers by "[]" changes no syntax: the skeleton
 *   is valid JSON exactly when the text is. Its error positions are not the
 *   text's, so after a syntax error the caller parses the text itself for
 *   the message (web_read.c).
 * - The scan needs to understand only strings (to skip them) and nesting;
 *   wherever the text is not JSON, cJSON's parse of the skeleton finds the
 *   same fault in the same place as in the text, since the two are equal
 *   up to the first replaced array. */
#include "io_internal.h"

#include <float.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- numbers --------------------------------------------------------------- */

static const double EXACT_POW10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                       1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* strtod of the token, its '.' as the locale's decimal point (cJSON's way) */
static double by_strtod(const char *p, size_t n, char point)
{
    char buf[64];
    for (size_t i = 0; i < n; i++) buf[i] = p[i] == '.' ? point : p[i];
    buf[n] = 0;
    return strtod(buf, NULL);
}

/* m 10^e, m < 2^64 exact: correctly rounded when the one rounding in the
 * 64-bit long double provably rounds on to the same double. The long double
 * y is within half its ulp of the exact value x; RN(y) = RN(x) unless y's 11
 * bits below the double's last lie next to or on the halfway pattern. */
static bool by_long_double(uint64_t m, int e, double *out)
{
#if LDBL_MANT_DIG == 64 && defined(__x86_64__)
    static const long double pow10[28] = {1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,
                                          1e10L, 1e11L, 1e12L, 1e13L, 1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L,
                                          1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
    if (e < -27 || e > 27) return false; /* 10^27 = 5^27 2^27, 5^27 < 2^64: exact */
    const long double y = e < 0 ? (long double)m / pow10[-e] : (long double)m * pow10[e];
    uint64_t bits;
    memcpy(&bits, &y, sizeof bits); /* the explicit 64-bit mantissa */
    const unsigned low = (unsigned)(bits & 0x7ffu);
    if (low >= 0x3ffu && low <= 0x401u) return false;
    if (!(y >= (long double)DBL_MIN && y <= (long double)DBL_MAX)) return false;
    *out = (double)y;
    return true;
#else
    (void)m, (void)e, (void)out;
    return false;
#endif
}

/* One JSON number at p (strict grammar, below `end`). Returns its length, or
 * 0 when the text there is not such a number or is longer than cJSON reads. */
static size_t lift_number(const char *p, const char *end, char point, double *out)
{
    const char *s = p;
    const bool negative = s < end && *s == '-';
    s += negative;
    if (s >= end || !is_digit(*s)) return 0;
    uint64_t m = 0;
    int digits = 0, scale = 0; /* significant digits kept; value = m 10^(scale + exp) */
    bool lost = false;         /* a nonzero digit beyond the 19 kept */
    if (*s == '0') {
        s++;
        if (s < end && is_digit(*s)) return 0; /* a leading zero */
    } else {
        for (; s < end && is_digit(*s); s++) {
            if (digits < 19) m = m * 10 + (uint64_t)(*s - '0'), digits++;
            else scale++, lost |= *s != '0';
        }
    }
    if (s < end && *s == '.') {
        s++;
        if (s >= end || !is_digit(*s)) return 0;
        for (; s < end && is_digit(*s); s++) {
            if (m == 0 && *s == '0') scale--; /* leading zeros of 0.000123 */
            else if (digits < 19) m = m * 10 + (uint64_t)(*s - '0'), digits++, scale--;
            else lost |= *s != '0';
        }
    }
    int ex = 0;
    if (s < end && (*s == 'e' || *s == 'E')) {
        s++;
        const bool eneg = s < end && *s == '-';
        if (s < end && (*s == '+' || *s == '-')) s++;
        if (s >= end || !is_digit(*s)) return 0;
        for (; s < end && is_digit(*s); s++)
            if (ex < 100000) ex = ex * 10 + (*s - '0');
        ex = eneg ? -ex : ex;
    }
    const size_t n = (size_t)(s - p);
    if (n > 63) return 0;
    const int e = scale + ex;
    double v;
    if (m == 0) v = 0;
    else if (!lost && m <= (1ull << 53) && e >= -22 && e <= 22)
        v = e < 0 ? (double)m / EXACT_POW10[-e] : (double)m * EXACT_POW10[e];
    else if (lost || !by_long_double(m, e, &v)) {
        *out = by_strtod(p, n, point);
        return n;
    }
    *out = negative ? -v : v;
    return n;
}

/* ---- the scan ------------------------------------------------------------ */

static bool is_blank(char c)
{
    return c == ' ' || c == '\n' || c == '\r' || c == '\t';
}

static const char *skip_blank(const char *p, const char *end)
{
    while (p < end && is_blank(*p)) p++;
    return p;
}

/* An array of numbers and nulls at p ('['): its entries appended to *col
 * and the text just past its ']' returned, or NULL (col->n back as it was)
 * when it is anything else. */
static const char *lift_array(const char *p, const char *end, char point, spn__lifted_col *col, size_t *cap,
                              bool *nomem)
{
    const size_t start = col->n;
    p = skip_blank(p + 1, end);
    if (p < end && *p == ']') return p + 1;
    for (;;) {
        if (col->n == *cap) {
            const size_t next = *cap ? *cap * 2 : 1024;
            double *bigger = realloc(col->v, next * sizeof *bigger);
            if (!bigger) {
                *nomem = true;
                break;
            }
            col->v = bigger, *cap = next;
        }
        if (end - p >= 4 && memcmp(p, "null", 4) == 0) {
            col->v[col->n++] = NAN;
            p += 4;
        } else {
            const size_t n = lift_number(p, end, point, &col->v[col->n]);
            if (!n) break;
            col->n++;
            p += n;
        }
        p = skip_blank(p, end);
        if (p < end && *p == ']') return p + 1;
        if (p >= end || *p != ',') break;
        p = skip_blank(p + 1, end);
    }
    col->n = start;
    return NULL;
}

/* Past the string that starts at p ('"'), or NULL if it does not close. */
static const char *skip_string(const char *p, const char *end, bool *escaped)
{
    *escaped = false;
    for (p++; p < end; p++) {
        if (*p == '"') return p + 1;
        if (*p == '\\') {
            *escaped = true;
            p++;
        }
    }
    return NULL;
}

static bool copy_out(spn__lifted *l, size_t *cap, const char *p, size_t n)
{
    if (l->skeleton_size + n + 1 > *cap) {
        size_t next = *cap ? *cap : 4096;
        while (next < l->skeleton_size + n + 1) next *= 2;
        char *bigger = realloc(l->skeleton, next);
        if (!bigger) return false;
        l->skeleton = bigger, *cap = next;
    }
    memcpy(l->skeleton + l->skeleton_size, p, n);
    l->skeleton_size += n;
    l->skeleton[l->skeleton_size] = 0;
    return true;
}

/* Is the value of field `key` of the top-level object `section` one to take
 * ("particles" or "springs", else section is empty), not taken before? Its
 * path ("particles.mass") in path. */
static bool wanted(const spn__lifted *l, const char *section, const char *key, char path[32])
{
    if (!*section || !*key || l->count == SPN__LIFT_MAX) return false;
    snprintf(path, 32, "%s.%s", section, key);
    return !spn__lifted_find(l, path);
}

spn_status spn__web_lift(const char *text, size_t size, spn__lifted *l)
{
    memset(l, 0, sizeof *l);
    const char *p = text, *end = text + size, *copied = text;
    const char point = *localeconv()->decimal_point;
    size_t skel_cap = 0;
    int depth = 0;         /* open objects and arrays */
    bool in_object[3] = {false, false, false}; /* the containers open at depths 0-2 */
    char section[16] = "", key[16] = ""; /* the field open at depth 1 (when it may be lifted from), at depth 2 */
    bool expect_key = false, nomem = false;
    while (p < end && !nomem) {
        const char c = *p;
        if (c == '"') {
            bool escaped;
            const char *q = skip_string(p, end, &escaped);
            if (!q) break; /* not JSON: cJSON will say where */
            const size_t n = (size_t)(q - p) - 2; /* the characters between the quotes */
            if (expect_key && (depth == 1 || depth == 2)) {
                char *slot = depth == 1 ? section : key;
                slot[0] = 0;
                if (!escaped && n < 16) memcpy(slot, p + 1, n), slot[n] = 0;
                if (depth == 1 && strcmp(section, "particles") != 0 && strcmp(section, "springs") != 0)
                    section[0] = 0;
            }
            expect_key = false;
            p = q;
        } else if (c == '{' || c == '[') {
            if (depth < 3) in_object[depth] = c == '{';
            if (depth == 1) key[0] = 0;
            depth++;
            expect_key = c == '{';
            p++;
        } else if (c == '}' || c == ']') {
            depth -= depth > 0;
            if (depth == 1) key[0] = 0;
            if (depth == 0) section[0] = 0;
            expect_key = false;
            p++;
        } else if (c == ',') {
            expect_key = depth >= 1 && depth <= 3 && in_object[depth - 1];
            p++;
        } else if (c == ':') {
            expect_key = false;
            p++;
            const char *v = skip_blank(p, end);
            char path[32];
            if (depth == 2 && in_object[0] && in_object[1] && v < end && *v == '[' && wanted(l, section, key, path)) {
                spn__lifted_col *col = &l->col[l->count];
                size_t cap = 0;
                const char *after = lift_array(v, end, point, col, &cap, &nomem);
                if (after) {
                    memcpy(col->path, path, sizeof col->path);
                    l->count++;
                    nomem = !copy_out(l, &skel_cap, copied, (size_t)(v - copied)) ||
                            !copy_out(l, &skel_cap, "[]", 2);
                    copied = p = after;
                } else {
                    free(col->v);
                    memset(col, 0, sizeof *col);
                }
            }
        } else p++;
    }
    if (!nomem && l->count) nomem = !copy_out(l, &skel_cap, copied, (size_t)(end - copied));
    if (nomem) {
        spn__lifted_free(l);
        return spn_error(SPN_ERR_NOMEM, "out of memory reading a web file");
    }
    return SPN_OK;
}

const spn__lifted_col *spn__lifted_find(const spn__lifted *l, const char *path)
{
    for (int i = 0; l && i < l->count; i++)
        if (strcmp(l->col[i].path, path) == 0) return &l->col[i];
    return NULL;
}

void spn__lifted_free(spn__lifted *l)
{
    for (int i = 0; i < l->count; i++) free(l->col[i].v);
    free(l->skeleton);
    memset(l, 0, sizeof *l);
}

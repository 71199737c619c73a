/* The JSON web file's float text (src/io/shortest.c): the integer
 * arithmetic gives exactly the text of the definition (the first of %.15g,
 * %.16g, %.17g that strtod reads back to the same bits) on values of every
 * kind: web-like coordinates, random bit patterns, integers, short decimals
 * and their neighbours, powers of two (whose lower neighbour is nearer),
 * exact decimal ties, and the edges of the range it serves. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"

static int checked;

static void assert_same_text(double v)
{
    char fast[40], slow[40];
    spn__format_double(fast, v);
    spn__format_double_printf(slow, v);
    if (strcmp(fast, slow) != 0) fail_msg("%.17g: %s, expected %s", v, fast, slow);
    double back = strtod(fast, NULL);
    if (memcmp(&back, &v, sizeof v) != 0) fail_msg("%s does not read back to %.17g", fast, v);
    checked++;
}

static uint64_t next(uint64_t *s)
{
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return *s;
}

static void test_kinds(void **state)
{
    (void)state;
    uint64_t s = 88172645463325252ull;
    for (int i = 0; i < 200000; i++) {
        const uint64_t r = next(&s);
        double v = (double)(r >> 11) / 9007199254740992.0;
        switch (i % 8) {
        case 0: memcpy(&v, &r, sizeof v); break; /* any bits */
        case 1: v = v * 0.3 - 0.1; break;         /* a web's coordinates */
        case 2: v = (double)(int64_t)(r >> (r & 63)); break;
        case 3: v = (double)(r % 100000000) / pow(10, (double)(r >> 59)); break;
        case 4: v = ldexp((double)(r >> 40), (int)(r % 200) - 100); break;
        case 5: v = ldexp((r >> 8) & 1 ? -1.0 : 1.0, (int)(r % 150) - 100); break;
        case 6: v = nextafter((double)(r % 1000000000000000ull) / pow(10, (double)((r >> 50) % 30)),
                              (r >> 5) & 1 ? INFINITY : -INFINITY);
            break;
        default: v = v * 1e-6; break; /* rest lengths of short threads, masses */
        }
        if (isfinite(v)) assert_same_text(v);
    }
    assert_true(checked > 190000);
}

static void test_edges(void **state)
{
    (void)state;
    const double edges[] = {0.0, -0.0, 1.0, -1.0, 0.1, 0.3, 2.0 / 3, 1e-25, 1e-24, 9.999999999999999e-26, 1e14,
                            99999999999999.98, 1e13, 1e15, 1e16, 1e17, 1e21, 1e22, 1e-5, 1e-4, 0.00012345,
                            9.5367431640625e-07, 112589990684262.5, /* 16 digits, an exact tie at 15 */
                            0.5, 0.25, 4.9406564584124654e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                            9.999999999999999e22, 123456789012345.67, 0.0009765625, 1.0 / 3 * 1e-20};
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        assert_same_text(edges[i]);
        assert_same_text(-edges[i]);
        assert_same_text(nextafter(edges[i], INFINITY));
        assert_same_text(nextafter(edges[i], -INFINITY));
    }
    /* every power of two the integer path serves, and its neighbours */
    for (int e = -84; e <= 47; e++) {
        const double p = ldexp(1.0, e);
        assert_same_text(p), assert_same_text(nextafter(p, 0)), assert_same_text(nextafter(p, INFINITY));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_kinds), cmocka_unit_test(test_edges)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}

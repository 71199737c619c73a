/* The JSON web file's columns read straight from the text (src/io/web_lift.c):
 * every number the same double as strtod gives (so as cJSON gives), on
 * numbers of every shape including decimals a hair from a halfway point
 * between two doubles; anything that is not JSON's own number grammar left
 * to cJSON; only the top-level sections' arrays taken; and every web file of
 * the test data, good or bad, and edits of one that put each kind of bad
 * entry in a taken column, read to the same world or refused with the same
 * message whether the columns are taken or not. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "io/io_internal.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t next_u64(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

/* ---- numbers ------------------------------------------------------------- */

enum { MAX_TOKENS = 20000 };
static char tokens[MAX_TOKENS][72];
static int ntokens;

static void add_token(const char *t)
{
    if (ntokens < MAX_TOKENS && strlen(t) <= 63) snprintf(tokens[ntokens++], sizeof tokens[0], "%s", t);
}

static double random_double(void)
{
    uint64_t bits = next_u64() & ~(0x7ffull << 52);
    bits |= (uint64_t)(1023 - 40 + (int)(next_u64() % 60)) << 52; /* 1e-12 .. 1e6 */
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

static void make_tokens(void)
{
    char t[96];
    ntokens = 0;
    static const char *const fixed[] = {"0", "-0", "1", "-1", "0.5", "10", "1e5", "1E5", "1e+5", "1e-5",
                                        "-0.0e-0", "9007199254740992", "9007199254740993", "18446744073709551615",
                                        "18446744073709551616", "123456789012345678901234567890", "1e22", "1e23",
                                        "1e-22", "1e-23", "1e308", "1.7976931348623157e308", "1e309", "1e-320",
                                        "2.2250738585072014e-308", "4.9e-324", "1e-400", "0.000000000000000000001",
                                        "100000000000000000000000000000000000000000000000000000000000000",
                                        "1.00000000000000000000000000000000000000000000000000000000000001",
                                        "0.1", "0.2", "0.3", "3.141592653589793", "2.718281828459045"};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) add_token(fixed[i]);
    for (int i = 0; i < 3000; i++) { /* what the writer prints: %.15g to %.17g of web-like values */
        const double v = random_double() * (next_u64() & 1 ? -1 : 1);
        for (int p = 15; p <= 17; p++) {
            snprintf(t, sizeof t, "%.*g", p, v);
            add_token(t);
        }
    }
    for (int i = 0; i < 3000; i++) { /* a decimal a hair from the halfway point between two doubles */
        const double a = random_double(), b = nextafter(a, INFINITY);
        const long double mid = ((long double)a + (long double)b) / 2; /* exact: 54 bits */
        const int digits = 17 + (int)(next_u64() % 6);
        snprintf(t, sizeof t, "%.*Le", digits - 1, mid);
        add_token(t);
        snprintf(t, sizeof t, "%.*Le", digits - 1, nextafterl(mid, (long double)INFINITY));
        add_token(t);
        snprintf(t, sizeof t, "%.*Le", digits - 1, nextafterl(mid, 0.0L));
        add_token(t);
    }
    while (ntokens < MAX_TOKENS) { /* random digits, point and exponent */
        const int n = 1 + (int)(next_u64() % 24), point = (int)(next_u64() % (unsigned)(n + 1));
        char *o = t;
        if (next_u64() & 1) *o++ = '-';
        for (int i = 0; i < n; i++) {
            if (i == point && i > 0) *o++ = '.';
            *o++ = (char)('0' + (i == 0 ? 1 + next_u64() % 9 : next_u64() % 10));
        }
        if (next_u64() & 1) o += sprintf(o, "e%d", (int)(next_u64() % 81) - 40);
        *o = 0;
        add_token(t);
    }
}

/* {"particles": {"mass": [tokens...]}} */
static char *numbers_document(int first, int count, const char *sep)
{
    size_t cap = 64 + (size_t)count * 80;
    char *doc = malloc(cap), *o = doc;
    o += sprintf(o, "{\"particles\": {\"mass\": [");
    for (int i = 0; i < count; i++) o += sprintf(o, "%s%s", i ? sep : "", tokens[first + i]);
    sprintf(o, "]}}");
    return doc;
}

static void test_numbers_match_strtod(void **state)
{
    (void)state;
    make_tokens();
    const char *seps[] = {",", ", ", " ,\n\t", "\r\n,"};
    for (int s = 0; s < 4; s++) {
        char *doc = numbers_document(0, ntokens, seps[s]);
        spn__lifted l;
        assert_int_equal(spn__web_lift(doc, strlen(doc), &l), SPN_OK);
        assert_int_equal(l.count, 1);
        assert_string_equal(l.col[0].path, "particles.mass");
        assert_int_equal(l.col[0].n, ntokens);
        assert_string_equal(l.skeleton, "{\"particles\": {\"mass\": []}}");
        for (int i = 0; i < ntokens; i++) {
            const double want = strtod(tokens[i], NULL), got = l.col[0].v[i];
            if (memcmp(&want, &got, sizeof want) != 0)
                fail_msg("'%s': %.17g (%a) read, strtod gives %.17g (%a)", tokens[i], got, got, want, want);
        }
        spn__lifted_free(&l);
        free(doc);
    }
}

/* What is not a JSON number, or is one cJSON would cut, stays in the text. */
static void test_other_entries_stay_in_text(void **state)
{
    (void)state;
    static const char *const entries[] = {
        "01", "+1", ".5", "1.", "1e", "1e+", "-", "--1", "1x", "0x10", "1.5.3", "true", "false", "\"1\"", "[1]",
        "{}", "nul", "nullx", "NaN", "Infinity", "1 2", "1,,2", "1,", "\x01" "1",
        "1234567890123456789012345678901234567890123456789012345678901234" /* 64 characters */};
    for (size_t i = 0; i < sizeof entries / sizeof entries[0]; i++) {
        char doc[256];
        snprintf(doc, sizeof doc, "{\"particles\": {\"mass\": [0, %s, 2], \"tag\": [1, 2, 3]}}", entries[i]);
        spn__lifted l;
        assert_int_equal(spn__web_lift(doc, strlen(doc), &l), SPN_OK);
        if (spn__lifted_find(&l, "particles.mass")) fail_msg("[0, %s, 2] was taken", entries[i]);
        assert_non_null(spn__lifted_find(&l, "particles.tag")); /* the next array still is */
        assert_non_null(strstr(l.skeleton, entries[i]));
        spn__lifted_free(&l);
    }
    /* 63 characters is what cJSON reads whole */
    const char *doc = "{\"springs\": {\"k\": [1.0000000000000000000000000000000000000000000000000000000000001]}}";
    spn__lifted l;
    assert_int_equal(spn__web_lift(doc, strlen(doc), &l), SPN_OK);
    assert_int_equal(l.count, 1);
    assert_true(l.col[0].v[0] == 1.0);
    spn__lifted_free(&l);
}

/* Only a field of the top-level "particles" or "springs" object, once. */
static void test_only_the_sections_columns(void **state)
{
    (void)state;
    static const struct {
        const char *doc;
        int taken;
    } cases[] = {
        {"{\"particles\": {\"mass\": [1, null, 2]}, \"springs\": {\"k\": [3]}}", 2},
        {"{\"metadata\": {\"particles\": {\"mass\": [1, 2]}}, \"x\": [1]}", 0},
        {"{\"world\": {\"gravity\": [0, -9.81, 0]}}", 0},
        {"{\"particles\": {\"deep\": {\"mass\": [1, 2]}}}", 0},
        {"{\"particles\": [{\"mass\": [1, 2]}]}", 0},
        {"[{\"particles\": {\"mass\": [1, 2]}}]", 0},
        {"{\"p\\u0061rticles\": {\"mass\": [1, 2]}}", 0},
        {"{\"particles\": {\"m\\u0061ss\": [1, 2]}}", 0},
        {"{\"particles\": {\"mass\": [1], \"mass\": [2]}}", 1},
        {"{\"key \\\"particles\\\"\": {\"mass\": [1]}, \"particles\": {\"mass\": [5]}}", 1},
        {"{\"particles\": {\"note\": \"a ] and a [ and a \\\" in text\", \"mass\": [7]}}", 1},
        {"{\"particles\": {\"mass\": [1, 2]", 1}, /* not JSON: cJSON says so, on the skeleton and the text */
        {"{{\n \"", 0},                             /* a string left open (found by fuzz_web_json) */
        {"{\"particles\": {\"mass\": [1], \"k", 1},
        {"{\"particles\": {\"mass\": [1], \"k\\", 1},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        spn__lifted l;
        assert_int_equal(spn__web_lift(cases[i].doc, strlen(cases[i].doc), &l), SPN_OK);
        if (l.count != cases[i].taken) fail_msg("%s: %d columns taken, expected %d", cases[i].doc, l.count, cases[i].taken);
        spn__lifted_free(&l);
    }
    const char *doc = "{\"key \\\"particles\\\"\": {\"mass\": [1]}, \"particles\": {\"mass\": [5]}}";
    spn__lifted l;
    assert_int_equal(spn__web_lift(doc, strlen(doc), &l), SPN_OK);
    assert_true(l.col[0].v[0] == 5);
    spn__lifted_free(&l);
}

/* ---- whole files: the same world or the same message either way ----------- */

static int compared;

static void same_either_way(const char *text, size_t size, const char *what)
{
    spn_world *a = NULL, *b = NULL;
    const spn_status sa = spn__web_parse_json(text, size, "web.json", true, &a);
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", spn_last_error());
    const spn_status sb = spn__web_parse_json(text, size, "web.json", false, &b);
    if (sa != sb) fail_msg("%s: status %d with the columns taken, %d without (%s / %s)", what, sa, sb, msg, spn_last_error());
    if (sa != SPN_OK) {
        if (strcmp(msg, spn_last_error()) != 0) fail_msg("%s: '%s' against '%s'", what, msg, spn_last_error());
        assert_null(a);
        assert_null(b);
    } else {
        spn_buffer ba = {0}, bb = {0};
        spn_sink sink = spn_sink_buffer(&ba);
        assert_int_equal(spn_web_write(a, &sink), SPN_OK);
        sink = spn_sink_buffer(&bb);
        assert_int_equal(spn_web_write(b, &sink), SPN_OK);
        if (ba.size != bb.size || memcmp(ba.data, bb.data, ba.size) != 0) fail_msg("%s: the worlds differ", what);
        spn_buffer_free(&ba);
        spn_buffer_free(&bb);
    }
    spn_world_destroy(a);
    spn_world_destroy(b);
    compared++;
}

static char *read_file(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    rewind(fp);
    char *text = malloc((size_t)n + 1);
    *size = fread(text, 1, (size_t)n, fp);
    text[*size] = 0;
    fclose(fp);
    return text;
}

static void compare_folder(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    for (struct dirent *e; (e = readdir(d));) {
        const size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 5, ".json") != 0) continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        size_t size;
        char *text = read_file(path, &size);
        same_either_way(text, size, path);
        free(text);
    }
    closedir(d);
}

/* chain4.json with `from` replaced by `to` */
static void edited(const char *text, const char *from, const char *to)
{
    const char *at = strstr(text, from);
    if (!at) fail_msg("'%s' is not in chain4.json", from);
    size_t len = strlen(text) - strlen(from) + strlen(to);
    char *doc = malloc(len + 1);
    sprintf(doc, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
    char what[256];
    snprintf(what, sizeof what, "chain4.json with %s", to);
    same_either_way(doc, len, what);
    free(doc);
}

static void test_files_read_the_same(void **state)
{
    (void)state;
    compared = 0;
    compare_folder(SPN_TEST_DATA "/io");
    compare_folder(SPN_TEST_DATA "/bad");
    size_t size;
    char *text = read_file(SPN_TEST_DATA "/io/chain4.json", &size);
    static const char *const edits[][2] = {
        {"\"fixed\": [1, 0, 0, 1]", "\"fixed\": [true, false, 0, 1]"},
        {"\"fixed\": [1, 0, 0, 1]", "\"fixed\": [1, 0, null, 1]"},
        {"\"fixed\": [1, 0, 0, 1]", "\"fixed\": [1, 0, 0.5, 1]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, null, 0.001, 0]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, 1e999, 0.001, 0]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, -1e-3, 0.001, 0]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, 0.001, 0.001]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, 0.001, 0.001, 0, 0]"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": []"},
        {"\"mass\": [0, 0.001, 0.001, 0]", "\"mass\": [0, 0.001, 0.001, 0], \"mass\": [1, 1, 1, 1]"},
        {"\"position\": [-0.1, 0, 0", "\"position\": [-0.1, -1e400, 0"},
        {"\"position\": [-0.1, 0, 0", "\"position\": [-0.1, 0.00000000000000000000000000000000000001, 0"},
        {"\"a\": [0, 1, 2]", "\"a\": [0, 1.5, 2]"},
        {"\"a\": [0, 1, 2]", "\"a\": [0, null, 2]"},
        {"\"a\": [0, 1, 2]", "\"a\": [0, 4294967296, 2]"},
        {"\"a\": [0, 1, 2]", "\"a\": [0, -0, 2]"},
        {"\"b\": [1, 2, 3]", "\"b\": [1, 2, 9]"},
        {"\"break_max\": [null, null, 0.5]", "\"break_max\": [null, -1, 0.5]"},
        {"\"break_max\": [null, null, 0.5]", "\"break_max\": [null, 1e-9, 0.5]"},
        {"\"k\": [20, 20, 20]", "\"k\": [20, null, 20]"},
        {"\"tag\": [1, 6, 1]", "\"tag\": [1, 6, 4294967295]"},
        {"\"tag\": [1, 6, 1]", "\"tag\": [1, 6, 1e1]"},
        {"\"order\": [0, 1, 2]", "\"order\": [0, 1 2]"},
        {"\"order\": [0, 1, 2]", "\"order\": [0, 1, 2,]"},
        {"\"order\": [0, 1, 2]", "\"order\": [0, 1, 2]]"},
        {"\"order\": [0, 1, 2]", "\"order\": [0, 1, 2], \"colour\": [1]"},
        {"\"stage\": [0, 1, 0]", "\"stage\": [0, 1, 0], \"x\": NaN"},
        {"\"count\": 3,", "\"count\": 3, \"k\": [1, 2, 3],"},
        {"\"springs\": {", "\"springs\": \n{"},
        {"\"drag\": 2", "\"drag\": 2, \"gravity\": [0, 0, 0]"},
        {"\"seed\": 7}", "\"seed\": 7, \"particles\": {\"mass\": [1]}}"},
    };
    for (size_t i = 0; i < sizeof edits / sizeof edits[0]; i++) edited(text, edits[i][0], edits[i][1]);
    /* the text cut anywhere: a syntax error after a taken column, at its place in the text */
    for (size_t cut = 1; cut < size; cut += 7) same_either_way(text, cut, "chain4.json cut short");
    free(text);
    assert_true(compared > 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_numbers_match_strtod),
        cmocka_unit_test(test_other_entries_stay_in_text),
        cmocka_unit_test(test_only_the_sections_columns),
        cmocka_unit_test(test_files_read_the_same),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The binary web file (docs/web-format.md, "Binary file"): save -> load gives
 * back every bit, the same world as the JSON file; the layout is the one the
 * document describes (offsets computed here from the document, not from the
 * code); every damaged or bad file is refused naming what is wrong; a world
 * the writer refuses leaves no bytes in a sink and no file on disk. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <spinneret/spinneret.h>

#include "physics/world_internal.h" /* spn__world_plant */

#include "web_io_util.h"

static spn_buffer binary_of(const spn_world *w)
{
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(spn_web_write_binary(w, &sink), SPN_OK);
    return buf;
}

static uint32_t get_u32(const char *p)
{
    const unsigned char *u = (const unsigned char *)p;
    return (uint32_t)u[0] | (uint32_t)u[1] << 8 | (uint32_t)u[2] << 16 | (uint32_t)u[3] << 24;
}

static void put_f64(char *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    for (int i = 0; i < 8; i++) p[i] = (char)(u >> 8 * i);
}

static void test_round_trip_bits(void **state)
{
    (void)state;
    spn_world *w = awkward_world();
    spn_buffer buf = binary_of(w);
    spn_world *back = assert_reads_back(&buf, w);

    /* The same world as through the JSON file, and written again, the same
     * bytes. */
    spn_buffer json = web_json_of(w);
    spn_world *from_json = NULL;
    assert_int_equal(spn_web_parse(json.data, json.size, "memory.json", &from_json), SPN_OK);
    assert_same_world(from_json, back);
    spn_buffer again = binary_of(from_json);
    assert_int_equal(again.size, buf.size);
    assert_memory_equal(again.data, buf.data, buf.size);

    /* Through a file: spn_web_save picks the binary file by its extension,
     * spn_web_load tells it by its content, whatever the name. */
    char dir[] = "/tmp/spn-iob-XXXXXX", path[64], renamed[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/web.spnw", dir);
    snprintf(renamed, sizeof renamed, "%s/web.json", dir);
    assert_true(spn_web_path_is_binary(path));
    assert_false(spn_web_path_is_binary(renamed) || spn_web_path_is_binary(".spnw") ||
                 spn_web_path_is_binary("web.spnw.json") || spn_web_path_is_binary(NULL));
    assert_int_equal(spn_web_save(back, path), SPN_OK);
    assert_int_equal(rename(path, renamed), 0);
    spn_world *loaded = NULL;
    assert_int_equal(spn_web_load(renamed, &loaded), SPN_OK);
    assert_same_world(w, loaded);
    remove(renamed);
    rmdir(dir);
    spn_buffer_free(&buf);
    spn_buffer_free(&json);
    spn_buffer_free(&again);
    spn_world_destroy(w);
    spn_world_destroy(back);
    spn_world_destroy(from_json);
    spn_world_destroy(loaded);
}

/* A file written when the layout was made (tests/data/io/chain4.spnw, from
 * chain4.json): files already written must keep reading the same. */
static void test_kept_file_reads(void **state)
{
    (void)state;
    spn_world *a = NULL, *b = NULL;
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/io/chain4.spnw", &a), SPN_OK);
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/io/chain4.json", &b), SPN_OK);
    assert_same_world(a, b);
    spn_world_destroy(a);
    spn_world_destroy(b);
}

/* Where the documented layout puts things in a file of np particles and ns
 * springs: the frame, the header, its padding, then the columns. */
typedef struct layout {
    size_t header, columns; /* offsets */
    size_t position, mass, k, break_max, spring_b, fixed;
} layout;

static layout layout_of(const spn_buffer *buf, size_t np, size_t ns)
{
    layout l;
    l.header = 16;
    const size_t end = l.header + get_u32(buf->data + 12);
    l.columns = (end + 7) / 8 * 8;
    l.position = l.columns;
    l.mass = l.position + 2 * 24 * np;                /* after position, velocity */
    l.k = l.mass + 8 * np;
    l.break_max = l.k + 4 * 8 * ns;                   /* after k, kd, rest, break_min */
    l.spring_b = l.break_max + 8 * ns + 4 * np + 4 * ns; /* after break_max, particles.tag, springs.a */
    l.fixed = l.spring_b + 4 * 4 * ns;                /* after b, tag, stage, order */
    return l;
}

/* The file with `n` bytes at `at` replaced, parsed: refused, and the message
 * holds `expect`. */
static void assert_refused(const spn_buffer *good, size_t size, size_t at, const void *bytes, size_t n,
                           const char *expect)
{
    char *copy = malloc(size > good->size ? size : good->size);
    assert_non_null(copy);
    memcpy(copy, good->data, good->size);
    if (size > good->size) memset(copy + good->size, 0, size - good->size);
    if (n) memcpy(copy + at, bytes, n);
    spn_world *w = (spn_world *)1;
    assert_int_equal(spn_web_parse(copy, size, "bad.spnw", &w), SPN_ERR_FORMAT);
    assert_null(w);
    if (!strstr(spn_last_error(), expect) || !strstr(spn_last_error(), "bad.spnw"))
        fail_msg("expected '%s' in: %s", expect, spn_last_error());
    free(copy);
}

static void test_bad_files_refused(void **state)
{
    (void)state;
    spn_world *w = awkward_world();
    const size_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    spn_buffer buf = binary_of(w);
    const layout l = layout_of(&buf, np, ns);
    assert_int_equal(buf.size, l.fixed + np + 2 * ns); /* the three byte columns end the file */
    char nan8[8], inf8[8], minus_inf8[8], neg8[8];
    put_f64(nan8, NAN), put_f64(inf8, INFINITY), put_f64(minus_inf8, -INFINITY), put_f64(neg8, -1e-9);
    const char two = 2, nul = 0, one = 1;
    const char layout2[4] = {2, 0, 0, 0}, huge[4] = {(char)0xff, (char)0xff, (char)0xff, 0x7f};
    const uint32_t far = 1000;
    char b_far[4];
    for (int i = 0; i < 4; i++) b_far[i] = (char)(far >> 8 * i);

    assert_refused(&buf, 12, 0, NULL, 0, "cut short: 12 bytes");
    assert_refused(&buf, buf.size, 8, layout2, 4, "layout 2 not supported");
    assert_refused(&buf, buf.size, 12, huge, 4, "its header claims 2147483647 bytes");
    assert_refused(&buf, buf.size, l.header, "[", 1, "header: not JSON");
    assert_refused(&buf, buf.size, l.header + 5, &nul, 1, "header: not JSON: NUL byte at offset 5");
    assert_refused(&buf, buf.size, l.header + strlen("{\n  \"f"), "X", 1, "missing field 'format'");
    assert_refused(&buf, buf.size - 1, 0, NULL, 0, "(a truncated file?)");
    assert_refused(&buf, buf.size + 8, 0, NULL, 0, "the columns take");
    assert_refused(&buf, buf.size, l.position + 8 * 4, nan8, 8, "particles.position[4] (particle 1, y): NaN");
    assert_refused(&buf, buf.size, l.mass + 8 * 2, inf8, 8, "particles.mass[2]: an infinity is not allowed");
    assert_refused(&buf, buf.size, l.mass + 8 * 2, neg8, 8, "particles.mass[2]: negative mass");
    assert_refused(&buf, buf.size, l.k + 8, neg8, 8, "springs.k[1]: negative stiffness");
    assert_refused(&buf, buf.size, l.break_max, minus_inf8, 8, "springs.break_max[0]: an infinity");
    assert_refused(&buf, buf.size, l.spring_b + 4 * 3, b_far, 4, "springs.b[3]: particle 1000 does not exist");
    assert_refused(&buf, buf.size, l.fixed + 3, &two, 1, "particles.fixed[3]: expected 0 or 1, got 2");
    if (l.columns > get_u32(buf.data + 12) + l.header) /* the header's length is not a multiple of 8 */
        assert_refused(&buf, buf.size, l.columns - 1, &one, 1, "padding after the header is not zero");

    spn_buffer_free(&buf);
    spn_world_destroy(w);
}

/* A header that is a JSON web file's complete document (columns and all) is
 * not a binary file's header: its columns would be ambiguous. */
static void test_header_with_columns_refused(void **state)
{
    (void)state;
    spn_world *w = awkward_world();
    spn_buffer json = web_json_of(w);
    const size_t size = 16 + (json.size + 7) / 8 * 8;
    char *file = calloc(1, size);
    assert_non_null(file);
    memcpy(file, "\x89SPNWEB\n\x01\x00\x00\x00", 12);
    for (int i = 0; i < 4; i++) file[12 + i] = (char)(json.size >> 8 * i);
    memcpy(file + 16, json.data, json.size);
    spn_world *out = NULL;
    assert_int_equal(spn_web_parse(file, size, "mixed.spnw", &out), SPN_ERR_FORMAT);
    if (!strstr(spn_last_error(), "particles.position: unknown field")) fail_msg("%s", spn_last_error());
    free(file);
    spn_buffer_free(&json);
    spn_world_destroy(w);
}

static void test_refused_world_writes_nothing(void **state)
{
    (void)state;
    char dir[] = "/tmp/spn-iob-XXXXXX", path[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/web.spnw", dir);
    spn_world *w = awkward_world();
    const spn_vec3 x9 = spn_world_position(w, 9);
    spn__world_plant(w, 9, x9, spn_v3(0, 0, INFINITY), UINT32_MAX, 0);
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(spn_web_write_binary(w, &sink), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "particle 9: velocity is not finite"));
    assert_int_equal(buf.size, 0);
    assert_int_equal(spn_web_save(w, path), SPN_ERR_INVALID);
    assert_int_equal(count_files(dir), 0);
    spn__world_plant(w, 9, x9, spn_v3(0, 0, 0), 2, NAN);
    assert_int_equal(spn_web_save(w, path), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "spring 2: rest is not finite"));
    assert_int_equal(count_files(dir), 0);
    rmdir(dir);
    spn_buffer_free(&buf);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_bits),
        cmocka_unit_test(test_kept_file_reads),
        cmocka_unit_test(test_bad_files_refused),
        cmocka_unit_test(test_header_with_columns_refused),
        cmocka_unit_test(test_refused_world_writes_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

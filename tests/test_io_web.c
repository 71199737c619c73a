/* The web file (docs/web-format.md): every file of the bad corpus is refused
 * with a message naming its problem; save -> load gives back the same bits in
 * every field; a failed save leaves no file and clobbers nothing. */
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
#include <unistd.h>
#include <spinneret/spinneret.h>

#include "physics/world_internal.h" /* spn__world_plant */

#include "web_io_util.h"

/* One row per file in tests/data/bad/: the text its message must contain. */
static const struct {
    const char *file, *expect;
} corpus[] = {
    {"empty.json", "empty file"},
    {"blank.json", "empty file"},
    {"truncated.json", "not JSON: syntax error at line 11, column"},
    {"nan_literal.json", "line 6, column 47 (NaN and infinities are not allowed)"},
    {"duplicate_field.json", "particles.mass: field appears twice"},
    {"trailing_text.json", "text after the end of the document at line 30"},
    {"top_array.json", "expected a JSON object at the top, got an array"},
    {"nul_byte.json", "NUL byte at offset 40"},
    {"missing_format.json", "missing field 'format'"},
    {"unknown_format.json", "unknown format 'obj-mesh'"},
    {"version_2.json", "unsupported version 2"},
    {"version_string.json", "version: expected a number, got a string"},
    {"units_imperial.json", "units: only \"SI\""},
    {"metadata_array.json", "metadata: expected an object, got an array"},
    {"missing_particles.json", "missing field 'particles'"},
    {"missing_mass.json", "missing field 'particles.mass'"},
    {"missing_rest.json", "missing field 'springs.rest'"},
    {"missing_count.json", "missing field 'springs.count'"},
    {"position_short.json", "particles.position: has 11 entries, expected 12"},
    {"k_short.json", "springs.k: has 2 entries, expected 3"},
    {"tag_long.json", "particles.tag: has more than 4 entries"},
    {"position_inf.json", "particles.position[4] (particle 1, y): number out of range"},
    {"mass_negative.json", "particles.mass[2]: negative mass"},
    {"mass_string.json", "particles.mass[1]: expected a number, got a string"},
    {"fixed_two.json", "particles.fixed[3]: expected 0, 1, true or false, got 2"},
    {"spring_to_missing.json", "springs.b[1]: particle 7 does not exist"},
    {"spring_to_itself.json", "springs.b[2]: spring joins particle 2 to itself"},
    {"spring_negative_end.json", "springs.a[0]: expected a whole number"},
    {"k_negative.json", "springs.k[1]: negative stiffness"},
    {"tag_fraction.json", "springs.tag[2]: expected a whole number in [0, 4294967295], got 1.5"},
    {"break_max_below_min.json", "springs.break_max[0]: 0.01 is less than break_min"},
    {"count_too_big.json", "particles.count: expected a whole number in [0, 100000000]"},
    {"count_huge_short.json", "particles.position: has 12 entries, expected 270000000"},
    {"unknown_field.json", "particles.colour: unknown field"},
    {"integrator_unknown.json", "world.integrator: unknown integrator 'verlet'"},
    {"gravity_short.json", "world.gravity: expected 3 numbers, got 2"},
    {"drag_negative.json", "world.drag: -1 is out of range"},
    {"particles_array.json", "particles: expected an object, got an array"},
    {"seed_negative.json", "world.seed: expected a whole number"},      /* found by fuzz_web_json */
    {"count_huge_number.json", "springs.count: expected a whole number"}, /* found by fuzz_web_json */
};
#define CORPUS_SIZE (sizeof corpus / sizeof corpus[0])

static void test_good_file_loads(void **state)
{
    (void)state;
    spn_world *w = NULL;
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/io/chain4.json", &w), SPN_OK);
    assert_int_equal(spn_world_particle_count(w), 4);
    assert_int_equal(spn_world_spring_count(w), 3);
    assert_true(spn_world_is_fixed(w, 0) && !spn_world_is_fixed(w, 1));
    assert_true(spn_world_mass(w, 1) == 0.001);
    spn_spring_info s = spn_world_spring(w, 2);
    assert_int_equal(s.a, 2);
    assert_int_equal(s.b, 3);
    assert_true(s.break_max == 0.5 && isinf(spn_world_spring(w, 0).break_max));
    assert_true(s.tension_only && !s.broken);
    assert_int_equal(spn_world_spring(w, 1).tag, SPN_THREAD_CAPTURE);
    assert_true(spn_world_get_def(w)->drag == 2);
    assert_non_null(strstr(spn_world_metadata(w), "\"builder\":\"hand-written\""));
    spn_world_destroy(w);
}

static void test_bad_corpus_refused(void **state)
{
    (void)state;
    for (size_t i = 0; i < CORPUS_SIZE; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/bad/%s", SPN_TEST_DATA, corpus[i].file);
        spn_world *w = (spn_world *)path; /* must come back NULL */
        spn_status st = spn_web_load(path, &w);
        if (st != SPN_ERR_FORMAT || w != NULL || !strstr(spn_last_error(), corpus[i].expect) ||
            !strstr(spn_last_error(), corpus[i].file))
            fail_msg("%s: status %s, message '%s', expected '%s'", corpus[i].file, spn_status_name(st),
                     spn_last_error(), corpus[i].expect);
    }
}

/* Every file in tests/data/bad/ has a row above, so none goes untested. */
static void test_corpus_table_complete(void **state)
{
    (void)state;
    DIR *dir = opendir(SPN_TEST_DATA "/bad");
    assert_non_null(dir);
    size_t files = 0;
    char unlisted[256] = "";
    for (struct dirent *e; (e = readdir(dir));) {
        const char *dot = strrchr(e->d_name, '.');
        if (!dot || strcmp(dot, ".json") != 0) continue;
        files++;
        bool listed = false;
        for (size_t i = 0; i < CORPUS_SIZE; i++) listed |= strcmp(corpus[i].file, e->d_name) == 0;
        if (!listed) snprintf(unlisted, sizeof unlisted, "%s", e->d_name);
    }
    closedir(dir);
    if (*unlisted) fail_msg("tests/data/bad/%s has no expected message in the corpus table", unlisted);
    assert_int_equal(files, CORPUS_SIZE);
    assert_true(CORPUS_SIZE >= 20);
}

static void test_missing_file(void **state)
{
    (void)state;
    spn_world *w = NULL;
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/io/no-such-web.json", &w), SPN_ERR_IO);
    assert_null(w);
    assert_non_null(strstr(spn_last_error(), "no-such-web.json: cannot open"));
}

static void test_round_trip_bits(void **state)
{
    (void)state;
    spn_world *w = awkward_world();
    spn_buffer buf = web_json_of(w);
    spn_world *back = assert_reads_back(&buf, w);
    assert_false(spn_world_spring(back, 5).broken);

    /* The same through a file, and a second save writes the same text. */
    char dir[] = "/tmp/spn-io-XXXXXX", path[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/web.json", dir);
    assert_int_equal(spn_web_save(back, path), SPN_OK);
    spn_world *again = NULL;
    assert_int_equal(spn_web_load(path, &again), SPN_OK);
    assert_same_world(w, again);
    spn_buffer buf2 = web_json_of(again);
    assert_string_equal(buf.data, buf2.data);
    remove(path);
    rmdir(dir);
    spn_buffer_free(&buf);
    spn_buffer_free(&buf2);
    spn_world_destroy(w);
    spn_world_destroy(back);
    spn_world_destroy(again);
}

static void test_failed_save_leaves_nothing(void **state)
{
    (void)state;
    char dir[] = "/tmp/spn-io-XXXXXX", path[64], fresh[64], text[32] = {0};
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/keep.json", dir);
    snprintf(fresh, sizeof fresh, "%s/new.json", dir);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs("precious", fp);
    fclose(fp);

    /* A NaN deep in the particle arrays: the writer has already written the
     * header and part of the arrays when it stops. */
    spn_world *w = awkward_world();
    spn__world_plant(w, 9, spn_v3(0, NAN, 0), spn_v3(0, 0, 0), UINT32_MAX, 0);
    assert_int_equal(spn_web_save(w, path), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "particle 9: position is not finite"));
    assert_int_equal(spn_web_save(w, fresh), SPN_ERR_INVALID);
    fp = fopen(path, "r");
    assert_non_null(fp);
    assert_non_null(fgets(text, sizeof text, fp));
    fclose(fp);
    assert_string_equal(text, "precious");
    assert_int_equal(count_files(dir), 1);

    /* Metadata that is not a JSON object is refused too. */
    spn_world_set_position(w, 9, spn_v3(0, 0, 0));
    assert_int_equal(spn_world_set_metadata(w, "[1, 2"), SPN_OK);
    assert_int_equal(spn_web_save(w, fresh), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "metadata"));
    assert_int_equal(count_files(dir), 1);

    /* A folder that does not exist. */
    assert_int_equal(spn_world_set_metadata(w, NULL), SPN_OK);
    assert_int_equal(spn_web_save(w, "/tmp/spn-no-such-folder/x/web.json"), SPN_ERR_IO);
    remove(path);
    rmdir(dir);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_file_loads),          cmocka_unit_test(test_bad_corpus_refused),
        cmocka_unit_test(test_corpus_table_complete),    cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_round_trip_bits),          cmocka_unit_test(test_failed_save_leaves_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

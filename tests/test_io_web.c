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

/* A web with every kind of value that could lose bits on the way: random
 * fractions, -0.0, a subnormal, huge and tiny magnitudes, finite and infinite
 * break lengths, broken and tension-only springs, fixed particles with mass. */
static spn_world *awkward_world(void)
{
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0.1, -9.80665, -0.0);
    def.drag = 0.3;
    def.integrator = SPN_INTEGRATOR_RK4;
    def.seed = 18446744073709551557ull; /* past 2^53: written as a string */
    def.provot_max_strain = 0.1;
    def.breakage = false;
    spn_orb_scene_def orb = spn_orb_scene_def_default();
    orb.rings = 4;
    orb.radials = 6;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&def, &orb, &w), SPN_OK);
    spn_rng rng;
    spn_rng_seed(&rng, 42);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        spn_vec3 p = spn_world_position(w, i);
        p.z = spn_rng_range(&rng, -1e-3, 1e-3);
        spn_world_set_position(w, i, p);
        if (!spn_world_is_fixed(w, i))
            spn_world_set_velocity(w, i, spn_v3(spn_rng_normal(&rng), -0.0, 4.9406564584124654e-324));
        spn_world_set_particle_tag(w, i, (uint32_t)spn_rng_below(&rng, 7));
    }
    spn_world_set_fixed(w, 3, true);
    spn_world_set_mass(w, 5, 1e-300);
    spn_world_set_spring_rest(w, 1, 1.0 / 3.0);
    spn_world_set_spring_stiffness(w, 2, 1e30, 1e-30);
    spn_world_break_spring(w, 4);
    spn_world_break_spring(w, 7);
    spn_world_set_time(w, 12.345678901234567);
    assert_int_equal(spn_world_set_metadata(w, "{\"builder\":\"test\",\"parameters\":{\"rings\":4},\"seed\":42}"),
                     SPN_OK);
    return w;
}

static bool same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }
static bool same_vec(spn_vec3 a, spn_vec3 b) { return memcmp(&a, &b, sizeof a) == 0; }

static void assert_same_world(const spn_world *a, const spn_world *b)
{
    const spn_world_def *da = spn_world_get_def(a), *db = spn_world_get_def(b);
    assert_true(same_vec(da->gravity, db->gravity));
    assert_true(same_bits(da->drag, db->drag) && da->integrator == db->integrator);
    assert_true(da->seed == db->seed && da->breakage == db->breakage);
    assert_true(same_bits(da->provot_max_strain, db->provot_max_strain));
    assert_true(same_bits(spn_world_time(a), spn_world_time(b)));
    assert_string_equal(spn_world_metadata(a), spn_world_metadata(b));
    assert_int_equal(spn_world_particle_count(a), spn_world_particle_count(b));
    assert_int_equal(spn_world_spring_count(a), spn_world_spring_count(b));
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++) {
        assert_true(same_vec(spn_world_position(a, i), spn_world_position(b, i)));
        assert_true(same_vec(spn_world_velocity(a, i), spn_world_velocity(b, i)));
        assert_true(same_bits(spn_world_mass(a, i), spn_world_mass(b, i)));
        assert_int_equal(spn_world_is_fixed(a, i), spn_world_is_fixed(b, i));
        assert_int_equal(spn_world_particle_tag(a, i), spn_world_particle_tag(b, i));
    }
    for (uint32_t s = 0; s < spn_world_spring_count(a); s++) {
        spn_spring_info x = spn_world_spring(a, s), y = spn_world_spring(b, s);
        assert_true(x.a == y.a && x.b == y.b && x.tag == y.tag && x.stage == y.stage && x.order == y.order);
        assert_true(same_bits(x.k, y.k) && same_bits(x.kd, y.kd) && same_bits(x.rest, y.rest));
        assert_true(same_bits(x.break_min, y.break_min) && same_bits(x.break_max, y.break_max));
        assert_true(x.tension_only == y.tension_only && x.broken == y.broken);
    }
}

static void test_round_trip_bits(void **state)
{
    (void)state;
    spn_world *w = awkward_world();
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(spn_web_write(w, &sink), SPN_OK);
    spn_world *back = NULL;
    assert_int_equal(spn_web_parse(buf.data, buf.size, "memory", &back), SPN_OK);
    assert_same_world(w, back);
    assert_true(spn_world_spring(back, 4).broken && spn_world_spring(back, 7).broken);
    assert_false(spn_world_spring(back, 5).broken);

    /* The same through a file, and a second save writes the same text. */
    char dir[] = "/tmp/spn-io-XXXXXX", path[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/web.json", dir);
    assert_int_equal(spn_web_save(back, path), SPN_OK);
    spn_world *again = NULL;
    assert_int_equal(spn_web_load(path, &again), SPN_OK);
    assert_same_world(w, again);
    spn_buffer buf2 = {0};
    sink = spn_sink_buffer(&buf2);
    assert_int_equal(spn_web_write(again, &sink), SPN_OK);
    assert_string_equal(buf.data, buf2.data);
    remove(path);
    rmdir(dir);
    spn_buffer_free(&buf);
    spn_buffer_free(&buf2);
    spn_world_destroy(w);
    spn_world_destroy(back);
    spn_world_destroy(again);
}

/* Files in `dir` other than . and .. */
static int count_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));) n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    if (d) closedir(d);
    return n;
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
    spn_world_set_position(w, 9, spn_v3(0, NAN, 0));
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

/* Inputs the fuzzers found (and hand-made cousins): every reader, given the
 * bytes in an exact-size heap buffer (no NUL after them, as the fuzzers and
 * library users pass them), refuses each file with the expected message —
 * and, run under ASan, without reading past the buffer or asking for
 * gigabytes. Also the library's particle limit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

typedef struct hostile_case {
    const char *file;     /* in tests/data/bad/ */
    const char *message;  /* a fragment the refusal must contain */
} hostile_case;

static const hostile_case cases[] = {
    {"hostile_ply_no_newline.ply", "repeats a vertex"}, /* read past its end (strspn) before */
    {"hostile_ply_huge_count.ply", "more than its"},
    {"hostile_ply_two_vertex_elements.ply", "more than one 'vertex' element"},
    {"hostile_ply_empty_element_loop.ply", "declares 1000000000 items"}, /* a minute of looping before */
    {"hostile_ply_huge_faces.ply", "more than its"},
    {"hostile_pov_huge_count.pov", "more than the rest of the file"},
    {"hostile_pov_huge_faces.pov", "more than the rest of the file"},
    {"hostile_pov_pins_twice.pov", "given twice"},
    {"hostile_pov_vectors_twice.pov", "given twice"},
};

static char *slurp(const char *name, size_t *size)
{
    char path[512];
    snprintf(path, sizeof path, "%s/bad/%s", SPN_TEST_DATA, name);
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    char *data = malloc(n > 0 ? (size_t)n : 1);
    assert_int_equal(fread(data, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    *size = (size_t)n;
    return data;
}

static spn_status parse(const char *name, const char *data, size_t size)
{
    const char *ext = strrchr(name, '.');
    if (strcmp(ext, ".ply") == 0 || strcmp(ext, ".obj") == 0) {
        spn_mesh m;
        spn_status st = ext[1] == 'p' ? spn_mesh_parse_ply(data, size, "fuzz", &m)
                                      : spn_mesh_parse_obj(data, size, "fuzz", &m);
        if (st == SPN_OK) spn_mesh_free(&m);
        return st;
    }
    if (strcmp(ext, ".pov") == 0) {
        spn_pov_scene *p = NULL;
        spn_status st = spn_pov_scene_parse(data, size, "fuzz", &p);
        spn_pov_scene_destroy(p);
        return st;
    }
    spn_world *w = NULL;
    spn_status st = spn_web_parse(data, size, "fuzz", &w);
    spn_world_destroy(w);
    return st;
}

static void test_found_inputs_refused(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t size;
        char *data = slurp(cases[i].file, &size);
        spn_status st = parse(cases[i].file, data, size);
        free(data);
        if (st == SPN_OK || !strstr(spn_last_error(), cases[i].message))
            fail_msg("%s: status %s, message '%s', expected one containing '%s'", cases[i].file,
                     spn_status_name(st), spn_last_error(), cases[i].message);
    }
}

static void test_particle_limit(void **state)
{
    (void)state;
    spn_set_max_particles(10);
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    for (int i = 0; i < 10; i++) assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_ERR_NOMEM);
    assert_non_null(strstr(spn_last_error(), "limit of 10"));
    assert_int_equal(spn_world_particle_count(w), 10);
    spn_world_destroy(w);
    /* An orb web of 3 x 5 has 16 particles: refused by the builder too. */
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 3;
    od.radials = 5;
    assert_int_not_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    spn_set_max_particles(0); /* the default again */
    assert_int_equal(spn_max_particles(), SPN_DEFAULT_MAX_PARTICLES);
    assert_int_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_found_inputs_refused),
        cmocka_unit_test(test_particle_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

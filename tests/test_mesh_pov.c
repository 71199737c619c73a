/* The film maker's scenes: declarations read from mesh2 objects, the scene
 * written back unchanged apart from number formatting when nothing moved,
 * only vertex numbers changed when something did, and malformed scenes in
 * tests/data/bad/ refused with the line named; frame folders rendered by
 * several povray processes at once, each frame its own picture, the first
 * frame that fails named. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cairo.h>
#include <spinneret/spinneret.h>

static const char scene[] =
    "// a test scene\n#version 3.7;\ncamera { location <0, 1.50, -3> look_at <0,0,0> }\n"
    "light_source { <2, 4, -3> color rgb 1 } /* a /* nested */ comment */\n"
    "#declare Floor = mesh2 { #local spring_system_fixed = true;\n"
    "  vertex_vectors { 3, <-1,0,-1>, <1, 0, -1>, <0, 0, 1.0> }\n"
    "  face_indices { 1, <0, 2, 1> }\n  pigment { color rgb 0.5 } }\n"
    "#declare Cloth = mesh2 {\n"
    "  #local spring_system_ks = 600;\n  #local spring_system_kb = 60;\n  #local spring_system_ds = 2;\n"
    "  #local spring_system_db = 0.5;\n  #local spring_system_mass = 3;\n  #local spring_system_vicinity = 0.1;\n"
    "  #local spring_system_fixed_vertices = array[1] {3};\n  #local spring_system_fixed = false;\n"
    "  vertex_vectors { 4,\n    <0.00, 1.50, 0>, < 1e-1 , 1.5, 0>,\n    <-.5, +1.5, 0.5>, <0.25, 1.5E0, 0.5> }\n"
    "  normal_vectors { 1, <0, 1, 0> }\n"
    "  face_indices { 2, <0, 1, 2>, 0, <1, 3, 2> }\n  texture { pigment { color rgb <1, 0, 0> } } }\n"
    "object { Floor } object { Cloth }\n";

/* Equal text, with numbers compared by value. */
static bool same_but_numbers(const char *a, const char *b)
{
    while (*a && *b) {
        bool na = isdigit((unsigned char)*a) || ((*a == '-' || *a == '+' || *a == '.') && (isdigit((unsigned char)a[1]) || a[1] == '.'));
        bool nb = isdigit((unsigned char)*b) || ((*b == '-' || *b == '+' || *b == '.') && (isdigit((unsigned char)b[1]) || b[1] == '.'));
        if (na && nb) {
            char *ea, *eb;
            double x = strtod(a, &ea), y = strtod(b, &eb);
            if (fabs(x - y) > 1e-9 * fmax(1, fabs(x))) return false;
            a = ea;
            b = eb;
        } else if (*a++ != *b++) {
            return false;
        }
    }
    return *a == *b;
}

static char *write_scene(const spn_pov_scene *p, const spn_vec3 *const *v)
{
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(spn_pov_scene_write(p, v, &sink), SPN_OK);
    assert_int_equal(sink.write(sink.ctx, "", 1), SPN_OK);
    return buf.data;
}

static void test_declarations(void **state)
{
    (void)state;
    spn_pov_scene *p;
    assert_int_equal(spn_pov_scene_parse(scene, strlen(scene), "t.pov", &p), SPN_OK);
    assert_int_equal(spn_pov_scene_object_count(p), 2);
    spn_mesh_spring_def f = spn_pov_scene_spring_def(p, 0), c = spn_pov_scene_spring_def(p, 1);
    assert_true(f.fixed);
    assert_false(c.fixed);
    assert_true(c.stretch_k == 600 && c.bend_k == 60 && c.stretch_kd == 2 && c.bend_kd == 0.5);
    assert_true(c.total_mass == 3 && c.vicinity == 0.1);
    assert_true(c.fixed_vertices[3] && !c.fixed_vertices[0]);
    const spn_mesh *m = spn_pov_scene_mesh(p, 1);
    assert_int_equal(m->vertex_count, 4);
    assert_int_equal(m->triangle_count, 2);
    assert_true(m->vertices[1].x == 0.1 && m->vertices[2].x == -0.5 && m->vertices[3].y == 1.5);
    assert_int_equal(m->triangles[3], 1);
    assert_int_equal(spn_pov_scene_object_line(p, 1), 9);
    spn_pov_scene_destroy(p);
}

static void test_round_trip(void **state)
{
    (void)state;
    spn_pov_scene *p;
    assert_int_equal(spn_pov_scene_parse(scene, strlen(scene), "t.pov", &p), SPN_OK);
    const spn_vec3 *same[2] = {NULL, spn_pov_scene_mesh(p, 1)->vertices};
    char *out = write_scene(p, same);
    assert_true(same_but_numbers(scene, out));
    assert_string_not_equal(scene, out); /* "0.00" became "0": only the formatting differs */
    free(out);
    spn_vec3 moved[4];
    for (int i = 0; i < 4; i++) moved[i] = spn_v3_add(same[1][i], spn_v3(0, -1.25, 0));
    const spn_vec3 *now[2] = {NULL, moved};
    out = write_scene(p, now);
    assert_false(same_but_numbers(scene, out));
    spn_pov_scene *q;
    assert_int_equal(spn_pov_scene_parse(out, strlen(out), "out.pov", &q), SPN_OK);
    for (int i = 0; i < 4; i++) assert_true(spn_v3_len(spn_v3_sub(spn_pov_scene_mesh(q, 1)->vertices[i], moved[i])) < 1e-12);
    assert_memory_equal(spn_pov_scene_mesh(q, 0)->vertices, spn_pov_scene_mesh(p, 0)->vertices, 3 * sizeof(spn_vec3));
    /* Everything before the cloth's vertices is untouched, byte for byte. */
    size_t head = (size_t)(strstr(scene, "<0.00, 1.50") - scene);
    assert_memory_equal(scene, out, head);
    assert_non_null(strstr(out, "normal_vectors { 1, <0, 1, 0> }"));
    free(out);
    spn_pov_scene_destroy(q);
    spn_pov_scene_destroy(p);
}

static void test_bad_scenes_name_the_line(void **state)
{
    (void)state;
    static const struct { const char *file, *where; } cases[] = {
        {"pov_missing_brace.pov", ":3:"}, {"pov_include.pov", ":2:"}, {"pov_nan.pov", ":5:"},
        {"pov_bad_face.pov", ":5:"},      {"pov_quad.pov", ":5:"},    {"pov_sphere_simulated.pov", ":3:"},
        {"pov_missing_mark.pov", ":2:"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/bad/%s", SPN_TEST_DATA, cases[i].file);
        spn_pov_scene *p = (spn_pov_scene *)1;
        assert_int_equal(spn_pov_scene_load(path, &p), SPN_ERR_FORMAT);
        assert_null(p);
        const char *msg = spn_last_error();
        if (!strstr(msg, cases[i].file) || !strstr(msg, cases[i].where)) fail_msg("%s: message '%s'", cases[i].file, msg);
    }
    const char *unclosed = "#version 3.7;\nbox { <0,0,0>, <1,1,1>\n";
    spn_pov_scene *p;
    assert_int_equal(spn_pov_scene_parse(unclosed, strlen(unclosed), "u.pov", &p), SPN_ERR_FORMAT);
    assert_non_null(strstr(spn_last_error(), "u.pov:2:"));
    const char *extra = "#version 3.7;\n}\n";
    assert_int_equal(spn_pov_scene_parse(extra, strlen(extra), "e.pov", &p), SPN_ERR_FORMAT);
    assert_non_null(strstr(spn_last_error(), "e.pov:2:"));
}

/* Frame i: nothing but a background of linear red i/8 (or a syntax error). */
static void write_frame(const char *dir, int i, bool broken)
{
    char path[600];
    snprintf(path, sizeof path, "%s/frame_%05d.pov", dir, i);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fprintf(fp, broken ? "#version 3.7;\nbackground { color rgb <\n" : "#version 3.7;\nbackground { color rgb <%g, 0, 1> }\n",
            i / 8.0);
    fclose(fp);
}

static void test_render_frames_at_once(void **state)
{
    (void)state;
    if (!spn_program_available("povray")) {
        printf("skipped: povray is not installed\n");
        skip();
    }
    char dir[512], cmd[600];
    snprintf(dir, sizeof dir, "%s/pov_frames_XXXXXX", SPN_BUILD_DIR);
    assert_non_null(mkdtemp(dir));
    enum { N = 9 };
    for (int i = 0; i < N; i++) write_frame(dir, i, i == 4 || i == 6);
    assert_int_equal(spn_pov_render_frames(dir, N, 16, 12, 10, NULL), SPN_ERR_IO);
    assert_non_null(strstr(spn_last_error(), "frame_00004.pov: povray failed"));
    write_frame(dir, 4, false);
    write_frame(dir, 6, false);
    assert_int_equal(spn_pov_render_frames(dir, N, 16, 12, 10, NULL), SPN_OK);
    for (int i = 0; i < N; i++) {
        char path[600];
        snprintf(path, sizeof path, "%s/frame_%05d.png", dir, i);
        cairo_surface_t *png = cairo_image_surface_create_from_png(path);
        assert_int_equal(cairo_surface_status(png), CAIRO_STATUS_SUCCESS);
        uint32_t v = *(const uint32_t *)(const void *)cairo_image_surface_get_data(png);
        /* povray writes sRGB: the scene's linear i/8 encoded */
        double c = i / 8.0, srgb = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1 / 2.4) - 0.055;
        int red = (int)((v >> 16) & 255), want = (int)lround(255 * srgb);
        if (abs(red - want) > 2) fail_msg("frame %d: red %d, expected %d (its own scene's)", i, red, want);
        cairo_surface_destroy(png);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_declarations),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_bad_scenes_name_the_line),
        cmocka_unit_test(test_render_frames_at_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

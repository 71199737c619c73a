/* Mesh readers: OBJ (index forms, negative indices, groups), PLY in its three
 * encodings giving the same mesh, other formats through assimp, and every
 * malformed file in tests/data/bad/ refused with its line named. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

static void test_obj_forms(void **state)
{
    (void)state;
    const char *text = "# tetra\nv 0 0 0\nv 1 0 0 1.0\nv 0 1 0\r\nvn 0 0 1\nvt 0 0\ng side\n"
                       "f 1/1/1 2//1 3\no top\nv 0 0 1\nf -4 -3 -1\nusemtl x\ns off\n";
    spn_mesh m;
    assert_int_equal(spn_mesh_parse_obj(text, strlen(text), "t.obj", &m), SPN_OK);
    assert_int_equal(m.vertex_count, 4);
    assert_int_equal(m.triangle_count, 2);
    assert_int_equal(m.triangles[3], 0);
    assert_int_equal(m.triangles[4], 1);
    assert_int_equal(m.triangles[5], 3);
    assert_int_equal(spn_mesh_group(&m, "side"), m.triangle_group[0]);
    assert_int_equal(spn_mesh_group(&m, "top"), m.triangle_group[1]);
    assert_true(m.vertices[3].z == 1);
    spn_mesh_free(&m);
}

static const char ply_header[] = "ply\nformat %s 1.0\ncomment test\nelement vertex 4\nproperty float x\n"
                                 "property float y\nproperty float z\nproperty uchar red\nelement face 2\n"
                                 "property list uchar int vertex_indices\nend_header\n";

static void put(char **p, const void *v, int size, bool big)
{
    for (int i = 0; i < size; i++) *(*p)++ = ((const char *)v)[big ? size - 1 - i : i];
}

/* The same square in binary little or big endian (the host is little endian). */
static size_t binary_ply(char *buf, bool big)
{
    char *p = buf + sprintf(buf, ply_header, big ? "binary_big_endian" : "binary_little_endian");
    const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 3; k++) put(&p, &v[i][k], 4, big);
        *p++ = 7;
    }
    const int32_t f[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int i = 0; i < 2; i++) {
        *p++ = 3;
        for (int k = 0; k < 3; k++) put(&p, &f[i][k], 4, big);
    }
    return (size_t)(p - buf);
}

static void test_ply_encodings_agree(void **state)
{
    (void)state;
    char ascii[1024], bin[1024];
    int n = sprintf(ascii, ply_header, "ascii");
    n += sprintf(ascii + n, "0 0 0 7\n1 0 0 7\n1 1 0 7\n0 1 0 7\n3 0 1 2\n3 0 2 3\n");
    spn_mesh a, b;
    assert_int_equal(spn_mesh_parse_ply(ascii, (size_t)n, "a.ply", &a), SPN_OK);
    for (int big = 0; big < 2; big++) {
        size_t size = binary_ply(bin, big);
        assert_int_equal(spn_mesh_parse_ply(bin, size, "b.ply", &b), SPN_OK);
        assert_int_equal(b.vertex_count, 4);
        assert_int_equal(b.triangle_count, 2);
        assert_memory_equal(a.vertices, b.vertices, 4 * sizeof *a.vertices);
        assert_memory_equal(a.triangles, b.triangles, 6 * sizeof *a.triangles);
        spn_mesh_free(&b);
        assert_int_equal(spn_mesh_parse_ply(bin, size - 3, "short.ply", &b), SPN_ERR_FORMAT);
        assert_non_null(strstr(spn_last_error(), "face 1"));
    }
    spn_mesh_free(&a);
}

static void test_assimp_formats(void **state)
{
    (void)state;
    spn_mesh m;
    spn_status st = spn_mesh_load(SPN_TEST_DATA "/mesh/tetra.stl", &m);
    if (st == SPN_ERR_UNSUPPORTED) {
        printf("skipped: built without assimp (%s)\n", spn_last_error());
        return;
    }
    assert_int_equal(st, SPN_OK);
    assert_int_equal(m.triangle_count, 4);
    assert_int_equal(m.vertex_count, 4); /* identical vertices joined: edges are shared */
    spn_world *w = spn_world_create(NULL);
    spn_mesh_stats ms;
    assert_int_equal(spn_mesh_add_to_world(w, &m, NULL, &ms), SPN_OK);
    assert_int_equal(ms.edges, 6);
    spn_world_destroy(w);
    spn_mesh_free(&m);
}

static void test_bad_files_name_the_line(void **state)
{
    (void)state;
    static const struct { const char *file, *where; } cases[] = {
        {"mesh_bad_index.obj", "mesh_bad_index.obj:4:"},   {"mesh_nan.obj", "mesh_nan.obj:2:"},
        {"mesh_quad.obj", "mesh_quad.obj:6:"},             {"mesh_missing_coord.obj", "mesh_missing_coord.obj:2:"},
        {"mesh_missing_data.ply", "mesh_missing_data.ply:11:"}, {"mesh_bad_index.ply", "mesh_bad_index.ply:13:"},
        {"mesh_quad.ply", "mesh_quad.ply:14:"},            {"mesh_inf.ply", "mesh_inf.ply:11:"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/bad/%s", SPN_TEST_DATA, cases[i].file);
        spn_mesh m;
        assert_int_equal(spn_mesh_load(path, &m), SPN_ERR_FORMAT);
        if (!strstr(spn_last_error(), cases[i].where)) fail_msg("%s: message '%s'", cases[i].file, spn_last_error());
        assert_int_equal(m.vertex_count, 0);
        assert_null(m.vertices);
    }
    spn_mesh m;
    assert_int_equal(spn_mesh_load(SPN_TEST_DATA "/bad/no-such-file.obj", &m), SPN_ERR_IO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_forms),
        cmocka_unit_test(test_ply_encodings_agree),
        cmocka_unit_test(test_assimp_formats),
        cmocka_unit_test(test_bad_files_name_the_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

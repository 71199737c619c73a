/* The mesh factory's counts on meshes small enough to count by hand: a
 * tetrahedron and a 2x2 grid of squares; vicinity springs against a brute
 * force count on the shipped sphere; masses spread by area; fixed vertices. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

static spn_mesh make_mesh(const spn_vec3 *v, uint32_t nv, const uint32_t *t, uint32_t nt)
{
    spn_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = nv;
    m.triangle_count = nt;
    m.vertices = malloc(nv * sizeof *v);
    m.triangles = malloc(3 * nt * sizeof *t);
    memcpy(m.vertices, v, nv * sizeof *v);
    memcpy(m.triangles, t, 3 * nt * sizeof *t);
    return m;
}

static spn_mesh tetrahedron(void)
{
    const spn_vec3 v[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const uint32_t t[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return make_mesh(v, 4, t, 4);
}

/* 3x3 vertices 1 m apart; every square split along the diagonal (i,j)-(i+1,j+1). */
static spn_mesh grid2x2(void)
{
    spn_vec3 v[9];
    uint32_t t[24], n = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) v[j * 3 + i] = spn_v3(i, 0, j);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            uint32_t a = j * 3 + i, b = a + 1, c = a + 3, d = a + 4;
            uint32_t tri[6] = {a, b, d, a, d, c};
            memcpy(t + n, tri, sizeof tri);
            n += 6;
        }
    return make_mesh(v, 9, t, 8);
}

static spn_mesh_stats build(const spn_mesh *m, double vicinity, spn_world **out)
{
    spn_world *w = spn_world_create(NULL);
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.vicinity = vicinity;
    spn_mesh_stats st;
    assert_int_equal(spn_mesh_add_to_world(w, m, &d, &st), SPN_OK);
    assert_int_equal(spn_world_spring_count(w), st.edges + st.bend + st.vicinity);
    if (out) *out = w;
    else spn_world_destroy(w);
    return st;
}

static void test_tetrahedron(void **state)
{
    (void)state;
    spn_mesh m = tetrahedron();
    spn_mesh_stats st = build(&m, 10, NULL);
    assert_int_equal(st.particles, 4);
    assert_int_equal(st.edges, 6);
    assert_int_equal(st.bend_pairs, 6); /* every edge joins two faces */
    assert_int_equal(st.bend, 0);       /* ... whose opposite vertices are already an edge */
    assert_int_equal(st.vicinity, 0);   /* every pair is joined already */
    spn_mesh_free(&m);
}

static void test_grid_counts(void **state)
{
    (void)state;
    spn_mesh m = grid2x2();
    spn_world *w;
    spn_mesh_stats st = build(&m, 0, &w);
    assert_int_equal(st.edges, 16);     /* 12 sides + 4 diagonals */
    assert_int_equal(st.bend_pairs, 8); /* 4 diagonals + 4 inner sides */
    assert_int_equal(st.bend, 8);
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info sp = spn_world_spring(w, s);
        double expect = sp.tag == SPN_THREAD_STRETCH ? 1 : sqrt(2);
        if (sp.tag == SPN_THREAD_STRETCH && sp.rest > 1.1) expect = sqrt(2);
        if (sp.tag == SPN_THREAD_BEND && sp.rest > 1.5) expect = sqrt(5); /* across an inner side */
        assert_true(fabs(sp.rest - expect) < 1e-12);
        assert_true(sp.tag == SPN_THREAD_STRETCH || sp.tag == SPN_THREAD_BEND);
    }
    spn_world_destroy(w);
    assert_int_equal(build(&m, 1.5, NULL).vicinity, 0);  /* 1 and sqrt 2 apart: all joined */
    assert_int_equal(build(&m, 2.1, NULL).vicinity, 6);  /* + the 6 pairs 2 apart */
    assert_int_equal(build(&m, 2.3, NULL).vicinity, 10); /* + 8 pairs sqrt 5 apart, 4 of them bends */
    spn_mesh_free(&m);
}

static void test_vicinity_matches_brute_force(void **state)
{
    (void)state;
    spn_mesh m;
    assert_int_equal(spn_mesh_load(SPN_SOURCE_DIR "/assets/models/sphere.obj", &m), SPN_OK);
    const double r = 0.13;
    spn_world *w;
    spn_mesh_stats st = build(&m, r, &w);
    uint32_t near = 0, joined_near = 0;
    for (uint32_t i = 0; i < m.vertex_count; i++)
        for (uint32_t j = i + 1; j < m.vertex_count; j++)
            near += spn_v3_len(spn_v3_sub(m.vertices[i], m.vertices[j])) < r;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info sp = spn_world_spring(w, s);
        if (sp.tag != SPN_THREAD_VICINITY && sp.rest < r) joined_near++;
        if (sp.tag == SPN_THREAD_VICINITY) assert_true(sp.rest < r);
    }
    assert_true(st.vicinity > 0);
    assert_int_equal(st.vicinity + joined_near, near);
    spn_world_destroy(w);
    spn_mesh_free(&m);
}

static void test_area_mass_and_fixed(void **state)
{
    (void)state;
    spn_mesh m = grid2x2();
    spn_world *w = spn_world_create(NULL);
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.total_mass = 2.0;
    bool fixed[9] = {[0] = true, [2] = true};
    d.fixed_vertices = fixed;
    spn_mesh_stats st;
    assert_int_equal(spn_mesh_add_to_world(w, &m, &d, &st), SPN_OK);
    assert_int_equal(st.fixed, 2);
    double sum = 0;
    for (uint32_t i = 0; i < 9; i++) sum += spn_world_mass(w, i);
    assert_true(fabs(sum - 2.0) < 1e-12);
    /* Area 4 m^2: the centre touches 6 triangles (3 m^2 / 3), corner 0 one (0.5 / 3). */
    assert_true(fabs(spn_world_mass(w, 4) - 2.0 * 1.0 / 4) < 1e-12);
    assert_true(fabs(spn_world_mass(w, 2) - 2.0 * (0.5 / 3) / 4) < 1e-12);
    assert_true(spn_world_is_fixed(w, 0) && spn_world_is_fixed(w, 2) && !spn_world_is_fixed(w, 1));
    spn_world_destroy(w);
    spn_mesh_free(&m);
}

static void test_fixed_group_and_bad_defs(void **state)
{
    (void)state;
    spn_mesh m;
    assert_int_equal(spn_mesh_load(SPN_SOURCE_DIR "/assets/models/cloth.obj", &m), SPN_OK);
    spn_world *w = spn_world_create(NULL);
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.fixed_group = "corners2";
    spn_mesh_stats st;
    assert_int_equal(spn_mesh_add_to_world(w, &m, &d, &st), SPN_OK);
    assert_int_equal(st.fixed, 6); /* the two corner triangles */
    assert_true(spn_world_is_fixed(w, 0) && spn_world_is_fixed(w, 20));
    d.fixed_group = "no-such-group";
    assert_int_equal(spn_mesh_add_to_world(w, &m, &d, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "no-such-group"));
    d = spn_mesh_spring_def_default();
    d.bend_k = -1;
    assert_int_equal(spn_mesh_add_to_world(w, &m, &d, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "bend_k"));
    spn_world_destroy(w);
    spn_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tetrahedron),
        cmocka_unit_test(test_grid_counts),
        cmocka_unit_test(test_vicinity_matches_brute_force),
        cmocka_unit_test(test_area_mass_and_fixed),
        cmocka_unit_test(test_fixed_group_and_bad_defs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

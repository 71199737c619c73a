/* Mesh objects in motion: a cloth pinned at two corners settles and hangs
 * below them; a spring sphere dropped on the floor bounces and comes to rest
 * on it, never below; a cloth thrown at a table faster than the table's
 * thickness per sub-step does not pass through (swept contacts); a free cloth
 * lands on a free, pinned one (collisions between free objects). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

/* n x n vertices, side `size`, centred on (cx, y, cz) in the x-z plane. */
static spn_mesh cloth(int n, double size, double cx, double y, double cz)
{
    spn_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = (uint32_t)(n * n);
    m.triangle_count = (uint32_t)(2 * (n - 1) * (n - 1));
    m.vertices = malloc(m.vertex_count * sizeof *m.vertices);
    m.triangles = malloc(3 * m.triangle_count * sizeof *m.triangles);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            m.vertices[j * n + i] = spn_v3(cx - size / 2 + size * i / (n - 1), y, cz - size / 2 + size * j / (n - 1));
    uint32_t *t = m.triangles;
    for (int j = 0; j < n - 1; j++)
        for (int i = 0; i < n - 1; i++) {
            uint32_t a = (uint32_t)(j * n + i), b = a + 1, c = a + (uint32_t)n, d = c + 1;
            uint32_t q[6] = {a, c, d, a, d, b};
            memcpy(t, q, sizeof q);
            t += 6;
        }
    return m;
}

static spn_mesh_spring_def soft_cloth(double mass)
{
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.total_mass = mass;
    d.stretch_k = 200;
    d.stretch_kd = 0.05;
    d.bend_k = 2;
    d.bend_kd = 0.005;
    return d;
}

static void test_cloth_hangs_from_two_corners(void **state)
{
    (void)state;
    spn_mesh_scene_def sd = spn_mesh_scene_def_default();
    sd.world.drag = 1.0; /* air, so that it comes to rest within the test */
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(&sd, &s), SPN_OK);
    const int n = 11;
    spn_mesh m = cloth(n, 0.5, 0, 1.0, 0);
    bool pins[121] = {[0] = true, [10] = true};
    spn_mesh_spring_def d = soft_cloth(0.1);
    d.fixed_vertices = pins;
    assert_int_equal(spn_mesh_scene_add(s, &m, &d, NULL), SPN_OK);
    assert_int_equal(spn_mesh_scene_advance(s, 10.0), SPN_OK);
    spn_world *w = spn_mesh_scene_world(s);
    printf("kinetic %g\n", spn_mesh_scene_kinetic(s));
    assert_true(spn_mesh_scene_kinetic(s) < 1e-4); /* from about 0.1 J while falling */
    assert_true(spn_v3_len(spn_v3_sub(spn_world_position(w, 0), m.vertices[0])) == 0);
    double far_y = 0, far_z = 0;
    for (int i = 0; i < n; i++) {
        spn_vec3 p = spn_world_position(w, (uint32_t)((n - 1) * n + i));
        far_y += p.y / n;
        far_z += p.z / n;
    }
    /* The far edge hangs one cloth length (0.5 m, a little more for stretch) under the pins' edge. */
    printf("far edge y %g z %g\n", far_y, far_z);
    assert_true(far_y < 1.0 - 0.45 && far_y > 1.0 - 0.6);
    assert_true(fabs(far_z - (-0.25)) < 0.05);
    for (uint32_t i = 0; i < m.vertex_count; i++) assert_true(spn_world_position(w, i).y <= 1.0 + 1e-9);
    spn_mesh_free(&m);
    spn_mesh_scene_destroy(s);
}

/* The floor is the world's plane, or a fixed mesh of two triangles. */
static void sphere_on_floor(bool mesh_floor)
{
    spn_mesh_scene_def sd = spn_mesh_scene_def_default();
    sd.ground = !mesh_floor;
    sd.ground_restitution = sd.restitution = 0.5;
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(&sd, &s), SPN_OK);
    spn_mesh m, floor = cloth(2, 6.0, 0, 0, 0);
    assert_int_equal(spn_mesh_load(SPN_SOURCE_DIR "/assets/models/sphere.obj", &m), SPN_OK);
    spn_mesh_spring_def d = spn_mesh_spring_def_default(), fixed = spn_mesh_spring_def_default();
    d.vicinity = 0.3; /* the documentation's example values */
    fixed.fixed = true;
    assert_int_equal(spn_mesh_scene_add(s, &m, &d, NULL), SPN_OK);
    if (mesh_floor) assert_int_equal(spn_mesh_scene_add(s, &floor, &fixed, NULL), SPN_OK);
    spn_world *w = spn_mesh_scene_world(s);
    double lowest = INFINITY, first_contact = -1, rise = 0, min_after = INFINITY, cy = 0;
    for (int f = 0; f < 450; f++) {
        assert_int_equal(spn_mesh_scene_advance(s, 0.01), SPN_OK);
        double low = INFINITY;
        cy = 0;
        for (uint32_t i = 0; i < m.vertex_count; i++) {
            low = fmin(low, spn_world_position(w, i).y);
            cy += spn_world_position(w, i).y / m.vertex_count;
        }
        lowest = fmin(lowest, low);
        if (first_contact < 0 && low < sd.skin + 1e-3) first_contact = f;
        if (first_contact >= 0) {
            min_after = fmin(min_after, cy);
            rise = fmax(rise, cy - min_after);
        }
    }
    assert_true(first_contact > 0);
    assert_true(lowest >= -1e-9); /* never below the floor */
    if (mesh_floor) assert_true(spn_mesh_scene_contacts(s) > 0);
    assert_true(rise > 0.05);     /* it bounced */
    assert_true(spn_mesh_scene_kinetic(s) < 0.01);
    assert_true(cy > 0.15 && cy < 0.21); /* resting on the floor (radius 0.2), a little squashed */
    spn_mesh_free(&m);
    spn_mesh_free(&floor);
    spn_mesh_scene_destroy(s);
}

static void test_sphere_bounces_and_rests_on_floor(void **state)
{
    (void)state;
    sphere_on_floor(false);
}

static void test_sphere_bounces_and_rests_on_mesh_floor(void **state)
{
    (void)state;
    sphere_on_floor(true);
}

/* A small triangle on a 30 degree slope: without friction it slides (a = g sin 30
 * over 0.3 s is 0.22 m), with full friction the contact keeps it in place. */
static double slide(double friction)
{
    spn_mesh_scene_def sd = spn_mesh_scene_def_default();
    sd.friction = friction;
    sd.restitution = 0;
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(&sd, &s), SPN_OK);
    const double c = cos(SPN_PI / 6), sn = sin(SPN_PI / 6);
    spn_mesh slope = cloth(2, 4.0, 0, 0, 0), chip = cloth(2, 0.05, 0, 1.2 * sd.skin, 0);
    for (uint32_t i = 0; i < 4; i++) { /* tilt both about z: downhill is -x */
        spn_vec3 *v = &slope.vertices[i], *w = &chip.vertices[i];
        *v = spn_v3(v->x * c, v->x * sn, v->z);
        *w = spn_v3(w->x * c - w->y * sn, w->x * sn + w->y * c, w->z);
    }
    spn_mesh_spring_def fixed = spn_mesh_spring_def_default(), d = soft_cloth(0.01);
    fixed.fixed = true;
    uint32_t obj;
    assert_int_equal(spn_mesh_scene_add(s, &slope, &fixed, NULL), SPN_OK);
    assert_int_equal(spn_mesh_scene_add(s, &chip, &d, &obj), SPN_OK);
    uint32_t first = spn_mesh_scene_object_stats(s, obj)->first_particle;
    spn_vec3 start = spn_world_position(spn_mesh_scene_world(s), first);
    assert_int_equal(spn_mesh_scene_advance(s, 0.3), SPN_OK);
    spn_vec3 dx = spn_v3_sub(spn_world_position(spn_mesh_scene_world(s), first), start), n = spn_v3(-sn, c, 0);
    double moved = spn_v3_len(spn_v3_sub(dx, spn_v3_scale(n, spn_v3_dot(n, dx)))); /* along the slope */
    spn_mesh_free(&slope);
    spn_mesh_free(&chip);
    spn_mesh_scene_destroy(s);
    return moved;
}

static void test_friction_on_a_slope(void **state)
{
    (void)state;
    double free_slide = slide(0), stuck = slide(1);
    printf("slid %g m without friction, %g m with full friction\n", free_slide, stuck);
    assert_true(fabs(free_slide - 0.5 * 9.81 * 0.5 * 0.09) < 0.03);
    assert_true(stuck < 0.005);
}

static void test_fast_cloth_does_not_tunnel_through_table(void **state)
{
    (void)state;
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(NULL, &s), SPN_OK);
    spn_mesh table, m = cloth(9, 0.5, 0, 0.85, 0);
    assert_int_equal(spn_mesh_load(SPN_SOURCE_DIR "/assets/models/table.obj", &table), SPN_OK);
    spn_mesh_spring_def fixed = spn_mesh_spring_def_default(), d = soft_cloth(0.2);
    fixed.fixed = true;
    d.stretch_k = 20;
    d.velocity = spn_v3(0, -100, 0);
    uint32_t obj;
    assert_int_equal(spn_mesh_scene_add(s, &table, &fixed, NULL), SPN_OK);
    assert_int_equal(spn_mesh_scene_add(s, &m, &d, &obj), SPN_OK);
    /* Each sub-step moves the cloth further than the 5 cm thick table top. */
    assert_true(100 * spn_mesh_scene_substep(s) > 0.05);
    spn_world *w = spn_mesh_scene_world(s);
    uint32_t first = spn_mesh_scene_object_stats(s, obj)->first_particle;
    for (int f = 0; f < 100; f++) {
        assert_int_equal(spn_mesh_scene_advance(s, 0.002), SPN_OK);
        for (uint32_t i = 0; i < m.vertex_count; i++) assert_true(spn_world_position(w, first + i).y >= 0.75);
    }
    assert_true(spn_mesh_scene_contacts(s) > 0);
    spn_mesh_free(&table);
    spn_mesh_free(&m);
    spn_mesh_scene_destroy(s);
}

/* The sub-step is 0.4 of the world's stable step, drag included: a scene
 * in thick air (drag 1e5 s^-1, a damping rate far above the cloth's
 * stiffness) steps shorter than the same scene in still air. (Until
 * 2026-12-05 the scene had its own copy of the bound, without the drag.) */
static double cloth_substep(double drag)
{
    spn_mesh_scene_def sd = spn_mesh_scene_def_default();
    sd.world.drag = drag;
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(&sd, &s), SPN_OK);
    spn_mesh m = cloth(9, 0.5, 0, 1, 0);
    spn_mesh_spring_def d = soft_cloth(0.2);
    assert_int_equal(spn_mesh_scene_add(s, &m, &d, NULL), SPN_OK);
    const double h = spn_mesh_scene_substep(s), stable = spn_world_stable_step(spn_mesh_scene_world(s), 0);
    assert_true(h == fmin(sd.max_substep, 0.4 * stable));
    spn_mesh_free(&m);
    spn_mesh_scene_destroy(s);
    return h;
}

static void test_substep_follows_stable_step(void **state)
{
    (void)state;
    const double still = cloth_substep(0), thick = cloth_substep(1e5);
    print_message("sub-step %g s in still air, %g s at drag 1e5\n", still, thick);
    assert_true(thick < 0.5 * still);
}

static void test_free_cloth_lands_on_free_cloth(void **state)
{
    (void)state;
    spn_mesh_scene_def sd = spn_mesh_scene_def_default();
    sd.world.drag = 0.5;
    spn_mesh_scene *s;
    assert_int_equal(spn_mesh_scene_create(&sd, &s), SPN_OK);
    const int n = 11;
    spn_mesh net = cloth(n, 1.0, 0, 0.5, 0), top = cloth(5, 0.3, 0.05, 0.8, 0.02);
    bool pins[121] = {[0] = true, [10] = true, [110] = true, [120] = true};
    spn_mesh_spring_def dn = soft_cloth(0.3), dt = soft_cloth(0.05);
    dn.fixed_vertices = pins;
    uint32_t a, b;
    assert_int_equal(spn_mesh_scene_add(s, &net, &dn, &a), SPN_OK);
    assert_int_equal(spn_mesh_scene_add(s, &top, &dt, &b), SPN_OK);
    assert_int_equal(spn_mesh_scene_advance(s, 1.5), SPN_OK);
    spn_world *w = spn_mesh_scene_world(s);
    uint32_t fa = spn_mesh_scene_object_stats(s, a)->first_particle, fb = spn_mesh_scene_object_stats(s, b)->first_particle;
    for (uint32_t i = 0; i < top.vertex_count; i++) {
        spn_vec3 p = spn_world_position(w, fb + i);
        double best = INFINITY, under = 0; /* the net's height at the nearest vertex across */
        for (uint32_t j = 0; j < net.vertex_count; j++) {
            spn_vec3 q = spn_world_position(w, fa + j);
            double dxz = hypot(p.x - q.x, p.z - q.z);
            if (dxz < best) best = dxz, under = q.y;
        }
        assert_true(p.y > under - 0.02);
    }
    assert_true(spn_mesh_scene_contacts(s) > 0);
    spn_mesh_free(&net);
    spn_mesh_free(&top);
    spn_mesh_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cloth_hangs_from_two_corners),
        cmocka_unit_test(test_substep_follows_stable_step),
        cmocka_unit_test(test_sphere_bounces_and_rests_on_floor),
        cmocka_unit_test(test_sphere_bounces_and_rests_on_mesh_floor),
        cmocka_unit_test(test_friction_on_a_slope),
        cmocka_unit_test(test_fast_cloth_does_not_tunnel_through_table),
        cmocka_unit_test(test_free_cloth_lands_on_free_cloth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

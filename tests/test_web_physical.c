/* Mehla's physical construction: structure, the settled web's tautness, and
 * the parameter tables of sec. 5.3.4-5.3.5 changing the web as the thesis says. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "web_checks.h"
#include <stdio.h>

static const spn_vec3 square[4] = {{-0.21, 0.22, 0}, {0.22, 0.2, 0}, {0.2, -0.22, 0}, {-0.22, -0.19, 0}};

static spn_world *build(double spoke_place, double spoke_rest, double frame_place, double frame_rest)
{
    spn_physical_def d = spn_physical_def_default();
    d.anchors = square;
    d.anchor_count = 4;
    d.move_outer = 0.03;
    d.spoke_placement = spoke_place;
    d.spoke_rest = spoke_rest;
    d.frame_placement = frame_place;
    d.frame_rest = frame_rest;
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_physical(&d, &w), SPN_OK);
    return w;
}

static void test_structure(void **state)
{
    (void)state;
    spn_world *w = build(0.007, 0.003, 0.020, 0.015);
    assert_true(web_all_anchored(w));
    assert_int_equal(web_crossings(w, SPN_THREAD_CAPTURE, SPN_THREAD_CAPTURE), 0);
    assert_int_equal(web_crossings(w, SPN_THREAD_CAPTURE, SPN_THREAD_RADIUS), 0);
    /* Outer frame: move_outer / outer_placement = 6 springs per anchor. */
    assert_int_equal(web_count(w, SPN_THREAD_ANCHOR), 4 * 6);
    uint32_t fixed = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) fixed += spn_world_is_fixed(w, i);
    assert_int_equal(fixed, 4);
    /* Stages in building order: every spring's order is its place. */
    uint32_t ns = spn_world_spring_count(w), last_stage = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        assert_int_equal(si.order, s);
        assert_true(si.stage >= last_stage);
        last_stage = si.stage;
        if (si.tag == SPN_THREAD_CAPTURE) assert_int_equal(si.stage, SPN_STAGE_CAPTURE);
        if (si.tag == SPN_THREAD_RADIUS) assert_int_equal(si.stage, SPN_STAGE_RADII);
        /* Over-extended: spokes laid at 7 mm with 3 mm rest (133%). */
        if (si.tag == SPN_THREAD_RADIUS) assert_true(si.length / si.rest > 1.7 && si.length / si.rest < 3.5);
    }
    spn_world_destroy(w);
}

/* Chains of radius springs between particles where they branch or end. */
static double worst_radius_bend(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    int *deg = calloc(np, sizeof *deg);
    uint32_t (*nb)[2] = calloc(np, sizeof *nb);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_RADIUS) continue;
        if (deg[si.a] < 2) nb[si.a][deg[si.a]] = si.b;
        if (deg[si.b] < 2) nb[si.b][deg[si.b]] = si.a;
        deg[si.a]++, deg[si.b]++;
    }
    double worst = 0;
    uint32_t *chain = malloc(np * sizeof *chain);
    for (uint32_t start = 0; start < np; start++) {
        if (deg[start] != 1) continue;
        uint32_t n = 0, prev = UINT32_MAX, cur = start;
        for (;;) {
            chain[n++] = cur;
            if (n > 1 && deg[cur] != 2) break;
            uint32_t next = nb[cur][0] == prev ? nb[cur][1] : nb[cur][0];
            prev = cur;
            cur = next;
        }
        spn_vec3 a = spn_world_position(w, chain[0]), b = spn_world_position(w, chain[n - 1]);
        spn_vec3 ab = spn_v3_sub(b, a);
        double len = spn_v3_len(ab);
        if (len < 0.05) continue;
        for (uint32_t k = 1; k + 1 < n; k++) {
            spn_vec3 ap = spn_v3_sub(spn_world_position(w, chain[k]), a);
            double off = spn_v3_len(spn_v3_cross(ap, ab)) / len;
            worst = fmax(worst, off / len);
        }
    }
    free(deg);
    free(nb);
    free(chain);
    return worst;
}

/* Area of the inner frame loop (frame springs form one cycle). */
static double frame_area(const spn_world *w, double *corner_area)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    uint32_t (*nb)[2] = calloc(np, sizeof *nb);
    int *deg = calloc(np, sizeof *deg);
    bool *corner = calloc(np, 1);
    uint32_t start = UINT32_MAX;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == SPN_THREAD_ANCHOR) corner[si.a] = corner[si.b] = true;
        if (si.tag != SPN_THREAD_FRAME) continue;
        nb[si.a][deg[si.a]++ % 2] = si.b;
        nb[si.b][deg[si.b]++ % 2] = si.a;
        start = si.a;
    }
    double area = 0, carea = 0;
    uint32_t prev = UINT32_MAX, cur = start, first_corner = UINT32_MAX, last_corner = UINT32_MAX;
    do {
        uint32_t next = nb[cur][0] == prev ? nb[cur][1] : nb[cur][0];
        spn_vec3 p = spn_world_position(w, cur), q = spn_world_position(w, next);
        area += p.x * q.y - q.x * p.y;
        if (corner[cur]) {
            if (last_corner != UINT32_MAX) {
                spn_vec3 c = spn_world_position(w, last_corner);
                carea += c.x * p.y - p.x * c.y;
            } else first_corner = cur;
            last_corner = cur;
        }
        prev = cur;
        cur = next;
    } while (cur != start);
    spn_vec3 c = spn_world_position(w, last_corner), f = spn_world_position(w, first_corner);
    carea += c.x * f.y - f.x * c.y;
    free(nb);
    free(deg);
    free(corner);
    *corner_area = fabs(carea) / 2;
    return fabs(area) / 2;
}

static void test_settles_taut(void **state)
{
    (void)state;
    spn_world *w = build(0.007, 0.003, 0.020, 0.015);
    spn_settle_report rep;
    assert_int_equal(spn_web_settle(w, 20, &rep), SPN_OK);
    double bend = worst_radius_bend(w);
    print_message("worst radius bend %.4f, settle %.3g s residual %.3g N\n", bend, rep.time, rep.residual);
    assert_true(bend < 0.02);
    double corners = 0, area = frame_area(w, &corners);
    assert_true(area < corners * 0.995); /* the frame bows inward */
    assert_int_equal(web_crossings(w, SPN_THREAD_CAPTURE, SPN_THREAD_CAPTURE), 0);
    spn_world_destroy(w);
}

/* Table 5.3.4: spoke placement 7, 9, 11, 15 mm (rest 3, 3, 5, 7): sparser spiral. */
static void test_spiral_table(void **state)
{
    (void)state;
    const double place[4] = {0.007, 0.009, 0.011, 0.015}, rest[4] = {0.003, 0.003, 0.005, 0.007};
    uint32_t prev = UINT32_MAX;
    for (int i = 0; i < 4; i++) {
        spn_world *w = build(place[i], rest[i], 0.020, 0.015);
        uint32_t n = web_count(w, SPN_THREAD_CAPTURE);
        assert_true(n < prev);
        prev = n;
        spn_world_destroy(w);
    }
}

/* Table 5.3.5: frame placement 20, 30, 40, 57 mm (rest 15, 25, 35, 50): fewer spokes. */
static void test_spoke_table(void **state)
{
    (void)state;
    const double place[4] = {0.020, 0.030, 0.040, 0.057}, rest[4] = {0.015, 0.025, 0.035, 0.050};
    int prev = 1 << 30;
    for (int i = 0; i < 4; i++) {
        spn_world *w = build(0.007, 0.003, place[i], rest[i]);
        spn_web_measures m;
        assert_int_equal(spn_web_measure(w, &m), SPN_OK);
        assert_true(m.radii < prev);
        assert_true(m.radii > 8);
        prev = m.radii;
        spn_world_destroy(w);
    }
}

static void test_same_seed_same_web(void **state)
{
    (void)state;
    spn_world *a = build(0.009, 0.003, 0.030, 0.025), *b = build(0.009, 0.003, 0.030, 0.025);
    assert_int_equal(spn_world_particle_count(a), spn_world_particle_count(b));
    assert_int_equal(spn_world_spring_count(a), spn_world_spring_count(b));
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++)
        assert_memory_equal(&spn_world_positions(a)[i], &spn_world_positions(b)[i], sizeof(spn_vec3));
    spn_world_destroy(a);
    spn_world_destroy(b);
}

/* The alternative the thesis compared: strands laid at rest, Provot limit on. */
static void test_provot_lays_at_rest(void **state)
{
    (void)state;
    spn_physical_def d = spn_physical_def_default();
    d.anchors = square;
    d.anchor_count = 4;
    d.move_outer = 0.03;
    d.provot = true;
    d.provot_max_strain = 0.05;
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_physical(&d, &w), SPN_OK);
    assert_true(fabs(spn_world_get_def(w)->provot_max_strain - 0.05) < 1e-12);
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        assert_true(fabs(si.length - si.rest) < 1e-9 * si.rest + 1e-12);
    }
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_structure),       cmocka_unit_test(test_settles_taut),
        cmocka_unit_test(test_spiral_table),    cmocka_unit_test(test_spoke_table),
        cmocka_unit_test(test_same_seed_same_web), cmocka_unit_test(test_provot_lays_at_rest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/* The thesis' wind (Mehla 2005, fig. 5.45) reproduces its own pseudo-code: the
 * forces the callback applies to a test world over 200 steps equal a direct,
 * independent evaluation of the figure (windgen called once per step of the
 * thesis' 0.02 s, the distance scaling from the centre mass). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

#define NP 5

typedef struct recorder {
    spn_thesis_wind *wind;
    spn_vec3 f[NP], x[NP];
    int calls;
} recorder;

static void record(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    recorder *r = user;
    spn_vec3 zero[NP];
    memset(zero, 0, sizeof zero);
    spn_thesis_wind_force(r->wind, w, t, x, v, zero);
    for (int i = 0; i < NP; i++) {
        r->f[i] = zero[i];
        r->x[i] = x[i];
        f[i] = spn_v3_add(f[i], zero[i]);
    }
    r->calls++;
}

/* Fig. 5.45, written out as the figure reads (counter in degrees). */
typedef struct windgen {
    double degree, random, wx, wy, wz;
    spn_rng rng;
} windgen;

static void windgen_call(windgen *g)
{
    const double MASS = 0.00000001, GRAVITY = 9.8, WIND = MASS * GRAVITY * 10;
    if (fmod(g->degree, 50) == 0) g->random = spn_rng_range(&g->rng, -3, 3);
    double s = sin(g->degree * SPN_PI / 180);
    g->wx = g->random * WIND * s;
    g->wy = g->random * WIND * s;
    g->wz = -WIND * s;
    g->degree = g->degree + 1;
}

static void test_matches_figure(void **state)
{
    (void)state;
    spn_world_def wd = spn_world_def_default();
    wd.gravity = spn_v3(0, 0, 0);
    spn_world *w = spn_world_create(&wd);
    const double radius = 0.5;
    spn_particle_def p = spn_particle_def_default();
    p.mass = 1e-3; /* heavy enough to move, light enough to move visibly */
    spn_vec3 pos[NP] = {{0, 0, 0}, {0.5, 0, 0}, {0, 0.25, 0}, {-0.3, -0.4, 0}, {0.1, 0.1, 0.2}};
    for (int i = 0; i < NP; i++) {
        p.position = pos[i];
        p.tag = i == 0 ? SPN_PARTICLE_HUB : SPN_PARTICLE_SPIRAL;
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    spn_thesis_wind_def def = spn_thesis_wind_def_default();
    def.radius = radius;
    def.seed = 42;
    recorder rec;
    memset(&rec, 0, sizeof rec);
    assert_int_equal(spn_thesis_wind_create(&def, w, &rec.wind), SPN_OK);
    assert_int_equal(spn_thesis_wind_centre(rec.wind), 0);
    spn_world_set_force_callback(w, record, &rec);

    windgen g = {0, 1, 0, 0, 0, {{0}}};
    spn_rng_seed(&g.rng, 42);
    double biggest = 0;
    for (int step = 0; step < 200; step++) {
        assert_int_equal(spn_world_step(w, 0.02), SPN_OK);
        windgen_call(&g);
        for (int i = 0; i < NP; i++) {
            double d = spn_v3_len(spn_v3_sub(rec.x[i], rec.x[0])) / (radius * 50);
            spn_vec3 expect = spn_v3(exp(d) * g.wx, exp(d) * g.wy, exp(d) * g.wz);
            spn_vec3 diff = spn_v3_sub(rec.f[i], expect);
            assert_true(spn_v3_len(diff) <= 1e-12 * (1e-9 + spn_v3_len(expect)));
            biggest = fmax(biggest, spn_v3_len(expect));
        }
    }
    assert_int_equal(rec.calls, 200);
    /* The wind was really there: up to 3 * sqrt(2) * W in the plane, W along z. */
    assert_true(biggest > 1e-7);
    spn_thesis_wind_destroy(rec.wind);
    spn_world_destroy(w);
}

static void test_factor_changes_every_50(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    spn_thesis_wind *wind;
    assert_int_equal(spn_thesis_wind_create(NULL, w, &wind), SPN_OK);
    /* Within a block of 50 counts x / (-z) is the factor; it is constant. */
    for (int block = 0; block < 4; block++) {
        double r0 = NAN;
        for (int c = block * 50 + 1; c < block * 50 + 50; c++) {
            spn_vec3 v = spn_thesis_wind_vector(wind, c * 0.02);
            double r = v.x / -v.z;
            assert_true(r >= -3 && r <= 3);
            if (isnan(r0)) r0 = r;
            assert_true(fabs(r - r0) < 1e-9);
        }
    }
    spn_thesis_wind_destroy(wind);
    spn_world_destroy(w);
}

static void test_rejects_bad_constants(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_thesis_wind *wind = NULL;
    spn_thesis_wind_def d = spn_thesis_wind_def_default();
    assert_int_equal(spn_thesis_wind_create(&d, w, &wind), SPN_ERR_INVALID); /* no particles */
    spn_particle_def p = spn_particle_def_default();
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    d.period = 0;
    assert_int_equal(spn_thesis_wind_create(&d, w, &wind), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "period"));
    d = spn_thesis_wind_def_default();
    d.centre = 7;
    assert_int_equal(spn_thesis_wind_create(&d, w, &wind), SPN_ERR_INVALID);
    assert_null(wind);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_figure),
        cmocka_unit_test(test_factor_changes_every_50),
        cmocka_unit_test(test_rejects_bad_constants),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

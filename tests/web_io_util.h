/* Shared by the web file tests (test_io_web.c, test_io_web_binary.c): a
 * world whose every field could lose bits on the way to a file and back, and
 * the check that two worlds agree bit for bit. Include after cmocka.h. */
#ifndef SPN_TESTS_WEB_IO_UTIL_H
#define SPN_TESTS_WEB_IO_UTIL_H

#include <dirent.h>
#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

/* A web with every kind of value that could lose bits on the way: random
 * fractions, -0.0, a subnormal, huge and tiny magnitudes, finite and infinite
 * break lengths, broken and tension-only springs, fixed particles with mass. */
static inline spn_world *awkward_world(void)
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

static inline bool same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }
static inline bool same_vec(spn_vec3 a, spn_vec3 b) { return memcmp(&a, &b, sizeof a) == 0; }

static inline void assert_same_world(const spn_world *a, const spn_world *b)
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

/* Files in `dir` other than . and .. */
static inline int count_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));) n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    if (d) closedir(d);
    return n;
}

/* A web file in memory read back: the same world as `w`, bit for bit
 * (awkward_world's broken springs 4 and 7 among it). */
static inline spn_world *assert_reads_back(const spn_buffer *buf, const spn_world *w)
{
    spn_world *back = NULL;
    assert_int_equal(spn_web_parse(buf->data, buf->size, "memory", &back), SPN_OK);
    assert_same_world(w, back);
    assert_true(spn_world_spring(back, 4).broken && spn_world_spring(back, 7).broken);
    return back;
}

/* The world as a JSON web file, in memory. */
static inline spn_buffer web_json_of(const spn_world *w)
{
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    assert_int_equal(spn_web_write(w, &sink), SPN_OK);
    return buf;
}

#endif

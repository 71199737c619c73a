/* hello_springs: the spring world in one page.
 *
 * Build a small graph (a rope of five segments hung between two pins, with a
 * weight hung by a sixth spring from its third node), step it with the implicit
 * solver until it rests, and read it back: positions, spring tensions,
 * energies. Run it: `./example_hello_springs`. */
#include <spinneret/spinneret.h>

#include <stdio.h>

/* Every call that can fail returns a status; the message names the culprit. */
#define CHECK(call)                                                          \
    do {                                                                     \
        spn_status st_ = (call);                                             \
        if (st_ != SPN_OK) {                                                 \
            fprintf(stderr, "hello_springs: %s\n", spn_last_error());       \
            return 1;                                                        \
        }                                                                    \
    } while (0)

int main(void)
{
    /* 1. A world from a definition with defaults: gravity (0, -9.81, 0). */
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT; /* stiff springs, big steps */
    def.drag = 2;                             /* a little air friction [1/s] */
    spn_world *w = spn_world_create(&def);
    if (!w) return 1;

    /* 2. Particles: two pins and the rope's nodes between them. */
    uint32_t rope[6];
    for (int i = 0; i < 6; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3(0.2 * i, 0, 0);
        p.mass = 0.01;                 /* kg */
        p.fixed = i == 0 || i == 5;    /* the pins */
        CHECK(spn_world_add_particle(w, &p, &rope[i]));
    }
    spn_particle_def weight = spn_particle_def_default();
    weight.position = spn_v3(0.5, -0.1, 0);
    weight.mass = 0.05;
    uint32_t bob;
    CHECK(spn_world_add_particle(w, &weight, &bob));

    /* 3. Springs: k [N/m], axial damping kd [N s/m], rest length [m]. */
    for (int i = 0; i < 5; i++) {
        spn_spring_def s = spn_spring_def_default();
        s.a = rope[i];
        s.b = rope[i + 1];
        s.k = 5000;
        s.kd = 0.5;
        s.rest = 0.21;          /* a little slack */
        s.tension_only = true;  /* a rope does not push */
        CHECK(spn_world_add_spring(w, &s, NULL));
    }
    spn_spring_def hanger = spn_spring_def_default();
    hanger.a = rope[2];
    hanger.b = bob;
    hanger.k = 500;
    hanger.rest = -1;           /* negative: the current distance */
    CHECK(spn_world_add_spring(w, &hanger, NULL));

    /* 4. Step: the world compiles itself on the first step. */
    for (int i = 0; i < 120; i++) CHECK(spn_world_step(w, 1.0 / 60));

    /* ... or settle: step until at rest, with a report that says why it stopped. */
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = 1.0 / 60;
    sd.max_residual = 1e-7;
    spn_settle_report rep;
    CHECK(spn_world_settle(w, &sd, &rep));
    printf("settled: %s after %.2f s more, largest residual force %.2e N\n",
           rep.reason == SPN_SETTLE_CONVERGED ? "at rest" : "out of time", rep.time, rep.residual);

    /* 5. Read it back. */
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        spn_vec3 x = spn_world_position(w, i);
        printf("particle %u  (%+.4f, %+.4f, %+.4f) m%s\n", i, x.x, x.y, x.z, spn_world_is_fixed(w, i) ? "  fixed" : "");
    }
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info info = spn_world_spring(w, s);
        printf("spring %u  %u-%u  length %.4f m  tension %.4f N\n", s, info.a, info.b, info.length, info.tension);
    }
    spn_energy e = spn_world_energy(w);
    printf("energy: kinetic %.3g J, elastic %.4f J, gravitational %.4f J, dissipated so far %.4f J\n", e.kinetic,
           e.elastic, e.gravitational, e.dissipated);

    /* It came to rest, with the weight below the node it hangs from. */
    int ok = rep.reason == SPN_SETTLE_CONVERGED && spn_world_position(w, bob).y < spn_world_position(w, rope[2]).y;
    spn_world_destroy(w);
    return ok ? 0 : 1;
}

/* Makes orb.json: the standard orb web of scenes.h (12 rings x 16 radials,
 * radius 0.15 m), its capture rings made compliant like capture silk
 * (k / 1000), settled under gravity. Not built by CMake; rebuild with
 *   cc -Iinclude tests/data/anim/make_orb.c build/libspinneret.a -lcairo -lcjson -lm -fopenmp */
#include <spinneret/spinneret.h>
#include <stdio.h>

int main(void)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 12;
    od.radials = 16;
    spn_world *w;
    if (spn_scene_orb(NULL, &od, &w) != SPN_OK) return 1;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info in = spn_world_spring(w, s);
        if (in.tag == SPN_THREAD_CAPTURE) spn_world_set_spring_stiffness(w, s, in.k * 1e-3, in.kd * 0.03);
    }
    spn_world_set_drag(w, 200);
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = 1e-5;
    sd.max_time = 0.5;
    sd.max_kinetic = 1e-13;
    spn_settle_report sr;
    if (spn_world_settle(w, &sd, &sr) != SPN_OK) return 1;
    spn_world_set_drag(w, 0);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) spn_world_set_velocity(w, i, spn_v3(0, 0, 0));
    spn_world_set_time(w, 0);
    fprintf(stderr, "settle: %s after %g s\n", sr.reason == SPN_SETTLE_CONVERGED ? "converged" : "timeout", sr.time);
    return spn_web_save(w, "tests/data/anim/orb.json") == SPN_OK ? 0 : 1;
}

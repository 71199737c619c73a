/* A spider at the hub: the standard orb web (scenes.h) with a 0.3 g load on
 * its hub, stepped under gravity with drag until it hangs still, then saved
 * as a web file. The upper radii now carry the spider and the lower ones go
 * slack, which is what `spinneret render --colour-by tension` shows.
 *
 *   example_loaded_web [OUT.json]      (default loaded_web.json)
 *
 * The thread here is far heavier than silk (0.1 g/m) so the explicit
 * symplectic integrator can take 0.1 ms steps; the look is what matters. */
#include <stdio.h>
#include <spinneret/spinneret.h>

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "loaded_web.json";
    spn_world_def wd = spn_world_def_default();
    wd.drag = 25; /* 1/s: damps the swing in a fraction of a second */
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.linear_density = 1e-4;
    spn_world *w;
    if (spn_scene_orb(&wd, &od, &w) != SPN_OK) {
        fprintf(stderr, "example_loaded_web: %s\n", spn_last_error());
        return 1;
    }
    spn_status st = spn_world_set_mass(w, 0, spn_world_mass(w, 0) + 3e-4); /* particle 0 is the hub */
    for (int i = 0; i < 15000 && st == SPN_OK; i++) st = spn_world_step(w, 1e-4);
    if (st == SPN_OK) st = spn_world_set_metadata(w, "{\"example\": \"loaded_web\", \"hub_load_kg\": 3e-4}");
    if (st == SPN_OK) st = spn_web_save(w, out);
    if (st != SPN_OK) fprintf(stderr, "example_loaded_web: %s\n", spn_last_error());
    else printf("hub hangs %.1f mm below the centre; wrote %s\n", -1e3 * spn_world_position(w, 0).y, out);
    spn_world_destroy(w);
    return st == SPN_OK ? 0 : 1;
}

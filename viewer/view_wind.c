/* The viewer's wind (key w, strength [ and ]): the animation part's gusty,
 * turbulent air field acting through the world's aerodynamic drag on every
 * thread, cached on a grid over the web so a live frame stays cheap. */
#include "view_internal.h"

#include <math.h>

static void detach(view_state *v)
{
    if (v->world) spn_world_set_air(v->world, NULL, NULL, 1.204, 1.81e-5);
    spn_air_destroy(v->air);
    v->air = NULL;
}

void view_wind_update(view_state *v)
{
    detach(v);
    if (!v->wind_on || !v->world || v->wind_strength <= 0) return;
    spn_air_def d = spn_air_def_default();
    d.speed = v->wind_strength;
    d.seed = v->opt.seed;
    uint32_t n = spn_world_particle_count(v->world);
    const spn_vec3 *x = spn_world_positions(v->world);
    spn_vec3 lo = x[0], hi = x[0];
    for (uint32_t i = 1; i < n; i++) {
        lo = spn_v3(fmin(lo.x, x[i].x), fmin(lo.y, x[i].y), fmin(lo.z, x[i].z));
        hi = spn_v3(fmax(hi.x, x[i].x), fmax(hi.y, x[i].y), fmax(hi.z, x[i].z));
    }
    spn_vec3 pad = spn_v3(0.1, 0.1, 0.1);
    if (spn_air_create(&d, &v->air) != SPN_OK ||
        spn_air_set_grid(v->air, spn_v3_sub(lo, pad), spn_v3_add(hi, pad), 16, 16, 4, 0.05) != SPN_OK) {
        fprintf(stderr, "spinneret view: wind: %s\n", spn_last_error());
        detach(v);
        v->wind_on = false;
        return;
    }
    spn_air_attach(v->air, v->world);
}

void view_wind_prepare(view_state *v, double t0, double t1)
{
    if (v->air) spn_air_prepare_held(v->air, t0, t1);
}

void view_wind_release(view_state *v) { detach(v); }

/* Construction states for building animations: the springs laid up to a point
 * of the construction order (spn_spring_info.order), with the auxiliary spiral
 * taken away where the capture spiral has already passed. The capture spiral
 * is laid from the outside in, so an auxiliary segment goes once the capture
 * thread is nearer the hub than the segment's inner end (Zschokke 2011: the
 * spider removes the auxiliary spiral while laying the sticky one). */
#include "web_internal.h"

#include <math.h>
#include <stdlib.h>

static spn_vec3 hub_of(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w);
    spn_vec3 c = spn_v3(0, 0, 0);
    int n = 0;
    for (uint32_t i = 0; i < np; i++)
        if (spn_world_particle_tag(w, i) == SPN_PARTICLE_HUB) c = spn_v3_add(c, spn_world_position(w, i)), n++;
    if (n) return spn_v3_scale(c, 1.0 / n);
    for (uint32_t i = 0; i < np; i++) c = spn_v3_add(c, spn_world_position(w, i));
    return np ? spn_v3_scale(c, 1.0 / np) : c;
}

static double from_hub(const spn_world *w, spn_vec3 hub, uint32_t i)
{
    return spn_v3_len(spn_v3_sub(spn_world_position(w, i), hub));
}

spn_status spn_web_construction_state(const spn_world *w, double fraction, spn_world **out)
{
    *out = NULL;
    if (!(fraction >= 0 && fraction <= 1)) return spn_error(SPN_ERR_INVALID, "fraction must be in [0, 1]");
    uint32_t ns = spn_world_spring_count(w), last = 0;
    for (uint32_t s = 0; s < ns; s++) last = (uint32_t)fmax(last, spn_world_spring(w, s).order);
    double cut = (last + 1.0) * fraction;
    spn_vec3 hub = hub_of(w);
    double capture_reach = INFINITY;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == SPN_THREAD_CAPTURE && si.order < cut)
            capture_reach = fmin(capture_reach, fmin(from_hub(w, hub, si.a), from_hub(w, hub, si.b)));
    }
    bool *rm = malloc((ns ? ns : 1) * sizeof *rm);
    spn_world *c = spn_world_clone(w);
    if (!rm || !c) {
        free(rm);
        spn_world_destroy(c);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        rm[s] = si.order >= cut;
        if (si.tag == SPN_THREAD_AUX_SPIRAL && fmin(from_hub(w, hub, si.a), from_hub(w, hub, si.b)) > capture_reach)
            rm[s] = true;
    }
    spn_status st = spn_world_remove_springs(c, rm);
    free(rm);
    if (st != SPN_OK) {
        spn_world_destroy(c);
        return st;
    }
    *out = c;
    return SPN_OK;
}

/* Dew: water droplets beaded along the capture spiral, the effect Mehla's
 * thesis left as future work (ch. 7).
 *
 * A film of water on a thread breaks up into droplets (the Plateau-Rayleigh
 * instability), so real dew sits in near-regular rows of main drops with
 * small satellite drops between some of them. Here main drops are laid along
 * each capture strand at gaps of `spacing` times a jitter factor, with radii
 * `radius` times (1 + radius_jitter * a clamped normal deviate); half of the
 * gaps wide enough get a satellite of about a third of the main radius. Drops
 * hang: the centre sits half a radius below the thread.
 * Invariants: the same strands and dew definition give the same drops (one
 * spn_rng seeded from def->seed, consumed in strand order); every radius is
 * positive; when the world has no capture thread every thread gets dew. */
#include "render_internal.h"
#include "spinneret/web.h"

#include <math.h>
#include <stdlib.h>

#define MAX_BEADS 20000000u

static spn_status push(spn__bead_list *list, spn_vec3 c, double r, uint32_t kind)
{
    if (list->count == list->capacity) {
        size_t cap = list->capacity ? list->capacity * 2 : 256;
        if (cap > MAX_BEADS) return spn_error(SPN_ERR_NOMEM, "dew: more than %u droplets; raise dew.spacing", MAX_BEADS);
        spn_bead *b = realloc(list->beads, cap * sizeof *b);
        if (!b) return spn_error(SPN_ERR_NOMEM, "dew: out of memory");
        list->beads = b;
        list->capacity = cap;
    }
    spn_bead bead = {spn_v3(c.x, c.y - 0.5 * r, c.z), r, kind};
    list->beads[list->count++] = bead;
    return SPN_OK;
}

/* The point at arc length `s` along segment (a, b) of length len. */
static spn_vec3 along(spn_vec3 a, spn_vec3 b, double s, double len)
{
    double t = len > 0 ? s / len : 0;
    return spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), t));
}

static double drop_radius(spn_rng *rng, const spn_dew_def *def)
{
    double n = spn_rng_normal(rng);
    if (n > 2) n = 2;
    if (n < -2) n = -2;
    double f = 1 + def->radius_jitter * 0.5 * n;
    return def->radius * (f < 0.3 ? 0.3 : f);
}

static double gap(spn_rng *rng, const spn_dew_def *def)
{
    return def->spacing * (1 + def->radius_jitter * spn_rng_range(rng, -0.6, 0.6));
}

static spn_status bead_chain(const spn__strands *s, const spn__chain *c, const spn_dew_def *def, spn_rng *rng,
                             spn__bead_list *out)
{
    uint32_t segs = c->closed ? c->count : c->count - 1;
    double next = def->spacing * spn_rng_range(rng, 0.2, 1.0), travelled = 0, last_main = -1, last_r = 0;
    spn_status st = SPN_OK;
    for (uint32_t i = 0; i < segs && st == SPN_OK; i++) {
        spn_vec3 a = s->points[c->first + i], b = s->points[c->first + (i + 1) % c->count];
        double len = spn_v3_len(spn_v3_sub(b, a));
        while (next < travelled + len && st == SPN_OK) {
            double r = drop_radius(rng, def);
            spn_vec3 p = along(a, b, next - travelled, len);
            st = push(out, p, r, c->kind);
            double g = gap(rng, def);
            if (st == SPN_OK && last_main >= 0 && spn_rng_uniform(rng) < 0.5 && next - last_main > 4 * (r + last_r)) {
                double mid = 0.5 * (next + last_main) - travelled;
                if (mid >= 0) st = push(out, along(a, b, mid, len), 0.3 * r, c->kind);
            }
            last_main = next;
            last_r = r;
            next += g;
        }
        travelled += len;
    }
    return st;
}

spn_status spn__dew_place(const spn__strands *s, const spn_dew_def *def, spn__bead_list *out)
{
    if (!def->enabled) return SPN_OK;
    bool any_capture = false;
    for (uint32_t i = 0; i < s->chain_count; i++) any_capture |= s->chains[i].kind == SPN_THREAD_CAPTURE;
    spn_rng rng;
    spn_rng_seed(&rng, def->seed);
    spn_status st = SPN_OK;
    for (uint32_t i = 0; i < s->chain_count && st == SPN_OK; i++)
        if (!any_capture || s->chains[i].kind == SPN_THREAD_CAPTURE) st = bead_chain(s, &s->chains[i], def, &rng, out);
    return st;
}

void spn__bead_list_free(spn__bead_list *list)
{
    free(list->beads);
    list->beads = NULL;
    list->count = list->capacity = 0;
}

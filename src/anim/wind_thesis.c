/* The thesis' wind: Mehla 2005, section 5.3.9, fig. 5.45, as a force callback.
 *
 * windgen keeps an angle counter (`degree`); whenever degree % 50 == 0 it draws
 * a new factor in [-3, 3]; the wind vector is (r W sin, r W sin, -W sin) with
 * W = MASS * GRAVITY * 10; each mass then gets exp(distance / (radius * 50))
 * times the vector, distance measured from a hub mass.
 *
 * Reading of the pseudo-code (documented in docs/wind-and-prey.md): the figure
 * indents `degree = degree + 1` and the vector update under the `if`, which
 * would freeze the counter at 1 and the wind at sin(0) = 0; the prose ("a new
 * random number ... every 50 degrees ... along with the sine term") says the
 * counter runs every call and the sine modulates every call. So: the counter
 * advances once per call, the factor changes every 50 counts, and the vector
 * is recomputed every call. The thesis called windgen once per simulation step
 * of 0.02 s; here the counter is tied to simulated time (one count per `tick`),
 * so the wind does not depend on the step or solver used. The angle is in
 * degrees unless `radians` is set (the counter is named `degree`).
 *
 * Invariant: the k-th factor is the k-th spn_rng_range(-r, r) draw from the
 * seed, whatever order the force evaluations come in. */
#include "anim_internal.h"

#include <math.h>
#include <stdlib.h>

struct spn_thesis_wind {
    spn_thesis_wind_def def;
    uint32_t centre;
    double radius;
    spn_rng rng;
    double *factors;  /* factors[k]: for counts [k * period, (k + 1) * period) */
    size_t nfactors, cap;
};

spn_thesis_wind_def spn_thesis_wind_def_default(void)
{
    spn_thesis_wind_def d;
    d.mass = 1e-8;
    d.gravity = 9.8;
    d.gain = 10;
    d.random_max = 3;
    d.period = 50;
    d.tick = 0.02;
    d.radians = false;
    d.falloff = 50;
    d.centre = -1;
    d.radius = 0;
    d.seed = 1;
    return d;
}

static spn_status check_def(const spn_thesis_wind_def *d, uint32_t np)
{
    if (!(d->mass >= 0) || !isfinite(d->mass)) return spn_error(SPN_ERR_INVALID, "thesis wind: mass must be >= 0");
    if (!isfinite(d->gravity) || !isfinite(d->gain)) return spn_error(SPN_ERR_INVALID, "thesis wind: gravity and gain must be finite");
    if (!(d->random_max >= 0) || !isfinite(d->random_max))
        return spn_error(SPN_ERR_INVALID, "thesis wind: random range must be >= 0");
    if (d->period < 1) return spn_error(SPN_ERR_INVALID, "thesis wind: period must be >= 1");
    if (!(d->tick > 0) || !isfinite(d->tick)) return spn_error(SPN_ERR_INVALID, "thesis wind: tick must be > 0");
    if (!(d->falloff > 0) || !isfinite(d->falloff)) return spn_error(SPN_ERR_INVALID, "thesis wind: falloff must be > 0");
    if (!(d->radius >= 0) || !isfinite(d->radius)) return spn_error(SPN_ERR_INVALID, "thesis wind: radius must be >= 0");
    if (np == 0) return spn_error(SPN_ERR_INVALID, "thesis wind: the world has no particles");
    if (d->centre >= (int64_t)np)
        return spn_error(SPN_ERR_INVALID, "thesis wind: centre particle %lld out of range (%u particles)",
                         (long long)d->centre, np);
    return SPN_OK;
}

spn_status spn_thesis_wind_create(const spn_thesis_wind_def *def, const spn_world *w, spn_thesis_wind **out)
{
    *out = NULL;
    spn_thesis_wind_def d = def ? *def : spn_thesis_wind_def_default();
    uint32_t np = spn_world_particle_count(w);
    spn_status st = check_def(&d, np);
    if (st != SPN_OK) return st;
    spn_thesis_wind *wind = calloc(1, sizeof *wind);
    if (!wind) return spn_error(SPN_ERR_NOMEM, "out of memory");
    wind->def = d;
    wind->centre = d.centre >= 0 ? (uint32_t)d.centre : spn__hub_particle(w);
    wind->radius = d.radius > 0 ? d.radius : spn__web_radius(w, wind->centre);
    if (!(wind->radius > 0)) wind->radius = 1;
    spn_rng_seed(&wind->rng, d.seed);
    *out = wind;
    return SPN_OK;
}

void spn_thesis_wind_destroy(spn_thesis_wind *wind)
{
    if (!wind) return;
    free(wind->factors);
    free(wind);
}

uint32_t spn_thesis_wind_centre(const spn_thesis_wind *wind) { return wind->centre; }
double spn_thesis_wind_radius(const spn_thesis_wind *wind) { return wind->radius; }

/* The factor for block k, drawing in order as far as needed. */
static double factor(spn_thesis_wind *wind, size_t k)
{
    while (wind->nfactors <= k) {
        if (wind->nfactors == wind->cap) {
            size_t cap = wind->cap ? 2 * wind->cap : 64;
            double *p = realloc(wind->factors, cap * sizeof *p);
            if (!p) return 1; /* keep the last known shape: the thesis' initial random = 1 */
            wind->factors = p;
            wind->cap = cap;
        }
        double r = wind->def.random_max;
        wind->factors[wind->nfactors++] = spn_rng_range(&wind->rng, -r, r);
    }
    return wind->factors[k];
}

spn_vec3 spn_thesis_wind_vector(spn_thesis_wind *wind, double t)
{
    const spn_thesis_wind_def *d = &wind->def;
    /* The small offset keeps t = n * tick, reached by summing steps, on count n. */
    double c = floor(t / d->tick + 1e-6);
    if (c < 0) c = 0;
    double r = factor(wind, (size_t)(c / d->period));
    double angle = d->radians ? c : c * SPN_PI / 180;
    double s = sin(angle), big = d->mass * d->gravity * d->gain;
    return spn_v3(r * big * s, r * big * s, -big * s);
}

void spn_thesis_wind_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v,
                           spn_vec3 *f)
{
    (void)v;
    spn_thesis_wind *wind = user;
    spn_vec3 wv = spn_thesis_wind_vector(wind, t);
    spn_vec3 c = x[wind->centre];
    double alpha = wind->radius * wind->def.falloff;
    uint32_t np = spn_world_particle_count(w);
    for (uint32_t i = 0; i < np; i++) {
        if (spn_world_is_fixed(w, i) || spn_world_particle_tag(w, i) == SPN_PARTICLE_PREY) continue;
        double s = exp(spn_v3_len(spn_v3_sub(x[i], c)) / alpha);
        f[i] = spn_v3_add(f[i], spn_v3_scale(wv, s));
    }
}

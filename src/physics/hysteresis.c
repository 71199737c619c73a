/* Silk's hysteresis: a loading-unloading cycle of spider silk loses most of
 * the work put in (Gosline et al. 1999, J. Exp. Biol. 202:3295, table 2:
 * Araneus major ampullate silk 65%, viscid capture silk more; Denny 1976,
 * J. Exp. Biol. 65:483), nearly independently of the rate. That loss is what
 * lets a web stop a prey instead of throwing it back (Sensenig et al. 2012).
 *
 * The law: while a spring is stretched (s = |l| - r > 0) its axial force is
 *   F = k s (1 + eta tanh(s' / s0)),   s0 = rate0 r,
 * stiffer while it lengthens, softer while it shortens, through the origin
 * (no permanent set, no memory). Far above the strain rate rate0 the extra
 * term is a friction-like +-eta k s, so a cycle from slack to a stretch A and
 * back does (1 + eta) k A^2 / 2 of work and gets (1 - eta) k A^2 / 2 back: a
 * loss fraction 2 eta / (1 + eta), hence eta = loss / (2 - loss). Below rate0
 * it is a dashpot of coefficient eta k s / s0, which keeps the law smooth
 * (a friction law with a dead band would have no unique equilibrium).
 *
 * Invariant: the hysteresis force times s' is eta k s s' tanh(s'/s0) >= 0, so
 * it only ever dissipates. It is applied as the secant damping coefficient
 *   c = kd + eta k s tanh(|s'| / s0) / |s'|   (-> kd + eta k s / s0 at rest)
 * written into the hot spring records before each step, from the state at the
 * step's start: every integrator then treats it as the spring's axial damping
 * (the implicit solver inside its linear system, stable at any step) and
 * counts its power kd s'^2 in the world's dissipated energy. For explicit
 * integrators c is capped at m / (2 dt) of the lighter free end, the stable
 * limit of a dashpot in a symplectic step.
 *
 * Known limit: a pre-tensioned thread vibrating by much less than its
 * pre-stretch loses a lot per cycle (the +-eta k s term does not shrink with
 * the amplitude), so small vibrations of a loaded web are strongly damped. */
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_status spn_world_set_tag_hysteresis(spn_world *w, uint32_t tag, double loss, double rate0)
{
    if (!(loss >= 0 && loss < 1))
        return spn_error(SPN_ERR_INVALID, "hysteresis of tag %u: loss must be in [0, 1), got %g", tag, loss);
    if (!(rate0 > 0) || !isfinite(rate0))
        return spn_error(SPN_ERR_INVALID, "hysteresis of tag %u: rate0 must be > 0 and finite, got %g", tag, rate0);
    const double eta = loss / (2 - loss);
    for (uint32_t i = 0; i < w->nhyst; i++)
        if (w->hyst[i].tag == tag) {
            w->hyst[i].eta = eta;
            w->hyst[i].rate0 = rate0;
            return SPN_OK;
        }
    spn_tag_hysteresis *h = realloc(w->hyst, (w->nhyst + 1) * sizeof *h);
    if (!h) return spn_error(SPN_ERR_NOMEM, "out of memory");
    w->hyst = h;
    w->hyst[w->nhyst++] = (spn_tag_hysteresis){tag, eta, rate0};
    return SPN_OK;
}

double spn_world_tag_hysteresis(const spn_world *w, uint32_t tag, double *rate0)
{
    for (uint32_t i = 0; i < w->nhyst; i++)
        if (w->hyst[i].tag == tag) {
            if (rate0) *rate0 = w->hyst[i].rate0;
            return 2 * w->hyst[i].eta / (1 + w->hyst[i].eta); /* eta = loss / (2 - loss) */
        }
    if (rate0) *rate0 = 0;
    return 0;
}

double spn_world_spring_damping(const spn_world *w, uint32_t s)
{
    if (s >= w->ns) return 0;
    if (w->compiled && !(w->sflags[s] & SPN_SPRING_BROKEN)) return w->hs[w->iperm[s]].kd;
    return w->kd[s];
}

static const spn_tag_hysteresis *find(const spn_world *w, uint32_t tag)
{
    for (uint32_t i = 0; i < w->nhyst; i++)
        if (w->hyst[i].tag == tag) return w->hyst[i].eta > 0 ? &w->hyst[i] : NULL;
    return NULL;
}

/* The secant coefficient eta k s tanh(|rate| / s0) / |rate|. */
static double secant(double eta, double k, double stretch, double rate, double s0)
{
    const double x = fabs(rate) / s0;
    const double t = x < 1e-8 ? 1 : tanh(x) / x; /* tanh(x) / x -> 1 at 0 */
    return eta * k * stretch * t / s0;
}

void spn__hysteresis_prepare(spn_world *w, double dt)
{
    if (!w->nhyst) return;
    const bool cap = w->def.integrator != SPN_INTEGRATOR_IMPLICIT;
    const uint32_t ns = w->ns;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, ns))
    for (uint32_t s = 0; s < ns; s++) {
        if (w->hflags[s] & SPN_SPRING_BROKEN) continue;
        const uint32_t pub = w->perm[s];
        const spn_tag_hysteresis *h = find(w, w->stag[pub]);
        if (!h) continue;
        spn__spring *sp = &w->hs[s];
        const uint32_t a = sp->a, b = spn__end_b(*sp);
        const spn_vec3 l = spn_v3_sub(w->x[a], w->x[b]);
        const double len = spn_v3_len(l), stretch = len - sp->rest;
        double c = w->kd[pub];
        if (len > 0 && stretch > 0 && sp->rest > 0) {
            const double rate = spn_v3_dot(spn_v3_sub(w->v[a], w->v[b]), l) / len;
            c += secant(h->eta, sp->k, stretch, rate, h->rate0 * sp->rest);
            if (cap) {
                double m = INFINITY;
                if (w->inv_mass[a] > 0) m = w->mass[a];
                if (w->inv_mass[b] > 0 && w->mass[b] < m) m = w->mass[b];
                if (isfinite(m) && c > 0.5 * m / dt) c = fmax(w->kd[pub], 0.5 * m / dt);
            }
        }
        sp->kd = c;
    }
}

void spn__silk_free(spn_world *w)
{
    free(w->hyst);
    free(w->contacts);
    w->hyst = NULL;
    w->contacts = NULL;
    w->nhyst = w->ncontacts = w->cap_contacts = 0;
}

bool spn__silk_clone(spn_world *c, const spn_world *w)
{
    c->contacts = NULL;
    c->ncontacts = c->cap_contacts = 0;
    c->hyst = NULL;
    c->nhyst = 0;
    if (!w->nhyst) return true;
    c->hyst = malloc(w->nhyst * sizeof *c->hyst);
    if (!c->hyst) return false;
    memcpy(c->hyst, w->hyst, w->nhyst * sizeof *c->hyst);
    c->nhyst = w->nhyst;
    return true;
}

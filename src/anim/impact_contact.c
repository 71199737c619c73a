/* Prey contact for the implicit solver, and the solver's own dissipation.
 *
 * Before each implicit step the impact lists its contacts for the world
 * (spn_world_set_contacts): every segment closer to a prey's centre than its
 * radius, and every taut glue tether. The force callback gives each the
 * force k depth0 n of its depth at the step's start and the world's backward
 * Euler step carries the stiffness, so the prey and the 1e-10 kg thread
 * particles move together at the solver's step instead of the 1e-7 s an
 * explicit contact needs. A contact is found a step late, already some way
 * in (at most 3% of a radius: spn_impact_step_limit, below): the depth it
 * first has becomes the contact's offset, so the penalty does not create
 * k depth^2 / 2 from nothing (the sphere is that much smaller for that
 * thread; the offset shrinks as the thread comes back out).
 *
 * Backward Euler removes energy by itself: for a quadratic energy one step
 * loses exactly 1/2 dv^T M dv + 1/2 dx^T K dx (with dv, dx the step's changes;
 * Hairer, Lubich & Wanner, or a two-line derivation from M dv = h f(x1)).
 * The ledger counts it as the solver's loss, from the saved start state:
 * particles' 1/2 m |dv|^2, springs' 1/2 k [(1 - tau)(u . dd)^2 + tau |dd|^2]
 * (the Hessian the solver uses, tau = 1 - r / L >= 0, slack springs none),
 * and per contact 1/2 k dy^2 plus the difference between the one-sided
 * penalty and its two-sided linear model at the ends of the step. */
#include "impact_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static spn_status grow(spn_impact *im, uint32_t n)
{
    if (n <= im->cap_cl) return SPN_OK;
    uint32_t cap = n < 64 ? 64 : 2 * n;
    spn_contact *c = realloc(im->cl, cap * sizeof *c);
    if (c) im->cl = c;
    uint32_t *g = realloc(im->cseg, cap * sizeof *g);
    if (g) im->cseg = g;
    if (!c || !g) return spn_error(SPN_ERR_NOMEM, "out of memory for %u contacts", n);
    im->cap_cl = cap;
    return SPN_OK;
}

static spn_status push(spn_impact *im, spn_contact c, uint32_t seg)
{
    spn_status st = grow(im, im->ncl + 1);
    if (st != SPN_OK) return st;
    im->cl[im->ncl] = c;
    im->cseg[im->ncl] = seg;
    im->ncl++;
    return SPN_OK;
}

/* A new contact counts from the depth it has (no force acted while it got
 * there); one the solver held at depth y_end (cend) that is found deeper,
 * because the thread slid over the curved sphere where the solver's frozen
 * normal saw a plane, counts from y_end (the offset takes up the rest: energy
 * no force paid for is not created); otherwise the offset only shrinks. */
double spn__impact_offset_depth(spn_impact *im, size_t i, double depth, bool update)
{
    double off = im->coff[i], end = im->cend[i];
    if (off < 0) off = depth;
    else if (end >= 0 && depth - off > end) off = depth - end;
    else off = fmin(off, depth);
    if (update) {
        im->coff[i] = off;
        im->cend[i] = -1;
    }
    return depth - off;
}

/* Segments touching prey p, with their offsets brought up to date: a contact
 * found for the first time gets the depth it reached without force as its
 * offset (the penalty counts from there, so it creates no energy), and an
 * offset only shrinks after (it follows a thread pushed back out, where the
 * penalty is zero, so that costs no energy either). */
static spn_status list_segments(spn_impact *im, const spn_vec3 *x, int p)
{
    const uint32_t ip = im->prey[p];
    const spn_vec3 c = x[ip];
    const double R = im->radius[p];
    double *coff = im->coff + (size_t)p * im->ns;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) {
            coff[s] = -1;
            continue;
        }
        double u;
        spn_vec3 r;
        double d2 = spn__impact_closest(im, s, x, c, &u, &r);
        if (d2 >= R * R || d2 <= 1e-30) {
            coff[s] = -1;
            continue;
        }
        double d = sqrt(d2), y = spn__impact_offset_depth(im, (size_t)p * im->ns + s, R - d, true);
        im->touched[p] = true;
        spn_contact ct = {ip, im->sa[s], im->sb[s], u, spn_v3_scale(r, 1 / d), im->kc, y, false, true};
        spn_status st = push(im, ct, (uint32_t)p * im->ns + s);
        if (st != SPN_OK) return st;
    }
    return SPN_OK;
}

/* Glue tethers that are taut, or would be within the step at twice their
 * present rate of lengthening: a slack one in the list is dropped by the
 * world's active set only after a whole extra solve (that made 97% of a
 * held prey's steps solve twice). One that goes taut unlisted takes up its
 * slack instead (tethers_follow). */
static spn_status list_tethers(spn_impact *im, const spn_vec3 *x, const spn_vec3 *v, double dt)
{
    for (int i = 0; i < im->ntethers; i++) {
        spn__tether *t = &im->tethers[i];
        uint32_t a = im->sa[t->s], b = im->sb[t->s], ip = im->prey[t->prey];
        spn_vec3 q = spn_v3_add(x[a], spn_v3_scale(spn_v3_sub(x[b], x[a]), t->u)), l = spn_v3_sub(x[ip], q);
        double len = spn_v3_len(l);
        if (!(len > 0)) continue;
        spn_vec3 vq = spn_v3_add(v[a], spn_v3_scale(spn_v3_sub(v[b], v[a]), t->u));
        double rate = spn_v3_dot(spn_v3_sub(v[ip], vq), l) / len;
        if (len + 2 * dt * fmax(rate, 0) <= t->rest) continue;
        t->slot = (int)im->ncl;
        spn_contact ct = {ip, a, b, t->u, spn_v3_scale(l, 1 / len), t->k, t->rest - len, true, true};
        spn_status st = push(im, ct, UINT32_MAX);
        if (st != SPN_OK) return st;
    }
    return SPN_OK;
}

spn_status spn_impact_before_step(spn_impact *im, spn_world *w, double dt)
{
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    memcpy(im->x0, x, im->np * sizeof *x);
    memcpy(im->v0, v, im->np * sizeof *v);
    im->ncl = 0;
    for (int i = 0; i < im->ntethers; i++) im->tethers[i].slot = -1;
    im->listed = spn_world_get_def(w)->integrator == SPN_INTEGRATOR_IMPLICIT;
    spn_status st = SPN_OK;
    if (im->listed) {
        im->offsets = true;
        for (int p = 0; p < im->nprey && st == SPN_OK; p++) st = list_segments(im, x, p);
        if (st == SPN_OK) st = list_tethers(im, x, v, dt);
    }
    if (st == SPN_OK) st = spn_world_set_contacts(w, im->cl, im->listed ? im->ncl : 0);
    if (st != SPN_OK) im->listed = false;
    return st;
}

static double springs_loss(const spn_impact *im, const spn_vec3 *x1)
{
    double loss = 0;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        uint32_t a = im->sa[s], b = im->sb[s];
        spn_vec3 l = spn_v3_sub(im->x0[a], im->x0[b]);
        double len = spn_v3_len(l), rest = im->rest[s];
        if (!(len > 0) || (len < rest && im->tension_only[s])) continue;
        spn_vec3 u = spn_v3_scale(l, 1 / len);
        spn_vec3 dd = spn_v3_sub(spn_v3_sub(x1[a], im->x0[a]), spn_v3_sub(x1[b], im->x0[b]));
        double tau = len > rest ? 1 - rest / len : 0, ax = spn_v3_dot(u, dd);
        loss += 0.5 * im->k[s] * ((1 - tau) * ax * ax + tau * spn_v3_dot(dd, dd));
    }
    return loss;
}

/* The contacts in force at the end of the step (the world's active set). */
static double contacts_loss(const spn_impact *im, const spn_world *w, const spn_vec3 *x1)
{
    uint32_t n;
    const spn_contact *wc = spn_world_contacts(w, &n);
    double loss = 0;
    for (uint32_t i = 0; i < im->ncl && i < n; i++) {
        const spn_contact *c = &im->cl[i];
        if (!wc[i].active) { /* the solver left it at the surface */
            if (im->cseg[i] != UINT32_MAX) im->cend[im->cseg[i]] = 0;
            continue;
        }
        spn_vec3 dp = spn_v3_sub(x1[c->p], im->x0[c->p]);
        spn_vec3 da = spn_v3_sub(x1[c->a], im->x0[c->a]), db = spn_v3_sub(x1[c->b], im->x0[c->b]);
        spn_vec3 dg = spn_v3_sub(dp, spn_v3_add(spn_v3_scale(da, 1 - c->u), spn_v3_scale(db, c->u)));
        double y0 = c->depth, y1 = y0 - spn_v3_dot(c->n, dg), dy = y1 - y0;
        if (im->cseg[i] != UINT32_MAX) im->cend[im->cseg[i]] = fmax(y1, 0);
        /* the part of the linear model's energy the one-sided law does not have */
        double off0 = c->pull ? fmin(-y0, 0) : fmin(y0, 0), off1 = c->pull ? fmin(-y1, 0) : fmin(y1, 0);
        loss += 0.5 * c->k * (dy * dy + off1 * off1 - off0 * off0);
    }
    return loss;
}

/* After the step, each glue tether's rest is set so its stretch is the one
 * the solver's linear model ended with. The model sees the tether along its
 * direction at the step's start; as the prey swings round the droplet's
 * anchor the true length grows by about |sideways move|^2 / 2L more, and a
 * taut tether would hold k y dy of energy no force paid for (measured: 4.4%
 * of a slow strike's energy by 0.3 s with steps of 1.7 ms, 0.25% with 0.5
 * ms). The glue draws out that much instead (glue is a viscoelastic liquid
 * that flows, Sahni et al. 2010). A tether the solver held slack, or did not
 * have, takes up what it stretched without pulling the same way. */
static void tethers_follow(spn_impact *im, const spn_world *w, const spn_vec3 *x1)
{
    uint32_t n;
    const spn_contact *wc = spn_world_contacts(w, &n);
    for (int i = 0; i < im->ntethers; i++) {
        spn__tether *t = &im->tethers[i];
        uint32_t a = im->sa[t->s], b = im->sb[t->s], p = im->prey[t->prey];
        spn_vec3 q = spn_v3_add(x1[a], spn_v3_scale(spn_v3_sub(x1[b], x1[a]), t->u));
        double len = spn_v3_len(spn_v3_sub(x1[p], q));
        if (t->slot < 0 || (uint32_t)t->slot >= n || !wc[t->slot].active) {
            t->rest = fmax(t->rest, len);
            continue;
        }
        const spn_contact *c = &im->cl[t->slot];
        spn_vec3 dg = spn_v3_sub(spn_v3_sub(x1[p], im->x0[p]),
                                 spn_v3_add(spn_v3_scale(spn_v3_sub(x1[a], im->x0[a]), 1 - c->u),
                                            spn_v3_scale(spn_v3_sub(x1[b], im->x0[b]), c->u)));
        double y1 = c->depth - spn_v3_dot(c->n, dg);
        t->rest = len + fmin(y1, 0);
    }
}

double spn__impact_solver_loss(spn_impact *im, const spn_world *w)
{
    if (!im->listed) return 0;
    const spn_vec3 *x1 = spn_world_positions(w), *v1 = spn_world_velocities(w);
    double loss = 0;
    for (uint32_t i = 0; i < im->np; i++) {
        if (spn_world_is_fixed(w, i)) continue;
        spn_vec3 dv = spn_v3_sub(v1[i], im->v0[i]);
        loss += 0.5 * spn_world_mass(w, i) * spn_v3_dot(dv, dv);
    }
    double sl = springs_loss(im, x1), cl = contacts_loss(im, w, x1);
    tethers_follow(im, w, x1);
    return loss + sl + cl;
}

/* The step schedule near prey (docs/wind-and-prey.md, "Contact step
 * schedule"): how far a step may carry a prey among the threads it touches
 * or nears.
 *
 * A contact's normal is frozen over a step while the thread slides over the
 * curved sphere: at a tenth of a radius of travel per step that missed
 * curvature made 13-18% of a slow strike's energy on the small Araneus web;
 * at 3% it is 1%. So:
 * - touching a thread (closer than R) or glued: 3% of R at the prey's own
 *   speed. Not its speed relative to the threads: those it drags move with
 *   it, the steps grew to the frame's substep while the strike still loaded
 *   the web, and the slow strike's ledger missed 2-9% (at the turn-around,
 *   where silk's hysteresis changes sign within a long step); nor a speed
 *   that fades below a few cm/s (a prey carried by the swaying web): 1.5-2.7%.
 *   The prey's own speed gives 0.02%;
 * - each thread closing in: max(3% of R, 0.8 of its gap) at the closing
 *   speed, so a contact is found at most 3% of a radius deep;
 * - threads it moves away from: no limit. A prey that bounced off or went
 *   through flies on at the frame's steps, even inside the web's box (the
 *   box rule before kept its steps fine as long as it was near the web). */
#define CONTACT_TRAVEL 0.03 /* of a radius, per step */
#define GAP_FRACTION 0.8    /* of an approaching thread's gap, per step */

static double prey_step(const spn_impact *im, const spn_vec3 *x, const spn_vec3 *v, int p, double dt)
{
    const uint32_t ip = im->prey[p];
    const spn_vec3 c = x[ip], vp = v[ip];
    const double R = im->radius[p], fine = CONTACT_TRAVEL * R;
    double limit = dt;
    bool touching = false;
    for (int i = 0; i < im->ntethers && !touching; i++) touching = im->tethers[i].prey == p;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        double u;
        spn_vec3 r;
        double d2 = spn__impact_closest(im, s, x, c, &u, &r);
        if (d2 <= 1e-30) continue; /* no normal: not a contact (list_segments) */
        double d = sqrt(d2);
        if (d < R) {
            touching = true;
            continue;
        }
        spn_vec3 vq = spn_v3_add(spn_v3_scale(v[im->sa[s]], 1 - u), spn_v3_scale(v[im->sb[s]], u));
        double closing = -spn_v3_dot(spn_v3_sub(vp, vq), r) / d, reach = fmax(fine, GAP_FRACTION * (d - R));
        if (closing * limit > reach) limit = reach / closing;
    }
    double speed = touching ? spn_v3_len(vp) : 0;
    return speed * limit > fine ? fine / speed : limit;
}

double spn_impact_step_limit(const spn_impact *im, const spn_world *w, double dt)
{
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    double limit = dt;
    for (int p = 0; p < im->nprey; p++) limit = fmin(limit, prey_step(im, x, v, p, limit));
    return limit;
}

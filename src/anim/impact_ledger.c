/* The impact's energy ledger and report: see impact.c for the balance it
 * keeps. Powers are evaluated on the state after each step and integrated by
 * the trapezoid rule. */
#include "impact_internal.h"

#include <math.h>
#include <string.h>

/* ---- the energy ledger ---------------------------------------------------- */

/* Elastic energy per kind into im->elastic and damping power per kind into
 * damp[], for the state (x, v). */
static void spring_energies(spn_impact *im, const spn_world *w, const spn_vec3 *x, const spn_vec3 *v, double *damp)
{
    for (int i = 0; i < SPN_KIND_SLOTS; i++) im->elastic[i] = damp[i] = 0;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        uint32_t a = im->sa[s], b = im->sb[s];
        spn_vec3 l = spn_v3_sub(x[a], x[b]);
        double len = spn_v3_len(l), d = len - im->rest[s];
        if ((d < 0 && im->tension_only[s]) || len <= 0) continue;
        /* backward Euler's damping acts along the direction at the step's start */
        spn_vec3 dir = l;
        if (im->listed) dir = spn_v3_sub(im->x0[a], im->x0[b]);
        double dlen = spn_v3_len(dir), rate = dlen > 0 ? spn_v3_dot(spn_v3_sub(v[a], v[b]), dir) / dlen : 0;
        im->elastic[im->slot[s]] += 0.5 * im->k[s] * d * d;
        /* the coefficient of the last step: kd plus silk's hysteresis */
        damp[im->slot[s]] += spn_world_spring_damping(w, s) * rate * rate;
    }
}

static double wind_power(spn_impact *im, const spn_world *w, const spn_vec3 *x, const spn_vec3 *v)
{
    if (!im->wind_fn) return 0;
    memset(im->fbuf, 0, im->np * sizeof *im->fbuf);
    im->wind_fn(im->wind_user, w, spn_world_time(w), x, v, im->fbuf);
    double p = 0;
    for (uint32_t i = 0; i < im->np; i++)
        if (!spn_world_is_fixed(w, i)) p += spn_v3_dot(im->fbuf[i], v[i]);
    return p;
}

static double viscous_power(const spn_world *w, const spn_vec3 *v)
{
    double drag = spn_world_get_def(w)->drag, p = 0;
    if (drag == 0) return 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i)) p += drag * spn_world_mass(w, i) * spn_v3_dot(v[i], v[i]);
    return p;
}

/* Kinetic + gravitational + elastic (im->elastic, already computed) + contact. */
static double mechanical(spn_impact *im, const spn_world *w, const spn_vec3 *x)
{
    spn_energy e = spn_world_energy(w);
    double total = e.kinetic + e.gravitational;
    if (!im->def.prey_gravity) /* lift cancels gravity: the prey has no potential energy */
        for (int p = 0; p < im->nprey; p++)
            total += spn_world_mass(w, im->prey[p]) * spn_v3_dot(spn_world_get_def(w)->gravity, x[im->prey[p]]);
    for (int i = 0; i < SPN_KIND_SLOTS; i++) total += im->elastic[i];
    im->contact = spn__impact_contact(im, x, NULL);
    return total + im->contact;
}

static double prey_kinetic(const spn_impact *im, const spn_world *w)
{
    double e = 0;
    for (int p = 0; p < im->nprey; p++) {
        spn_vec3 v = spn_world_velocity(w, im->prey[p]);
        e += 0.5 * spn_world_mass(w, im->prey[p]) * spn_v3_dot(v, v);
    }
    return e;
}

void spn__impact_ledger_start(spn_impact *im, const spn_world *w)
{
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    spring_energies(im, w, x, v, im->damp_prev);
    memcpy(im->elastic0, im->elastic, sizeof im->elastic0);
    im->viscous_prev = viscous_power(w, v);
    im->total0 = mechanical(im, w, x);
    im->prey_ke0 = prey_kinetic(im, w);
    /* Air and wind are attached after creation; the web starts at rest, where
     * their power is zero. */
    im->air_prev = im->wind_prev = 0;
}

static void check_strike(spn_impact *im, spn_world *w);

void spn_impact_after_step(spn_impact *im, spn_world *w, double dt)
{
    /* Before yielding moves rest lengths: the loss is the step's. */
    im->solver += spn__impact_solver_loss(im, w);
    spn__impact_yield(im, w);
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    double damp[SPN_KIND_SLOTS];
    spring_energies(im, w, x, v, damp);
    /* Backward Euler's forces act at the step's end (rectangle rule), the
     * explicit solvers' between (trapezoid). */
    const double a = im->listed ? 0 : 0.5 * dt, b = dt - a;
    for (int i = 0; i < SPN_KIND_SLOTS; i++) {
        im->kinds[i].damping += a * im->damp_prev[i] + b * damp[i];
        im->damp_prev[i] = damp[i];
    }
    double pv = viscous_power(w, v), pa = spn_world_air_power(w), pw = wind_power(im, w, x, v);
    im->viscous += a * im->viscous_prev + b * pv;
    im->air_work += a * im->air_prev + b * pa;
    im->wind_work += a * im->wind_prev + b * pw;
    im->listed = false;
    im->viscous_prev = pv;
    spn__impact_glue_update(im, w);
    for (int p = 0; p < im->nprey; p++)
        if (im->touched[p] && !im->hit_known[p]) {
            im->hit_known[p] = true;
            im->hit[p] = x[im->prey[p]];
        }
    check_strike(im, w);
    im->air_prev = pa;
    im->wind_prev = pw;
}

/* Stopped, passed through, bounced or missed: compare the prey with the web
 * along its initial direction of flight. */
static spn_prey_outcome outcome(const spn_impact *im, const spn_world *w, int p);

/* The strike is over when every prey that touched the web has been arrested
 * (its speed along its flight no longer positive) or has gone through; the
 * prey that never touched do not hold it up once the others are done. */
static void check_strike(spn_impact *im, spn_world *w)
{
    if (im->strike_done) return;
    int touched = 0;
    for (int p = 0; p < im->nprey; p++) {
        if (!im->touched[p]) continue;
        touched++;
        double along = spn_v3_dot(spn_world_velocity(w, im->prey[p]), im->dir0[p]);
        if (along > 0 && outcome(im, w, p) != SPN_PREY_PASSED) return;
    }
    if (!touched) return;
    im->strike_done = true;
    im->strike_time = spn_world_time(w);
    spn_impact_report_get(im, w, &im->strike);
}

/* Held: a thread inside the prey's sphere or a glue droplet on it. */
static spn_prey_outcome outcome(const spn_impact *im, const spn_world *w, int p)
{
    if (!im->touched[p]) return SPN_PREY_MISSED;
    spn_vec3 c = spn_world_position(w, im->prey[p]), n = im->dir0[p];
    double R = im->radius[p], lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < im->ntethers; i++)
        if (im->tethers[i].prey == p) return SPN_PREY_HELD;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        double u;
        spn_vec3 r;
        if (spn__impact_closest(im, s, spn_world_positions(w), c, &u, &r) < R * R) return SPN_PREY_HELD;
    }
    for (uint32_t i = 0; i < im->np; i++) {
        if (spn_world_particle_tag(w, i) == SPN_PARTICLE_PREY) continue;
        double d = spn_v3_dot(spn_world_position(w, i), n);
        lo = fmin(lo, d);
        hi = fmax(hi, d);
    }
    double along = spn_v3_dot(c, n), vel = spn_v3_dot(spn_world_velocity(w, im->prey[p]), n);
    if (along > hi + R && vel > 0) return SPN_PREY_PASSED;
    if (along < lo - R && vel < 0) return SPN_PREY_BOUNCED;
    /* Touching nothing inside the web's extent along its flight but still
     * flying at half its first speed or more: not arrested. Threads torn
     * loose trail a prey that tore through, and the extent moves with them
     * (an 8 m/s prey through the physical web, test_anim_impact). */
    if (fabs(vel) >= 0.5 * im->speed0[p]) return vel > 0 ? SPN_PREY_PASSED : SPN_PREY_BOUNCED;
    return SPN_PREY_STOPPED;
}

void spn_impact_report_get(spn_impact *im, const spn_world *w, spn_impact_report *r)
{
    memset(r, 0, sizeof *r);
    r->nprey = im->nprey;
    for (int p = 0; p < im->nprey; p++) r->outcome[p] = outcome(im, w, p);
    r->prey_kinetic_start = im->prey_ke0;
    r->prey_kinetic_end = prey_kinetic(im, w);
    r->total_start = im->total0;
    double damp[SPN_KIND_SLOTS];
    spring_energies(im, w, spn_world_positions(w), spn_world_velocities(w), damp);
    r->total_now = mechanical(im, w, spn_world_positions(w));
    r->air_work = im->air_work;
    r->wind_work = im->wind_work;
    r->viscous = im->viscous;
    r->contact_energy = im->contact;
    r->web_kinetic = spn_world_energy(w).kinetic - r->prey_kinetic_end;
    r->breaks = im->breaks;
    r->web_radius = im->web_radius;
    r->break_distance_max = im->break_dist_max;
    r->break_distance_mean = im->breaks ? im->break_dist_sum / im->breaks : 0;
    r->nkinds = im->nkinds;
    r->glue = im->glue_lost;
    r->glue_held = im->ntethers;
    for (int i = 0; i < im->ntethers; i++) r->glue_strength_held += im->tethers[i].strength;
    r->solver = im->solver;
    double lost = im->viscous + im->glue_lost + im->solver;
    for (int i = 0; i < im->nkinds; i++) {
        r->kinds[i] = im->kinds[i];
        r->kinds[i].elastic = im->elastic[i] - im->elastic0[i];
        lost += r->kinds[i].damping + r->kinds[i].broken + r->kinds[i].plastic;
    }
    r->strike_time = im->strike_done ? im->strike_time : -1;
    if (im->strike_done) {
        r->strike_prey_kinetic_lost = im->strike.prey_kinetic_start - im->strike.prey_kinetic_end;
        r->strike_air = -im->strike.air_work;
        r->strike_web_kinetic = im->strike.web_kinetic;
        r->strike_glue = im->strike.glue;
        for (int i = 0; i < im->strike.nkinds; i++) {
            const spn_kind_energy *k = &im->strike.kinds[i];
            r->strike_absorbed[i] = k->elastic + k->damping + k->plastic + k->broken;
        }
    }
    r->balance_error = fabs(r->total_now + lost - r->air_work - r->wind_work - r->total_start);
}

/* Prey striking the web: a sphere (one particle of the world, so every solver
 * moves it) in contact with thread segments, and the thread breakage it causes.
 *
 * Contact: for each intact segment ab, the closest point q = a + u (b - a),
 * u in [0, 1], to the sphere's centre c; when |c - q| = d < R a penalty force
 * F = kc (R - d) n, n = (c - q) / d, pushes the sphere and -F is shared by the
 * ends as (1 - u) and u. This is the gradient of the potential kc (R - d)^2 / 2
 * (u minimises the distance, so its variation does not enter), hence
 * conservative and frictionless: threads slide over the sphere. Contact is
 * with segments, not only particles, so a sphere cannot slip between the
 * particles of a thread.
 *
 * Breakage: each thread kind breaks at its strain (web_util.c); the world
 * does the breaking (break_max) and tells us through its break callback.
 *
 * The energy ledger (spn_impact_after_step) follows what becomes of the prey's
 * kinetic energy: elastic energy per thread kind, dissipation by the springs'
 * damping per kind (kd (l' . l/|l|)^2 integrated by the trapezoid rule over
 * the steps), elastic energy lost when a spring breaks, work of the air on the
 * threads (the drag formula of world.h evaluated on the segments) and of any
 * wind force, and the contact potential. The balance
 *   E(t) + damping + broken - air work - wind work = E(0)
 * holds to the integrator's accuracy: its residual is the report's
 * balance_error. */
#include "anim_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PREY 8

struct spn_impact {
    spn_impact_def def;
    int nprey;
    uint32_t prey[MAX_PREY];
    double radius[MAX_PREY];
    spn_vec3 dir0[MAX_PREY];
    bool touched[MAX_PREY];
    double kc;
    /* springs, cached at creation (the graph does not change) */
    uint32_t ns, np;
    uint32_t *sa, *sb;
    double *k, *kd, *rest, *diam;
    uint8_t *tension_only, *broken, *slot;
    /* ledger */
    int nkinds;
    spn_kind_energy kinds[SPN_KIND_SLOTS];
    double elastic0[SPN_KIND_SLOTS], elastic[SPN_KIND_SLOTS], damp_prev[SPN_KIND_SLOTS];
    double viscous, viscous_prev;
    double air_prev, wind_prev, air_work, wind_work;
    double total0, prey_ke0, contact;
    uint32_t breaks;
    spn_air_fn air_fn;
    void *air_user;
    double rho, mu;
    spn_force_fn wind_fn;
    void *wind_user;
    spn_vec3 *fbuf;
};

spn_impact_def spn_impact_def_default(void)
{
    spn_impact_def d;
    d.contact_stiffness = 0;
    d.breaking_scale = 1;
    d.breakage = true;
    return d;
}

const char *spn_prey_outcome_name(spn_prey_outcome outcome)
{
    static const char *const names[] = {"missed", "stopped", "passed_through", "bounced"};
    return (unsigned)outcome < 4 ? names[outcome] : "unknown";
}

double spn_impact_contact_stiffness(const spn_impact *impact) { return impact->kc; }

uint32_t spn_impact_prey_particle(const spn_impact *impact, int i) { return impact->prey[i]; }

static int slot_of(spn_impact *im, uint32_t tag)
{
    for (int i = 0; i < im->nkinds; i++)
        if (im->kinds[i].tag == tag) return i;
    if (im->nkinds == SPN_KIND_SLOTS) return SPN_KIND_SLOTS - 1; /* shared overflow slot */
    im->kinds[im->nkinds].tag = tag;
    return im->nkinds++;
}

static spn_status cache_springs(spn_impact *im, const spn_world *w)
{
    uint32_t ns = spn_world_spring_count(w);
    im->ns = ns;
    im->np = spn_world_particle_count(w);
    im->sa = malloc(ns * sizeof *im->sa + 1);
    im->sb = malloc(ns * sizeof *im->sb + 1);
    im->k = malloc(ns * sizeof *im->k + 1);
    im->kd = malloc(ns * sizeof *im->kd + 1);
    im->rest = malloc(ns * sizeof *im->rest + 1);
    im->diam = malloc(ns * sizeof *im->diam + 1);
    im->tension_only = malloc(ns + 1);
    im->broken = malloc(ns + 1);
    im->slot = malloc(ns + 1);
    im->fbuf = malloc(im->np * sizeof *im->fbuf + 1);
    if (!im->sa || !im->sb || !im->k || !im->kd || !im->rest || !im->diam || !im->tension_only || !im->broken ||
        !im->slot || !im->fbuf)
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    double kmax = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info in = spn_world_spring(w, s);
        im->sa[s] = in.a;
        im->sb[s] = in.b;
        im->k[s] = in.k;
        im->kd[s] = in.kd;
        im->rest[s] = in.rest;
        im->diam[s] = spn_thread_diameter(in.tag);
        im->tension_only[s] = in.tension_only;
        im->broken[s] = in.broken;
        im->slot[s] = (uint8_t)slot_of(im, in.tag);
        if (!in.broken) kmax = fmax(kmax, in.k);
    }
    im->kc = im->def.contact_stiffness > 0 ? im->def.contact_stiffness : (kmax > 0 ? kmax : 1);
    return SPN_OK;
}

static void on_break(void *user, uint32_t s, double t, double length)
{
    (void)t;
    spn_impact *im = user;
    if (s >= im->ns || im->broken[s]) return;
    im->broken[s] = 1;
    double d = length - im->rest[s];
    spn_kind_energy *ke = &im->kinds[im->slot[s]];
    if (d > 0 || !im->tension_only[s]) ke->broken += 0.5 * im->k[s] * d * d;
    ke->breaks++;
    im->breaks++;
}

spn_status spn_prey_parse(const char *text, spn_prey_def *out)
{
    double v[8];
    char tail;
    if (!text || sscanf(text, "%lf,%lf,%lf;%lf,%lf,%lf;%lf;%lf%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                        &v[7], &tail) != 8)
        return spn_error(SPN_ERR_INVALID, "impact '%s': expected \"x,y,z;vx,vy,vz;mass;radius\"", text ? text : "");
    for (int i = 0; i < 8; i++)
        if (!isfinite(v[i])) return spn_error(SPN_ERR_INVALID, "impact '%s': values must be finite", text);
    if (!(v[6] > 0)) return spn_error(SPN_ERR_INVALID, "impact '%s': mass must be > 0", text);
    if (!(v[7] > 0)) return spn_error(SPN_ERR_INVALID, "impact '%s': radius must be > 0", text);
    out->position = spn_v3(v[0], v[1], v[2]);
    out->velocity = spn_v3(v[3], v[4], v[5]);
    out->mass = v[6];
    out->radius = v[7];
    return SPN_OK;
}

static spn_status add_prey(spn_impact *im, spn_world *w, const spn_prey_def *prey, int nprey)
{
    for (int i = 0; i < nprey; i++) {
        if (!(prey[i].mass > 0) || !(prey[i].radius > 0) || !spn_v3_finite(prey[i].position) ||
            !spn_v3_finite(prey[i].velocity))
            return spn_error(SPN_ERR_INVALID, "impact %d: mass and radius must be > 0, vectors finite", i + 1);
        spn_particle_def p = spn_particle_def_default();
        p.position = prey[i].position;
        p.velocity = prey[i].velocity;
        p.mass = prey[i].mass;
        p.tag = SPN_PARTICLE_PREY;
        spn_status st = spn_world_add_particle(w, &p, &im->prey[i]);
        if (st != SPN_OK) return st;
        im->radius[i] = prey[i].radius;
        im->dir0[i] = spn_v3_norm(prey[i].velocity);
    }
    im->nprey = nprey;
    return SPN_OK;
}

static void ledger_start(spn_impact *im, const spn_world *w);

spn_status spn_impact_create(spn_world **w, const spn_prey_def *prey, int nprey, const spn_impact_def *def,
                             spn_impact **out)
{
    *out = NULL;
    if (nprey < 0 || nprey > MAX_PREY) return spn_error(SPN_ERR_INVALID, "impact: at most %d prey", MAX_PREY);
    spn_impact *im = calloc(1, sizeof *im);
    if (!im) return spn_error(SPN_ERR_NOMEM, "out of memory");
    im->def = def ? *def : spn_impact_def_default();
    spn_status st = SPN_OK;
    if (!(im->def.breaking_scale > 0) || !(im->def.contact_stiffness >= 0))
        st = spn_error(SPN_ERR_INVALID, "impact: breaking scale must be > 0 and contact stiffness >= 0");
    if (st == SPN_OK && im->def.breakage) {
        spn_world *copy = NULL;
        st = spn__world_with_breaks(*w, im->def.breaking_scale, &copy);
        if (st == SPN_OK) {
            spn_world_destroy(*w);
            *w = copy;
        }
    }
    if (st == SPN_OK) st = add_prey(im, *w, prey, nprey);
    if (st == SPN_OK) st = cache_springs(im, *w);
    if (st != SPN_OK) {
        spn_impact_destroy(im);
        return st;
    }
    spn_world_set_break_callback(*w, on_break, im);
    ledger_start(im, *w);
    *out = im;
    return SPN_OK;
}

void spn_impact_destroy(spn_impact *im)
{
    if (!im) return;
    free(im->sa);
    free(im->sb);
    free(im->k);
    free(im->kd);
    free(im->rest);
    free(im->diam);
    free(im->tension_only);
    free(im->broken);
    free(im->slot);
    free(im->fbuf);
    free(im);
}

/* Closest point of segment s to c: returns squared distance, u and the offset c - q. */
static double closest(const spn_impact *im, uint32_t s, const spn_vec3 *x, spn_vec3 c, double *u, spn_vec3 *r)
{
    spn_vec3 a = x[im->sa[s]], ab = spn_v3_sub(x[im->sb[s]], a);
    double l2 = spn_v3_dot(ab, ab), t = l2 > 0 ? spn_v3_dot(spn_v3_sub(c, a), ab) / l2 : 0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    *u = t;
    *r = spn_v3_sub(c, spn_v3_add(a, spn_v3_scale(ab, t)));
    return spn_v3_dot(*r, *r);
}

/* Contact forces into f (when f is not NULL); returns the contact potential. */
static double contact(spn_impact *im, const spn_vec3 *x, spn_vec3 *f)
{
    double energy = 0;
    for (int p = 0; p < im->nprey; p++) {
        spn_vec3 c = x[im->prey[p]];
        double R = im->radius[p];
        for (uint32_t s = 0; s < im->ns; s++) {
            if (im->broken[s]) continue;
            double u;
            spn_vec3 r;
            double d2 = closest(im, s, x, c, &u, &r);
            if (d2 >= R * R || d2 <= 1e-30) continue;
            double d = sqrt(d2), depth = R - d;
            energy += 0.5 * im->kc * depth * depth;
            if (!f) continue;
            im->touched[p] = true;
            spn_vec3 F = spn_v3_scale(r, im->kc * depth / d);
            f[im->prey[p]] = spn_v3_add(f[im->prey[p]], F);
            f[im->sa[s]] = spn_v3_sub(f[im->sa[s]], spn_v3_scale(F, 1 - u));
            f[im->sb[s]] = spn_v3_sub(f[im->sb[s]], spn_v3_scale(F, u));
        }
    }
    return energy;
}

void spn_impact_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)w;
    (void)t;
    (void)v;
    contact(user, x, f);
}

void spn_impact_track_air(spn_impact *im, spn_air_fn fn, void *user, double rho, double mu)
{
    im->air_fn = fn;
    im->air_user = user;
    im->rho = rho;
    im->mu = mu;
}

void spn_impact_track_wind(spn_impact *im, spn_force_fn fn, void *user)
{
    im->wind_fn = fn;
    im->wind_user = user;
}


/* ---- the energy ledger ---------------------------------------------------- */

/* Elastic energy per kind into im->elastic and damping power per kind into
 * damp[], for the state (x, v). */
static void spring_energies(spn_impact *im, const spn_vec3 *x, const spn_vec3 *v, double *damp)
{
    for (int i = 0; i < SPN_KIND_SLOTS; i++) im->elastic[i] = damp[i] = 0;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        uint32_t a = im->sa[s], b = im->sb[s];
        spn_vec3 l = spn_v3_sub(x[a], x[b]);
        double len = spn_v3_len(l), d = len - im->rest[s];
        if ((d < 0 && im->tension_only[s]) || len <= 0) continue;
        double rate = spn_v3_dot(spn_v3_sub(v[a], v[b]), l) / len;
        im->elastic[im->slot[s]] += 0.5 * im->k[s] * d * d;
        damp[im->slot[s]] += im->kd[s] * rate * rate;
    }
}

/* Power of the air drag on the threads (world.h's formula on each segment,
 * half the force to each end): positive when the air drives the web. */
static double air_power(const spn_impact *im, const spn_world *w, const spn_vec3 *x, const spn_vec3 *v)
{
    if (!im->air_fn) return 0;
    double p = 0, t = spn_world_time(w);
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s] || !(im->diam[s] > 0)) continue;
        uint32_t a = im->sa[s], b = im->sb[s];
        spn_vec3 l = spn_v3_sub(x[b], x[a]);
        double len = spn_v3_len(l);
        if (len <= 0) continue;
        spn_vec3 e = spn_v3_scale(l, 1 / len), mid = spn_v3_scale(spn_v3_add(x[a], x[b]), 0.5);
        spn_vec3 vm = spn_v3_scale(spn_v3_add(v[a], v[b]), 0.5);
        spn_vec3 u = spn_v3_sub(im->air_fn(im->air_user, t, mid), vm);
        spn_vec3 un = spn_v3_sub(u, spn_v3_scale(e, spn_v3_dot(u, e)));
        double speed = spn_v3_len(un), re = im->rho * speed * im->diam[s] / im->mu;
        double mag = 0.5 * im->rho * spn_cylinder_drag_coefficient(re) * im->diam[s] * len * speed;
        double pa = spn_world_is_fixed(w, a) ? 0 : 0.5 * spn_v3_dot(un, v[a]);
        double pb = spn_world_is_fixed(w, b) ? 0 : 0.5 * spn_v3_dot(un, v[b]);
        p += mag * (pa + pb);
    }
    return p;
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
    for (int i = 0; i < SPN_KIND_SLOTS; i++) total += im->elastic[i];
    im->contact = contact(im, x, NULL);
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

static void ledger_start(spn_impact *im, const spn_world *w)
{
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    spring_energies(im, x, v, im->damp_prev);
    memcpy(im->elastic0, im->elastic, sizeof im->elastic0);
    im->viscous_prev = viscous_power(w, v);
    im->total0 = mechanical(im, w, x);
    im->prey_ke0 = prey_kinetic(im, w);
    /* Air and wind are attached after creation; the web starts at rest, where
     * their power is zero. */
    im->air_prev = im->wind_prev = 0;
}

void spn_impact_after_step(spn_impact *im, const spn_world *w, double dt)
{
    const spn_vec3 *x = spn_world_positions(w), *v = spn_world_velocities(w);
    double damp[SPN_KIND_SLOTS];
    spring_energies(im, x, v, damp);
    for (int i = 0; i < SPN_KIND_SLOTS; i++) {
        im->kinds[i].damping += 0.5 * dt * (im->damp_prev[i] + damp[i]);
        im->damp_prev[i] = damp[i];
    }
    double pv = viscous_power(w, v), pa = air_power(im, w, x, v), pw = wind_power(im, w, x, v);
    im->viscous += 0.5 * dt * (im->viscous_prev + pv);
    im->air_work += 0.5 * dt * (im->air_prev + pa);
    im->wind_work += 0.5 * dt * (im->wind_prev + pw);
    im->viscous_prev = pv;
    im->air_prev = pa;
    im->wind_prev = pw;
}

/* Stopped, passed through, bounced or missed: compare the prey with the web
 * along its initial direction of flight. */
static spn_prey_outcome outcome(const spn_impact *im, const spn_world *w, int p)
{
    if (!im->touched[p]) return SPN_PREY_MISSED;
    spn_vec3 c = spn_world_position(w, im->prey[p]), n = im->dir0[p];
    double R = im->radius[p], lo = INFINITY, hi = -INFINITY;
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        double u;
        spn_vec3 r;
        if (closest(im, s, spn_world_positions(w), c, &u, &r) < R * R) return SPN_PREY_STOPPED;
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
    spring_energies(im, spn_world_positions(w), spn_world_velocities(w), damp);
    r->total_now = mechanical(im, w, spn_world_positions(w));
    r->air_work = im->air_work;
    r->wind_work = im->wind_work;
    r->viscous = im->viscous;
    r->contact_energy = im->contact;
    r->breaks = im->breaks;
    r->nkinds = im->nkinds;
    double lost = im->viscous;
    for (int i = 0; i < im->nkinds; i++) {
        r->kinds[i] = im->kinds[i];
        r->kinds[i].elastic = im->elastic[i] - im->elastic0[i];
        lost += r->kinds[i].damping + r->kinds[i].broken;
    }
    r->balance_error = fabs(r->total_now + lost - r->air_work - r->wind_work - r->total_start);
}

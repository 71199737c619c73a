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
 * Glue: once a prey has touched the web, capture thread within its sticky
 * outline (legs, wings: glue_outline radii) is tethered to it, with a
 * strength of the adhesion per length of thread in the outline (Opell &
 * Hendricks 2009); a tether pulled past it lets go and its stretch energy is
 * the ledger's glue term. Tethers are what hold a caught prey (glue_segment,
 * spn__impact_glue_update; docs/wind-and-prey.md, "Capture").
 *
 * The energy ledger (spn_impact_after_step) follows what becomes of the prey's
 * kinetic energy: elastic energy per thread kind, dissipation by the springs'
 * damping per kind (kd (l' . l/|l|)^2 integrated by the trapezoid rule over
 * the steps), elastic energy lost when a spring breaks, work of the air on the
 * threads (the world's own drag, spn_world_air_power) and of any wind force,
 * and the contact potential. The balance
 *   E(t) + damping + broken - air work - wind work = E(0)
 * holds to the integrator's accuracy: its residual is the report's
 * balance_error. */
#include "impact_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Glue is soft: it draws out about a millimetre before it lets go at its
 * strength (droplets extend several times their size, Opell & Hendricks
 * 2007); our assumption of the length. */
#define SPN_GLUE_STRETCH 1e-3 /* [m] */

spn_impact_def spn_impact_def_default(void)
{
    spn_impact_def d;
    d.contact_stiffness = 0;
    d.breaking_scale = 1;
    d.breakage = true;
    d.prey_gravity = false;
    d.plastic = true;
    d.glue_strength = 4e-5;
    d.glue_adhesion = 0.05;
    d.hysteresis = true;
    d.glue_outline = 2.5;
    return d;
}

const char *spn_prey_outcome_name(spn_prey_outcome outcome)
{
    static const char *const names[] = {"missed", "stopped", "passed_through", "bounced", "held"};
    return (unsigned)outcome < 5 ? names[outcome] : "unknown";
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
    im->tension_only = malloc(ns + 1);
    im->broken = malloc(ns + 1);
    im->slot = malloc(ns + 1);
    im->tag = malloc(ns * sizeof *im->tag + 1);
    im->rest0 = malloc(ns * sizeof *im->rest0 + 1);
    im->len0 = malloc(ns * sizeof *im->len0 + 1);
    im->fbuf = malloc(im->np * sizeof *im->fbuf + 1);
    im->x0 = malloc(im->np * sizeof *im->x0 + 1);
    im->v0 = malloc(im->np * sizeof *im->v0 + 1);
    im->coff = malloc((size_t)(im->nprey ? im->nprey : 1) * ns * sizeof *im->coff + 1);
    im->cend = malloc((size_t)(im->nprey ? im->nprey : 1) * ns * sizeof *im->cend + 1);
    if (!im->x0 || !im->v0 || !im->coff || !im->cend) return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < (size_t)im->nprey * ns; i++) im->coff[i] = im->cend[i] = -1;
    if (!im->sa || !im->sb || !im->k || !im->kd || !im->rest || !im->tension_only || !im->broken ||
        !im->slot || !im->tag || !im->rest0 || !im->len0 || !im->fbuf)
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    double kmax = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info in = spn_world_spring(w, s);
        im->sa[s] = in.a;
        im->sb[s] = in.b;
        im->k[s] = in.k;
        im->kd[s] = in.kd;
        im->rest[s] = in.rest;
        im->rest0[s] = in.rest;
        im->len0[s] = in.length;
        im->tension_only[s] = in.tension_only;
        im->broken[s] = in.broken;
        im->slot[s] = (uint8_t)slot_of(im, in.tag);
        im->tag[s] = in.tag;
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
    /* How far from the strike the damage is (Cranford et al. 2012: local). */
    const spn_vec3 *x = spn_world_positions(im->world);
    spn_vec3 mid = spn_v3_scale(spn_v3_add(x[im->sa[s]], x[im->sb[s]]), 0.5);
    double best = INFINITY;
    for (int p = 0; p < im->nprey; p++)
        if (im->hit_known[p]) best = fmin(best, spn_v3_len(spn_v3_sub(mid, im->hit[p])));
    if (isfinite(best)) {
        im->break_dist_max = fmax(im->break_dist_max, best);
        im->break_dist_sum += best;
    }
}

spn_status spn_prey_parse(const char *text, spn_prey_def *out)
{
    double v[8];
    char tail;
    if (!text || sscanf(text, "%lf,%lf,%lf;%lf,%lf,%lf;%lf;%lf%c", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                        &v[7], &tail) != 8)
        return spn_error(SPN_ERR_INVALID, "impact '%s': expected \"x,y,z;vx,vy,vz;mass;radius\"", text ? text : "");
    /* Ranges wide enough for any prey, narrow enough that the contact's time
     * step stays usable: a 1e-300 kg speck made the run take forever, and
     * 1e300 m/s blew it up at the first step. */
    static const struct { const char *what; double lo, hi; } range[] = {
        {"position [m]", -1e6, 1e6}, {"velocity [m/s]", -1e3, 1e3}, {"mass [kg]", 1e-9, 100}, {"radius [m]", 1e-6, 10}};
    for (int i = 0; i < 8; i++) {
        int r = i < 3 ? 0 : i < 6 ? 1 : i - 4;
        if (!(v[i] >= range[r].lo && v[i] <= range[r].hi))
            return spn_error(SPN_ERR_INVALID, "impact '%s': %s must be in [%g, %g], got %g", text, range[r].what,
                             range[r].lo, range[r].hi, v[i]);
    }
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
        im->speed0[i] = spn_v3_len(prey[i].velocity);
    }
    im->nprey = nprey;
    return SPN_OK;
}

spn_status spn_impact_create(spn_world **w, const spn_prey_def *prey, int nprey, const spn_impact_def *def,
                             spn_impact **out)
{
    *out = NULL;
    if (nprey < 0 || nprey > MAX_PREY) return spn_error(SPN_ERR_INVALID, "impact: at most %d prey", MAX_PREY);
    spn_impact *im = calloc(1, sizeof *im);
    if (!im) return spn_error(SPN_ERR_NOMEM, "out of memory");
    im->def = def ? *def : spn_impact_def_default();
    spn_status st = SPN_OK;
    if (!(im->def.breaking_scale > 0) || !(im->def.contact_stiffness >= 0) || !(im->def.glue_strength >= 0) ||
        !(im->def.glue_adhesion >= 0))
        st = spn_error(SPN_ERR_INVALID, "impact: breaking scale must be > 0, contact stiffness and glue >= 0");
    else if (!(im->def.glue_outline >= 1 && im->def.glue_outline <= 100))
        st = spn_error(SPN_ERR_INVALID, "impact: glue outline must be in [1, 100] prey radii, got %g",
                       im->def.glue_outline);
    if (st == SPN_OK && im->def.breakage) {
        spn_world *copy = NULL;
        st = spn__world_with_breaks(*w, im->def.breaking_scale, &copy);
        if (st == SPN_OK) {
            spn_world_destroy(*w);
            *w = copy;
        }
    }
    /* Hysteresis as a stiff secant dashpot is for the implicit solver: an
     * explicit step would need it capped at m / (2 dt), most of it lost. */
    if (st == SPN_OK && im->def.hysteresis && spn_world_get_def(*w)->integrator == SPN_INTEGRATOR_IMPLICIT)
        for (uint32_t tag = 0; tag <= SPN_THREAD_SHOT && st == SPN_OK; tag++)
            if (spn_thread_hysteresis(tag) > 0)
                st = spn_world_set_tag_hysteresis(*w, tag, spn_thread_hysteresis(tag), SPN_HYSTERESIS_RATE);
    if (st == SPN_OK) st = add_prey(im, *w, prey, nprey);
    if (st == SPN_OK) st = cache_springs(im, *w);
    if (st != SPN_OK) {
        spn_impact_destroy(im);
        return st;
    }
    spn_world_set_break_callback(*w, on_break, im);
    im->world = *w;
    im->web_radius = spn__web_radius(*w, spn__hub_particle(*w));
    spn__impact_ledger_start(im, *w);
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
    free(im->tension_only);
    free(im->broken);
    free(im->slot);
    free(im->tag);
    free(im->rest0);
    free(im->len0);
    free(im->fbuf);
    free(im->x0);
    free(im->coff);
    free(im->cend);
    free(im->cseg);
    free(im->v0);
    free(im->cl);
    free(im);
}

/* Closest point of segment s to c: returns squared distance, u and the offset c - q. */
double spn__impact_closest(const spn_impact *im, uint32_t s, const spn_vec3 *x, spn_vec3 c, double *u, spn_vec3 *r)
{
    spn_vec3 a = x[im->sa[s]], ab = spn_v3_sub(x[im->sb[s]], a);
    double l2 = spn_v3_dot(ab, ab), t = l2 > 0 ? spn_v3_dot(spn_v3_sub(c, a), ab) / l2 : 0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    *u = t;
    *r = spn_v3_sub(c, spn_v3_add(a, spn_v3_scale(ab, t)));
    return spn_v3_dot(*r, *r);
}

static double tether_force(spn_impact *im, const spn__tether *t, const spn_vec3 *x, spn_vec3 *f)
{
    uint32_t a = im->sa[t->s], b = im->sb[t->s], p = im->prey[t->prey];
    spn_vec3 q = spn_v3_add(x[a], spn_v3_scale(spn_v3_sub(x[b], x[a]), t->u)), l = spn_v3_sub(x[p], q);
    double len = spn_v3_len(l), stretch = len - t->rest;
    if (stretch <= 0) return 0;
    if (f) {
        spn_vec3 F = spn_v3_scale(l, -t->k * stretch / len);
        f[p] = spn_v3_add(f[p], F);
        f[a] = spn_v3_sub(f[a], spn_v3_scale(F, 1 - t->u));
        f[b] = spn_v3_sub(f[b], spn_v3_scale(F, t->u));
    }
    return 0.5 * t->k * stretch * stretch;
}

double spn__impact_contact(spn_impact *im, const spn_vec3 *x, spn_vec3 *f)
{
    double energy = 0;
    for (int p = 0; p < im->nprey; p++) {
        spn_vec3 c = x[im->prey[p]];
        double R = im->radius[p];
        for (uint32_t s = 0; s < im->ns; s++) {
            if (im->broken[s]) continue;
            double u;
            spn_vec3 r;
            double d2 = spn__impact_closest(im, s, x, c, &u, &r);
            if (d2 >= R * R || d2 <= 1e-30) continue;
            double d = sqrt(d2), depth = R - d;
            if (im->offsets) depth = spn__impact_offset_depth(im, (size_t)p * im->ns + s, depth, false);
            if (depth <= 0) continue;
            energy += 0.5 * im->kc * depth * depth;
            if (!f) continue;
            im->touched[p] = true;
            spn_vec3 F = spn_v3_scale(r, im->kc * depth / d);
            f[im->prey[p]] = spn_v3_add(f[im->prey[p]], F);
            f[im->sa[s]] = spn_v3_sub(f[im->sa[s]], spn_v3_scale(F, 1 - u));
            f[im->sb[s]] = spn_v3_sub(f[im->sb[s]], spn_v3_scale(F, u));
        }
    }
    for (int i = 0; i < im->ntethers; i++) energy += tether_force(im, &im->tethers[i], x, f);
    return energy;
}

void spn__impact_yield(spn_impact *im, spn_world *w)
{
    if (!im->def.plastic) return;
    const spn_vec3 *x = spn_world_positions(w);
    for (uint32_t s = 0; s < im->ns; s++) {
        if (im->broken[s]) continue;
        double ey = spn_thread_yield_strain(im->tag[s]), r0 = im->rest0[s];
        if (!isfinite(ey)) continue;
        double len = spn_v3_len(spn_v3_sub(x[im->sa[s]], x[im->sb[s]]));
        /* A thread built past its yield strain (a web's frame and anchors
         * hold 7-10% in equilibrium) yielded while it was made: it yields
         * again only past the length it had then. */
        double ylen = fmax(r0 * (1 + ey), im->len0[s]), over = len - ylen;
        if (over <= 0) continue;
        /* force k (len - rest) on the post-yield line k (ylen - r0 + a over) */
        double rest = len - (ylen - r0) - SPN_POST_YIELD * over;
        if (rest <= im->rest[s]) continue;
        double d0 = len - im->rest[s], d1 = len - rest;
        im->kinds[im->slot[s]].plastic += 0.5 * im->k[s] * (d0 * d0 - d1 * d1);
        im->rest[s] = rest;
        spn_world_set_spring_rest(w, s, rest);
    }
}

static bool sticky(uint32_t tag) { return tag == SPN_THREAD_CAPTURE || tag == SPN_THREAD_INSCRIPTION; }

static spn__tether *find_tether(spn_impact *im, int p, uint32_t s)
{
    for (int i = 0; i < im->ntethers; i++)
        if (im->tethers[i].prey == p && im->tethers[i].s == s) return &im->tethers[i];
    return NULL;
}

/* Length of segment s inside the sphere (c, R): the part of the thread whose
 * droplets touch the prey. */
static double chord(const spn_impact *im, uint32_t s, const spn_vec3 *x, spn_vec3 c, double R)
{
    spn_vec3 a = x[im->sa[s]], ab = spn_v3_sub(x[im->sb[s]], a), ac = spn_v3_sub(a, c);
    double A = spn_v3_dot(ab, ab), B = spn_v3_dot(ab, ac), C = spn_v3_dot(ac, ac) - R * R, disc = B * B - A * C;
    if (!(A > 0) || !(disc > 0)) return 0;
    double r = sqrt(disc), t0 = fmax((-B - r) / A, 0), t1 = fmin((-B + r) / A, 1);
    return t1 > t0 ? (t1 - t0) * sqrt(A) : 0;
}

/* Capture segment s within prey p's sticky outline (radius Ro = glue_outline
 * R: legs and wings): glue it, or let an existing glue grow. A tether pulls
 * the prey's centre towards the thread once it is longer than its rest; the
 * rest is the closest the thread has come (never under R: the body's contact
 * holds it there), so the glue holds the prey where the strike left it. Its
 * strength is the adhesion over the length of thread inside the outline
 * (adhesive recruitment, Opell & Hendricks 2009), at least one droplet's.
 * Anchor, rest and strength change only while the tether is slack and leave
 * it slack: that costs no energy. */
static void glue_segment(spn_impact *im, int p, uint32_t s, const spn_vec3 *x, double u, double d)
{
    const double R = im->radius[p], Ro = R * im->def.glue_outline;
    double strength = fmax(im->def.glue_strength, im->def.glue_adhesion * chord(im, s, x, x[im->prey[p]], Ro));
    spn__tether *t = find_tether(im, p, s);
    if (!t) {
        if (im->ntethers == MAX_TETHERS) return;
        t = &im->tethers[im->ntethers++];
        *t = (spn__tether){p, s, u, fmax(R, d), strength, strength / SPN_GLUE_STRETCH, -1};
        return;
    }
    if (tether_force(im, t, x, NULL) > 0) return; /* taut: its droplets hold where they are */
    if (d < t->rest) {
        t->u = u;
        t->rest = fmax(R, d);
    }
    if (strength > t->strength) {
        t->strength = strength;
        t->k = strength / SPN_GLUE_STRETCH;
    }
}

void spn__impact_glue_update(spn_impact *im, const spn_world *w)
{
    if (!(im->def.glue_strength > 0) && !(im->def.glue_adhesion > 0)) return;
    const spn_vec3 *x = spn_world_positions(w);
    /* Droplets that let go: pulled past their strength, or on a broken thread. */
    for (int i = 0; i < im->ntethers;) {
        double e = tether_force(im, &im->tethers[i], x, NULL);
        double pull = sqrt(2 * e * im->tethers[i].k);
        if (pull > im->tethers[i].strength || im->broken[im->tethers[i].s]) {
            im->glue_lost += e;
            im->detached++;
            im->tethers[i] = im->tethers[--im->ntethers];
        } else {
            i++;
        }
    }
    /* Glue where a prey that has touched the web reaches capture thread. */
    for (int p = 0; p < im->nprey; p++) {
        if (!im->touched[p]) continue;
        const double Ro = im->radius[p] * im->def.glue_outline;
        for (uint32_t s = 0; s < im->ns; s++) {
            if (im->broken[s] || !sticky(im->tag[s])) continue;
            double u;
            spn_vec3 r;
            double d2 = spn__impact_closest(im, s, x, x[im->prey[p]], &u, &r);
            if (d2 < Ro * Ro) glue_segment(im, p, s, x, u, sqrt(d2));
        }
    }
}

/* A flying insect's lift balances its weight until it is caught. */
static void lift(const spn_impact *im, const spn_world *w, spn_vec3 *f)
{
    if (im->def.prey_gravity) return;
    spn_vec3 g = spn_world_get_def(w)->gravity;
    for (int p = 0; p < im->nprey; p++)
        f[im->prey[p]] = spn_v3_sub(f[im->prey[p]], spn_v3_scale(g, spn_world_mass(w, im->prey[p])));
}

void spn_impact_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)t;
    (void)v;
    spn_impact *im = user;
    lift(im, w, f);
    /* With the implicit solver the world applies the listed contacts itself. */
    if (!im->listed) spn__impact_contact(im, x, f);
}

void spn_impact_track_wind(spn_impact *im, spn_force_fn fn, void *user)
{
    im->wind_fn = fn;
    im->wind_user = user;
}



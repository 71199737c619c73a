/* The spring world: definitions, construction, accessors, callbacks and
 * colliders, cloning. Construction appends to growable arrays; adding
 * anything invalidates the compiled data (compile.c), and the next step
 * compiles again. */
#include "world_internal.h"

#include "spinneret/limits.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

spn_world_def spn_world_def_default(void)
{
    spn_world_def d;
    memset(&d, 0, sizeof d);
    d.gravity = spn_v3(0, -9.81, 0);
    d.drag = 0;
    d.integrator = SPN_INTEGRATOR_SYMPLECTIC;
    d.dt_min = 1e-7;
    d.dt_factor = 2;
    d.energy_jump = 1e3;
    d.threads = 0;
    d.breakage = true;
    d.cg_tolerance = 1e-10;
    d.cg_max_iterations = 1000;
    d.provot_max_strain = 0;
    d.provot_iterations = 4;
    d.seed = 1;
    d.parallel_min = 32768;
    return d;
}

spn_particle_def spn_particle_def_default(void)
{
    spn_particle_def p;
    memset(&p, 0, sizeof p);
    p.mass = 1;
    return p;
}

spn_spring_def spn_spring_def_default(void)
{
    spn_spring_def s;
    memset(&s, 0, sizeof s);
    s.k = 1;
    s.rest = -1;
    s.break_min = 0;
    s.break_max = INFINITY;
    return s;
}

static const char *const integrator_names[SPN_INTEGRATOR_COUNT] = {"euler", "symplectic", "rk4", "adaptive",
                                                                    "implicit"};

const char *spn_integrator_name(spn_integrator integrator)
{
    return (unsigned)integrator < SPN_INTEGRATOR_COUNT ? integrator_names[integrator] : "unknown";
}

spn_status spn_integrator_parse(const char *name, spn_integrator *out)
{
    for (int i = 0; i < SPN_INTEGRATOR_COUNT; i++)
        if (name && strcmp(name, integrator_names[i]) == 0) {
            *out = (spn_integrator)i;
            return SPN_OK;
        }
    return spn_error(SPN_ERR_INVALID,
                     "unknown solver '%s' (choose euler, symplectic, rk4, adaptive or implicit)", name ? name : "");
}

spn_world *spn_world_create(const spn_world_def *def)
{
    spn_world *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    w->def = def ? *def : spn_world_def_default();
    w->air_rho = 1.204;
    w->air_mu = 1.81e-5;
    return w;
}

void spn_world_destroy(spn_world *w)
{
    if (!w) return;
    spn__free_compiled(w);
    free(w->x);
    free(w->v);
    free(w->mass);
    free(w->inv_mass);
    free(w->ptag);
    free(w->sa);
    free(w->sb);
    free(w->k);
    free(w->kd);
    free(w->rest);
    free(w->bmin);
    free(w->bmax);
    free(w->sflags);
    free(w->stag);
    free(w->sstage);
    free(w->sorder);
    free(w->diam);
    free(w->colliders);
    free(w->metadata);
    spn__silk_free(w);
    free(w);
}

const spn_world_def *spn_world_get_def(const spn_world *w) { return &w->def; }

/* Grow one array to `cap` elements of `size` bytes. */
static bool grow(void **p, size_t cap, size_t size)
{
    void *q = realloc(*p, cap * size);
    if (!q) return false;
    *p = q;
    return true;
}

static bool reserve_particles(spn_world *w, uint32_t need)
{
    if (need <= w->cap_p) return true;
    size_t cap = w->cap_p ? w->cap_p : 64;
    while (cap < need) cap *= 2;
    if (cap > UINT32_MAX) return false;
    bool ok = grow((void **)&w->x, cap, sizeof *w->x) && grow((void **)&w->v, cap, sizeof *w->v) &&
              grow((void **)&w->mass, cap, sizeof *w->mass) && grow((void **)&w->inv_mass, cap, sizeof *w->inv_mass) &&
              grow((void **)&w->ptag, cap, sizeof *w->ptag);
    if (ok) w->cap_p = (uint32_t)cap;
    return ok;
}

static bool reserve_springs(spn_world *w, uint32_t need)
{
    if (need <= w->cap_s) return true;
    size_t cap = w->cap_s ? w->cap_s : 64;
    while (cap < need) cap *= 2;
    if (cap > UINT32_MAX) return false;
    bool ok = grow((void **)&w->sa, cap, sizeof *w->sa) && grow((void **)&w->sb, cap, sizeof *w->sb) &&
              grow((void **)&w->k, cap, sizeof *w->k) && grow((void **)&w->kd, cap, sizeof *w->kd) &&
              grow((void **)&w->rest, cap, sizeof *w->rest) && grow((void **)&w->bmin, cap, sizeof *w->bmin) &&
              grow((void **)&w->bmax, cap, sizeof *w->bmax) && grow((void **)&w->sflags, cap, sizeof *w->sflags) &&
              grow((void **)&w->stag, cap, sizeof *w->stag) && grow((void **)&w->sstage, cap, sizeof *w->sstage) &&
              grow((void **)&w->sorder, cap, sizeof *w->sorder);
    if (ok) w->cap_s = (uint32_t)cap;
    return ok;
}

/* A particle's mass, and a spring's stiffness and damping, as the
 * constructors and the setters take them: finite and not negative (a
 * negative one would leave the implicit step's matrix not positive
 * definite). */
static spn_status check_mass(uint32_t i, double mass)
{
    if (!(mass >= 0) || !isfinite(mass))
        return spn_error(SPN_ERR_INVALID, "particle %u: mass must be finite and not negative, not %g", i, mass);
    return SPN_OK;
}

static spn_status check_stiffness(uint32_t s, double k, double kd)
{
    if (!(k >= 0) || !isfinite(k))
        return spn_error(SPN_ERR_INVALID, "spring %u: stiffness k must be finite and not negative, not %g", s, k);
    if (!(kd >= 0) || !isfinite(kd))
        return spn_error(SPN_ERR_INVALID, "spring %u: damping kd must be finite and not negative, not %g", s, kd);
    return SPN_OK;
}

spn_status spn_world_add_particle(spn_world *w, const spn_particle_def *def, uint32_t *id)
{
    if (!spn_v3_finite(def->position) || !spn_v3_finite(def->velocity))
        return spn_error(SPN_ERR_INVALID, "particle %u: position and velocity must be finite", w->np);
    spn_status st = check_mass(w->np, def->mass);
    if (st != SPN_OK) return st;
    if (w->np >= spn_max_particles()) return spn_check_counts("world", (uint64_t)w->np + 1, 0);
    if (!reserve_particles(w, w->np + 1)) return spn_error(SPN_ERR_NOMEM, "out of memory");
    uint32_t i = w->np++;
    w->x[i] = def->position;
    w->v[i] = def->fixed ? spn_v3(0, 0, 0) : def->velocity;
    w->mass[i] = def->mass;
    w->inv_mass[i] = (def->fixed || def->mass == 0) ? 0 : 1.0 / def->mass;
    w->ptag[i] = def->tag;
    w->compiled = false;
    if (id) *id = i;
    return SPN_OK;
}

spn_status spn_world_add_spring(spn_world *w, const spn_spring_def *def, uint32_t *id)
{
    uint32_t s = w->ns;
    if (def->a >= w->np || def->b >= w->np)
        return spn_error(SPN_ERR_INVALID, "spring %u: particle %u does not exist", s, def->a >= w->np ? def->a : def->b);
    if (def->a == def->b) return spn_error(SPN_ERR_INVALID, "spring %u: both ends are particle %u", s, def->a);
    spn_status st = check_stiffness(s, def->k, def->kd);
    if (st != SPN_OK) return st;
    if (isnan(def->rest) || isinf(def->rest) || isnan(def->break_min) || isnan(def->break_max))
        return spn_error(SPN_ERR_INVALID, "spring %u: rest and break lengths must be numbers", s);
    if (s >= spn_max_springs()) return spn_check_counts("world", 0, (uint64_t)s + 1);
    if (!reserve_springs(w, s + 1)) return spn_error(SPN_ERR_NOMEM, "out of memory");
    w->sa[s] = def->a;
    w->sb[s] = def->b;
    w->k[s] = def->k;
    w->kd[s] = def->kd;
    w->rest[s] = def->rest >= 0 ? def->rest : spn_v3_len(spn_v3_sub(w->x[def->a], w->x[def->b]));
    w->bmin[s] = def->break_min;
    w->bmax[s] = def->break_max;
    w->sflags[s] = def->tension_only ? SPN_SPRING_TENSION_ONLY : 0;
    w->stag[s] = def->tag;
    w->sstage[s] = def->stage;
    w->sorder[s] = def->order;
    w->ns++;
    w->compiled = false;
    if (id) *id = s;
    return SPN_OK;
}

spn_status spn_world_remove_springs(spn_world *w, const bool *remove)
{
    uint32_t n = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (remove[s]) continue;
        spn__move_spring(w, s, n, w->sa[s], w->sb[s]);
        n++;
    }
    w->ns = n;
    w->compiled = false;
    return SPN_OK;
}

uint32_t spn_world_particle_count(const spn_world *w) { return w->np; }
uint32_t spn_world_spring_count(const spn_world *w) { return w->ns; }
const spn_vec3 *spn_world_positions(const spn_world *w) { return w->x; }
const spn_vec3 *spn_world_velocities(const spn_world *w) { return w->v; }
spn_vec3 spn_world_position(const spn_world *w, uint32_t i) { return w->x[i]; }
spn_vec3 spn_world_velocity(const spn_world *w, uint32_t i) { return w->v[i]; }
double spn_world_mass(const spn_world *w, uint32_t i) { return w->mass[i]; }
bool spn_world_is_fixed(const spn_world *w, uint32_t i) { return w->inv_mass[i] == 0; }
uint32_t spn_world_particle_tag(const spn_world *w, uint32_t i) { return w->ptag[i]; }
spn_particle_def spn_world_particle_def(const spn_world *w, uint32_t i)
{
    spn_particle_def p = spn_particle_def_default();
    p.position = w->x[i];
    p.velocity = w->v[i];
    p.mass = w->mass[i];
    p.fixed = spn_world_is_fixed(w, i);
    p.tag = w->ptag[i];
    return p;
}
/* The setters refuse what no step can make and a web file cannot hold: a
 * position, velocity or rest length that is not finite, and a fixed
 * particle's velocity other than 0 (fixed particles do not move, and
 * spn_world_add_particle and spn_world_set_fixed keep it 0). The writers, the
 * equilibrium solve and the locality order still check what they read (a
 * value planted by spn__world_plant, for their tests). */
spn_status spn_world_set_position(spn_world *w, uint32_t i, spn_vec3 p)
{
    if (!spn_v3_finite(p))
        return spn_error(SPN_ERR_INVALID, "particle %u: position must be finite, not (%g, %g, %g)", i, p.x, p.y, p.z);
    w->x[i] = p;
    return SPN_OK;
}
spn_status spn_world_set_velocity(spn_world *w, uint32_t i, spn_vec3 v)
{
    if (!spn_v3_finite(v))
        return spn_error(SPN_ERR_INVALID, "particle %u: velocity must be finite, not (%g, %g, %g)", i, v.x, v.y, v.z);
    if (spn_world_is_fixed(w, i) && (v.x != 0 || v.y != 0 || v.z != 0))
        return spn_error(SPN_ERR_INVALID, "particle %u is fixed: its velocity stays 0, not (%g, %g, %g)", i, v.x, v.y,
                         v.z);
    w->v[i] = v;
    return SPN_OK;
}
void spn_world_set_particle_tag(spn_world *w, uint32_t i, uint32_t tag) { w->ptag[i] = tag; }

static double free_mass_of(const spn_world *w, uint32_t i) { return w->inv_mass[i] > 0 ? w->mass[i] : 0; }

void spn_world_set_fixed(spn_world *w, uint32_t i, bool fixed)
{
    w->free_mass -= free_mass_of(w, i);
    w->inv_mass[i] = (fixed || w->mass[i] == 0) ? 0 : 1.0 / w->mass[i];
    if (fixed) w->v[i] = spn_v3(0, 0, 0);
    w->free_mass += free_mass_of(w, i);
}

spn_status spn_world_set_mass(spn_world *w, uint32_t i, double mass)
{
    spn_status st = check_mass(i, mass);
    if (st != SPN_OK) return st;
    bool fixed = w->inv_mass[i] == 0 && w->mass[i] != 0;
    w->free_mass -= free_mass_of(w, i);
    w->mass[i] = mass;
    w->inv_mass[i] = (fixed || mass == 0) ? 0 : 1.0 / mass;
    w->free_mass += free_mass_of(w, i);
    return SPN_OK;
}

spn_spring_def spn_world_spring_def(const spn_world *w, uint32_t s)
{
    spn_spring_def d;
    d.a = w->sa[s];
    d.b = w->sb[s];
    d.k = w->k[s];
    d.kd = w->kd[s];
    d.rest = w->rest[s];
    d.break_min = w->bmin[s];
    d.break_max = w->bmax[s];
    d.tension_only = (w->sflags[s] & SPN_SPRING_TENSION_ONLY) != 0;
    d.tag = w->stag[s];
    d.stage = w->sstage[s];
    d.order = w->sorder[s];
    return d;
}

bool spn_world_spring_is_broken(const spn_world *w, uint32_t s) { return (w->sflags[s] & SPN_SPRING_BROKEN) != 0; }

spn_spring_info spn_world_spring(const spn_world *w, uint32_t s)
{
    const spn_spring_def d = spn_world_spring_def(w, s);
    spn_spring_info info;
    info.a = d.a;
    info.b = d.b;
    info.k = d.k;
    info.kd = d.kd;
    info.rest = d.rest;
    info.break_min = d.break_min;
    info.break_max = d.break_max;
    info.tension_only = d.tension_only;
    info.broken = spn_world_spring_is_broken(w, s);
    info.tag = d.tag;
    info.stage = d.stage;
    info.order = d.order;
    info.length = spn_v3_len(spn_v3_sub(w->x[info.a], w->x[info.b]));
    double stretch = info.length - info.rest;
    info.tension = (info.broken || (info.tension_only && stretch < 0)) ? 0 : info.k * stretch;
    return info;
}

static void store_rest(spn_world *w, uint32_t s, double rest)
{
    w->rest[s] = rest;
    if (w->compiled) {
        w->hs[w->iperm[s]].rest = rest;
        spn__lattice_spring_changed(w, s);
    }
}

spn_status spn_world_set_spring_rest(spn_world *w, uint32_t s, double rest)
{
    if (!(rest >= 0) || !isfinite(rest))
        return spn_error(SPN_ERR_INVALID, "spring %u: rest length must be finite and not negative, not %g", s, rest);
    store_rest(w, s, rest);
    return SPN_OK;
}

void spn__world_plant(spn_world *w, uint32_t i, spn_vec3 x, spn_vec3 v, uint32_t s, double rest)
{
    if (i < w->np) w->x[i] = x, w->v[i] = v;
    if (s < w->ns) store_rest(w, s, rest);
}

spn_status spn_world_set_spring_stiffness(spn_world *w, uint32_t s, double k, double kd)
{
    spn_status st = check_stiffness(s, k, kd);
    if (st != SPN_OK) return st;
    w->k[s] = k;
    w->kd[s] = kd;
    if (w->compiled) {
        w->hs[w->iperm[s]] = spn__hot_spring(w, s);
        spn__lattice_spring_changed(w, s);
    }
    return SPN_OK;
}
void spn_world_set_spring_tag(spn_world *w, uint32_t s, uint32_t tag)
{
    w->stag[s] = tag;
    w->compiled = false; /* the air buffers depend on the tags' diameters */
}
spn_status spn_world_set_spring_breaks(spn_world *w, uint32_t s, double break_min, double break_max)
{
    if (isnan(break_min) || isnan(break_max))
        return spn_error(SPN_ERR_INVALID, "spring %u: break lengths must be numbers", s);
    w->bmin[s] = break_min;
    w->bmax[s] = break_max;
    w->compiled = false; /* whether any spring can break decides the step's path */
    return SPN_OK;
}

void spn_world_break_spring(spn_world *w, uint32_t s)
{
    w->sflags[s] |= SPN_SPRING_BROKEN;
    if (w->compiled) {
        w->hflags[w->iperm[s]] |= SPN_SPRING_BROKEN;
        w->hs[w->iperm[s]] = spn__hot_spring(w, s);
        spn__lattice_drop(w);
    }
}

bool spn_world_lattice_allowed(const spn_world *w) { return !w->lattice_off; }

void spn_world_set_integrator(spn_world *w, spn_integrator integrator) { w->def.integrator = integrator; }

/* The settings a setter and spn__check_settings both check; `where`
 * starts the message ("" from a setter). */
static spn_status check_solver(const char *where, double cg_tolerance, int cg_max_iterations)
{
    if (!(cg_tolerance > 0 && cg_tolerance < 1))
        return spn_error(SPN_ERR_INVALID, "%scg_tolerance must be in (0, 1), not %g", where, cg_tolerance);
    if (cg_max_iterations < 1)
        return spn_error(SPN_ERR_INVALID, "%scg_max_iterations must be at least 1, not %d", where, cg_max_iterations);
    return SPN_OK;
}

static spn_status check_gravity(const char *where, spn_vec3 g)
{
    if (!spn_v3_finite(g))
        return spn_error(SPN_ERR_INVALID, "%sgravity must be finite, not (%g, %g, %g)", where, g.x, g.y, g.z);
    return SPN_OK;
}

static spn_status check_drag(const char *where, double drag)
{
    if (!(drag >= 0) || !isfinite(drag))
        return spn_error(SPN_ERR_INVALID, "%sdrag must be finite and not negative, not %g", where, drag);
    return SPN_OK;
}

spn_status spn_world_set_solver_tolerance(spn_world *w, double cg_tolerance, int cg_max_iterations)
{
    const spn_status st = check_solver("", cg_tolerance, cg_max_iterations);
    if (st != SPN_OK) return st;
    w->def.cg_tolerance = cg_tolerance;
    w->def.cg_max_iterations = cg_max_iterations;
    return SPN_OK;
}

spn_status spn__check_settings(const spn_world_def *d)
{
    const char *const what = "world settings (spn_world_def): ";
    spn_status st = check_gravity(what, d->gravity);
    if (st == SPN_OK) st = check_drag(what, d->drag);
    if (st == SPN_OK) st = check_solver(what, d->cg_tolerance, d->cg_max_iterations);
    if (st != SPN_OK) return st;
    if ((unsigned)d->integrator >= SPN_INTEGRATOR_COUNT)
        return spn_error(SPN_ERR_INVALID, "%sintegrator %d is none of the %d there are", what, (int)d->integrator,
                         SPN_INTEGRATOR_COUNT);
    if (d->threads < 0) return spn_error(SPN_ERR_INVALID, "%sthreads must not be negative, not %d", what, d->threads);
    if (!(d->dt_min > 0) || !isfinite(d->dt_min))
        return spn_error(SPN_ERR_INVALID, "%sdt_min must be finite and positive, not %g", what, d->dt_min);
    if (!(d->dt_factor > 1) || !isfinite(d->dt_factor))
        return spn_error(SPN_ERR_INVALID, "%sdt_factor must be finite and above 1, not %g", what, d->dt_factor);
    if (!(d->energy_jump > 0))
        return spn_error(SPN_ERR_INVALID, "%senergy_jump must be positive, not %g", what, d->energy_jump);
    if (!(d->provot_max_strain >= 0) || !isfinite(d->provot_max_strain))
        return spn_error(SPN_ERR_INVALID, "%sprovot_max_strain must be finite and not negative, not %g", what,
                         d->provot_max_strain);
    if (d->provot_iterations < 0)
        return spn_error(SPN_ERR_INVALID, "%sprovot_iterations must not be negative, not %d", what,
                         d->provot_iterations);
    return SPN_OK;
}

/* gravity and drag as a web file's world settings have them (web_read.c) */
spn_status spn_world_set_gravity(spn_world *w, spn_vec3 g)
{
    const spn_status st = check_gravity("", g);
    if (st != SPN_OK) return st;
    w->def.gravity = g;
    return SPN_OK;
}
spn_status spn_world_set_drag(spn_world *w, double drag)
{
    const spn_status st = check_drag("", drag);
    if (st != SPN_OK) return st;
    w->def.drag = drag;
    return SPN_OK;
}
spn_status spn_world_set_energy_limit(spn_world *w, spn_energy_limit limit)
{
    if (limit != SPN_ENERGY_LIMIT_OFF && limit != SPN_ENERGY_LIMIT_UNFINISHED && limit != SPN_ENERGY_LIMIT_ALWAYS)
        return spn_error(SPN_ERR_INVALID, "energy limit: off (0), unfinished (1) or always (2), not %d", (int)limit);
    w->energy_limit = (uint8_t)limit;
    return SPN_OK;
}
spn_energy_limit spn_world_energy_limit(const spn_world *w) { return (spn_energy_limit)w->energy_limit; }
double spn_world_time(const spn_world *w) { return w->t; }
void spn_world_set_time(spn_world *w, double t) { w->t = t; }
uint64_t spn_world_step_count(const spn_world *w) { return w->steps; }
spn_step_report spn_world_last_step(const spn_world *w) { return w->last; }

spn_status spn_world_set_metadata(spn_world *w, const char *json_object)
{
    char *copy = NULL;
    if (json_object) {
        size_t n = strlen(json_object) + 1;
        copy = malloc(n);
        if (!copy) return spn_error(SPN_ERR_NOMEM, "out of memory");
        memcpy(copy, json_object, n);
    }
    free(w->metadata);
    w->metadata = copy;
    return SPN_OK;
}

const char *spn_world_metadata(const spn_world *w) { return w->metadata ? w->metadata : "{}"; }

void spn_world_set_force_callback(spn_world *w, spn_force_fn fn, void *user)
{
    w->force_fn = fn;
    w->force_user = user;
}

spn_force_fn spn_world_force_callback(const spn_world *w, void **user)
{
    if (user) *user = w->force_user;
    return w->force_fn;
}

void spn_world_set_break_callback(spn_world *w, spn_break_fn fn, void *user)
{
    w->break_fn = fn;
    w->break_user = user;
}

spn_break_fn spn_world_break_callback(const spn_world *w, void **user)
{
    if (user) *user = w->break_user;
    return w->break_fn;
}

void spn_world_set_collide_callback(spn_world *w, spn_collide_fn fn, void *user)
{
    w->collide_fn = fn;
    w->collide_user = user;
}

spn_collide_fn spn_world_collide_callback(const spn_world *w, void **user)
{
    if (user) *user = w->collide_user;
    return w->collide_fn;
}

void spn_world_set_air(spn_world *w, spn_air_fn fn, void *user, double rho, double mu)
{
    w->air_fn = fn;
    w->air_batch = NULL;
    w->air_user = user;
    w->air_rho = rho;
    w->air_mu = mu;
    w->air_pure = false;
    w->air_interval = w->air_spacing = 0;
    w->air_held_k = NAN; /* (another function's samples) */
}

spn_status spn_world_set_air_resolution(spn_world *w, double interval, double spacing)
{
    const bool off = interval == 0 && spacing == 0;
    if (!off && !(interval > 0 && interval < INFINITY && spacing > 0 && spacing < INFINITY))
        return spn_error(SPN_ERR_INVALID,
                         "air resolution: interval and spacing both positive and finite, or both 0 (exact samples); "
                         "not interval %g s, spacing %g m",
                         interval, spacing);
    if (!off && !w->air_held) w->compiled = false; /* (its buffer comes with the air's, spn__compile) */
    w->air_interval = interval, w->air_spacing = spacing;
    w->air_held_k = NAN;
    return SPN_OK;
}

void spn_world_air_resolution(const spn_world *w, double *interval, double *spacing)
{
    if (interval) *interval = w->air_interval;
    if (spacing) *spacing = w->air_spacing;
}

void spn_world_set_air_pure(spn_world *w, bool pure) { w->air_pure = pure; }

void spn_world_set_air_batch(spn_world *w, spn_air_batch_fn fn) { w->air_batch = fn; }

spn_air_fn spn_world_air(const spn_world *w, void **user, double *rho, double *mu)
{
    if (user) *user = w->air_user;
    if (rho) *rho = w->air_rho;
    if (mu) *mu = w->air_mu;
    return w->air_fn;
}

void spn_world_set_tag_diameter(spn_world *w, uint32_t tag, double diameter)
{
    for (uint32_t i = 0; i < w->ndiam; i++)
        if (w->diam[i].tag == tag) {
            w->diam[i].diameter = diameter;
            w->compiled = false;
            return;
        }
    spn_tag_diameter *d = realloc(w->diam, (w->ndiam + 1) * sizeof *d);
    if (!d) return;
    w->diam = d;
    w->diam[w->ndiam].tag = tag;
    w->diam[w->ndiam].diameter = diameter;
    w->ndiam++;
    w->compiled = false;
}

double spn_world_tag_diameter(const spn_world *w, uint32_t tag)
{
    for (uint32_t i = 0; i < w->ndiam; i++)
        if (w->diam[i].tag == tag) return w->diam[i].diameter;
    return 0;
}

static spn_status add_collider(spn_world *w, spn_collider c)
{
    if (!spn_v3_finite(c.p) || !isfinite(c.d) || !(c.restitution >= 0 && c.restitution <= 1) ||
        !(c.friction >= 0 && c.friction <= 1))
        return spn_error(SPN_ERR_INVALID, "collider: values must be finite, restitution and friction in [0, 1]");
    spn_collider *p = realloc(w->colliders, (w->ncolliders + 1) * sizeof *p);
    if (!p) return spn_error(SPN_ERR_NOMEM, "out of memory");
    w->colliders = p;
    w->colliders[w->ncolliders++] = c;
    return SPN_OK;
}

spn_status spn_world_add_plane(spn_world *w, spn_vec3 normal, double offset, double restitution, double friction)
{
    if (spn_v3_len(normal) == 0) return spn_error(SPN_ERR_INVALID, "plane: normal is zero");
    spn_collider c = {0, spn_v3_norm(normal), offset, restitution, friction};
    return add_collider(w, c);
}

spn_status spn_world_add_sphere(spn_world *w, spn_vec3 centre, double radius, double restitution, double friction)
{
    if (!(radius > 0)) return spn_error(SPN_ERR_INVALID, "sphere: radius must be positive");
    spn_collider c = {1, centre, radius, restitution, friction};
    return add_collider(w, c);
}

uint32_t spn_world_collider_count(const spn_world *w) { return w->ncolliders; }

static bool dup_array(void **dst, const void *src, size_t n, size_t size)
{
    if (n == 0) {
        *dst = NULL;
        return true;
    }
    *dst = malloc(n * size);
    if (!*dst) return false;
    memcpy(*dst, src, n * size);
    return true;
}

/* The particle and the spring arrays a copy of a world holds (spn_world_copy_into,
 * spn_world_clone), by offset, with the size of one element. */
typedef struct world_array {
    size_t offset, size;
} world_array;

#define WORLD_ARRAY(field) {offsetof(spn_world, field), sizeof *((spn_world *)0)->field}
static const world_array particle_arrays[] = {WORLD_ARRAY(x), WORLD_ARRAY(v), WORLD_ARRAY(mass),
                                              WORLD_ARRAY(inv_mass), WORLD_ARRAY(ptag)};
static const world_array spring_arrays[] = {WORLD_ARRAY(sa),     WORLD_ARRAY(sb),    WORLD_ARRAY(k),
                                            WORLD_ARRAY(kd),     WORLD_ARRAY(rest),  WORLD_ARRAY(bmin),
                                            WORLD_ARRAY(bmax),   WORLD_ARRAY(sflags), WORLD_ARRAY(stag),
                                            WORLD_ARRAY(sstage), WORLD_ARRAY(sorder)};
#undef WORLD_ARRAY

static void **array_at(spn_world *w, const world_array *a) { return (void **)((char *)w + a->offset); }

/* Each of `n` arrays of dst large enough for `count` elements (grown to it
 * when `cap` is short); false, with the ones done grown, when memory ran out. */
static bool fit_arrays(spn_world *dst, const world_array *arrays, size_t n, uint32_t cap, uint32_t count)
{
    if (count <= cap) return true;
    for (size_t i = 0; i < n; i++) {
        void **p = array_at(dst, &arrays[i]), *bigger = realloc(*p, (size_t)count * arrays[i].size);
        if (!bigger) return false;
        *p = bigger;
    }
    return true;
}

spn_status spn_world_copy_into(spn_world *dst, const spn_world *src)
{
    if (dst == src) return SPN_OK;
    spn__free_compiled(dst);
    spn__silk_free(dst); /* the contacts too */
    enum { NP = sizeof particle_arrays / sizeof *particle_arrays, NS = sizeof spring_arrays / sizeof *spring_arrays };
    if (!fit_arrays(dst, particle_arrays, NP, dst->cap_p, src->np) ||
        !fit_arrays(dst, spring_arrays, NS, dst->cap_s, src->ns))
        return spn_error(SPN_ERR_NOMEM, "out of memory copying a world (%u particles, %u springs)", src->np, src->ns);
    /* grown arrays hold at least this many (each array grew, or none did) */
    uint32_t cap_p = dst->cap_p > src->np ? dst->cap_p : src->np, cap_s = dst->cap_s > src->ns ? dst->cap_s : src->ns;
    void *keep_p[NP], *keep_s[NS];
    for (size_t i = 0; i < NP; i++) keep_p[i] = *array_at(dst, &particle_arrays[i]);
    for (size_t i = 0; i < NS; i++) keep_s[i] = *array_at(dst, &spring_arrays[i]);
    free(dst->diam), free(dst->colliders), free(dst->metadata);
    *dst = *src;
    spn__forget_compiled(dst);
    dst->diam = NULL, dst->colliders = NULL, dst->metadata = NULL;
    dst->cap_p = cap_p, dst->cap_s = cap_s;
    for (size_t i = 0; i < NP; i++) {
        void **p = array_at(dst, &particle_arrays[i]);
        *p = keep_p[i];
        if (src->np) memcpy(*p, *array_at((spn_world *)src, &particle_arrays[i]), (size_t)src->np * particle_arrays[i].size);
    }
    for (size_t i = 0; i < NS; i++) {
        void **p = array_at(dst, &spring_arrays[i]);
        *p = keep_s[i];
        if (src->ns) memcpy(*p, *array_at((spn_world *)src, &spring_arrays[i]), (size_t)src->ns * spring_arrays[i].size);
    }
    bool ok = dup_array((void **)&dst->diam, src->diam, src->ndiam, sizeof *src->diam) &&
              dup_array((void **)&dst->colliders, src->colliders, src->ncolliders, sizeof *src->colliders) &&
              dup_array((void **)&dst->metadata, src->metadata, src->metadata ? strlen(src->metadata) + 1 : 0, 1) &&
              spn__silk_clone(dst, src);
    if (ok) return SPN_OK;
    /* what failed is NULL: a smaller world, but one that can be destroyed */
    if (!dst->diam) dst->ndiam = 0;
    if (!dst->colliders) dst->ncolliders = 0;
    return spn_error(SPN_ERR_NOMEM, "out of memory copying a world");
}

/* A clone is a copy into an empty world: one list of what a world owns
 * (particle_arrays, spring_arrays and spn_world_copy_into's rest). */
spn_world *spn_world_clone(const spn_world *w)
{
    spn_world *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    if (spn_world_copy_into(c, w) == SPN_OK) return c;
    spn_world_destroy(c);
    return NULL;
}

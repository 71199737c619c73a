/* The spring phases of a shot: THWAP, WHOOSH and ZIPP (ours; the source,
 * Zimmerman's breakdown, names them but built only THWIP).
 *
 * The strand is a chain of n particles and n-1 tension-only springs in an
 * spn_world, built and compiled once at creation: at contact we only write
 * positions, velocities, masses and rest lengths, so no phase change and no
 * step allocates.
 * - Material: the character's weight M g stretches the strand by `stretch`,
 *   so EA = M g / stretch and a segment of rest r has k = EA / r; the mass per
 *   particle is linear_density * r; damping kd = 2 zeta sqrt(k m / 2) (two
 *   equal masses). Symplectic Euler is stable for dt < 1 / sqrt(k / m) on a
 *   chain (highest mode 2 sqrt(k/m)); we sub-step at half that.
 * - THWAP: at contact each segment's rest is its length then (no force jump);
 *   from the time the recoil wave reaches it (arc length from the target /
 *   wave_speed) it eases (smoothstep over snap_time) to the taut rest
 *   taut * |target - origin| / (n - 1). The hand and the target are pinned.
 * - WHOOSH: the hand end gets the character's mass and velocity and swings;
 *   release once it has regained `follow_through` of its drop after the
 *   bottom, or after whoosh_max_time.
 * - ZIPP: the character flies on ballistically; the hand end gets a strand
 *   particle's mass and keeps its velocity; rest lengths become the current
 *   lengths times (1 + slack) (the silk lets go of its stretch and goes limp),
 *   drag pulls it towards the drift
 *   velocity of the air, and it fades over the last 40% of zipp_time.
 * Positions and velocities carry over at every change: nothing pops. */
#include "shoot_internal.h"
#include "spinneret/web.h"

#include <math.h>

spn_status spn__springs_create(spn_shot *s)
{
    const spn_shot_def *d = &s->def;
    const uint32_t n = s->n;
    double dist = spn_v3_len(spn_v3_sub(d->target, d->origin));
    double g = spn_v3_len(d->gravity);
    s->up = g > 0 ? spn_v3_scale(d->gravity, -1.0 / g) : spn_v3(0, 1, 0);
    s->seg_rest = d->taut * dist / (n - 1);
    double ea = d->character_mass * (g > 0 ? g : 9.81) / d->stretch;
    s->k = ea / s->seg_rest;
    s->seg_mass = d->linear_density * s->seg_rest;
    s->kd = 2 * d->damping_ratio * sqrt(0.5 * s->k * s->seg_mass);
    s->dt_sub = 0.5 / sqrt(s->k / s->seg_mass);
    double c = d->wave_damping + d->sway_damping + d->air_drag; /* explicit damping: keep c dt well under 1 */
    if (c > 0) s->dt_sub = fmin(s->dt_sub, 0.25 / c);

    spn_world_def wd = spn_world_def_default();
    wd.gravity = d->gravity;
    wd.integrator = SPN_INTEGRATOR_SYMPLECTIC;
    wd.threads = 1;
    wd.breakage = false;
    s->world = spn_world_create(&wd);
    if (!s->world) return spn_error(SPN_ERR_NOMEM, "shot: out of memory for the spring world");
    spn_particle_def p = spn_particle_def_default();
    p.mass = s->seg_mass;
    for (uint32_t i = 0; i < n; i++) {
        p.position = spn_v3_add(d->origin, spn_v3_scale(spn_v3_sub(d->target, d->origin), (double)i / (n - 1)));
        p.fixed = i == 0 || i == n - 1;
        spn_status st = spn_world_add_particle(s->world, &p, NULL);
        if (st != SPN_OK) return st;
    }
    spn_spring_def sp = spn_spring_def_default();
    sp.k = s->k;
    sp.kd = s->kd;
    sp.rest = s->seg_rest;
    sp.tension_only = true;
    sp.tag = SPN_THREAD_SHOT;
    for (uint32_t i = 0; i + 1 < n; i++) {
        sp.a = i;
        sp.b = i + 1;
        sp.order = i;
        spn_status st = spn_world_add_spring(s->world, &sp, NULL);
        if (st != SPN_OK) return st;
    }
    return spn_world_compile(s->world);
}

static void enter(spn_shot *s, spn_shot_phase phase)
{
    s->phase = phase;
    s->phase_start[phase] = s->t;
}

/* Forces beyond the springs and gravity, for every spring phase:
 * - wave damping: each interior particle is slowed relative to the mean of its
 *   neighbours, f = -c m (v_i - (v_{i-1} + v_{i+1}) / 2). It calms the strand's
 *   sideways ringing (spring damping acts only along the segments) without
 *   braking the swing as a whole, which plain air drag would.
 * - sway damping (THWAP, WHOOSH): the same against the velocity a rigid
 *   strand would have, interpolated between its ends' velocities. A straight
 *   strand turning about its anchor moves exactly like that, so the swing is
 *   untouched while its slow sideways modes (which the neighbour term barely
 *   sees) die out.
 * - ZIPP only: air moving at `drift`; the world's drag gives -c m v, this adds
 *   c m drift. */
static void strand_forces(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    const spn_shot *s = user;
    (void)t;
    (void)x;
    const double c = s->def.wave_damping, cs = s->phase == SPN_SHOT_ZIPP ? 0 : s->def.sway_damping;
    const uint32_t last = s->n - 1;
    for (uint32_t i = 1; i < last; i++) {
        double m = spn_world_mass(w, i), u = (double)i / last;
        spn_vec3 mean = spn_v3_scale(spn_v3_add(v[i - 1], v[i + 1]), 0.5);
        spn_vec3 rigid = spn_v3_add(spn_v3_scale(v[0], 1 - u), spn_v3_scale(v[last], u));
        f[i] = spn_v3_sub(f[i], spn_v3_scale(spn_v3_sub(v[i], mean), c * m));
        f[i] = spn_v3_sub(f[i], spn_v3_scale(spn_v3_sub(v[i], rigid), cs * m));
    }
    if (s->phase != SPN_SHOT_ZIPP) return;
    spn_vec3 a = spn_v3_scale(s->def.drift, s->def.air_drag);
    for (uint32_t i = 0; i < s->n; i++)
        if (!spn_world_is_fixed(w, i)) f[i] = spn_v3_add(f[i], spn_v3_scale(a, spn_world_mass(w, i)));
}

void spn__thwap_begin(spn_shot *s)
{
    const uint32_t n = s->n;
    spn_world *w = s->world;
    enter(s, SPN_SHOT_THWAP);
    for (uint32_t i = 0; i < n; i++) {
        spn_vec3 v = spn_v3_scale(spn_v3_sub(s->tick_b[i], s->tick_a[i]), 1.0 / s->tick);
        if (i > 0 && i + 1 < n) {
            /* The head has stopped: the strand keeps its sideways motion (the
             * noise wave whips on) but not its motion along itself, which
             * would only crumple it into the anchor. */
            spn_vec3 tan = spn_v3_norm(spn_v3_sub(s->pos[i + 1], s->pos[i - 1]));
            v = spn_v3_sub(v, spn_v3_scale(tan, spn_v3_dot(v, tan)));
        }
        spn_world_set_position(w, i, s->pos[i]);
        spn_world_set_velocity(w, i, spn_world_is_fixed(w, i) ? spn_v3(0, 0, 0) : v);
    }
    double arc = 0;
    for (uint32_t j = n - 1; j-- > 0;) {
        s->rest0[j] = spn_v3_len(spn_v3_sub(s->pos[j + 1], s->pos[j]));
        spn_world_set_spring_rest(w, j, s->rest0[j]);
        s->wave_at[j] = s->t + arc / s->def.wave_speed;
        arc += s->rest0[j];
    }
    s->thwap_end = s->t + arc / s->def.wave_speed + s->def.snap_time + s->def.hold_time;
    spn_world_set_time(w, s->t);
    spn_world_set_force_callback(w, strand_forces, s);
}

static void thwap_rests(spn_shot *s, double t)
{
    for (uint32_t j = 0; j + 1 < s->n; j++) {
        double u = s->def.snap_time > 0 ? (t - s->wave_at[j]) / s->def.snap_time : (t >= s->wave_at[j] ? 1 : 0);
        u = fmin(fmax(u, 0), 1);
        double e = u * u * (3 - 2 * u);
        spn_world_set_spring_rest(s->world, j, s->rest0[j] + e * (s->seg_rest - s->rest0[j]));
    }
}

static void whoosh_begin(spn_shot *s)
{
    spn_world *w = s->world;
    enter(s, SPN_SHOT_WHOOSH);
    spn_world_set_mass(w, 0, s->def.character_mass);
    spn_world_set_fixed(w, 0, false);
    spn_world_set_velocity(w, 0, s->def.character_velocity);
    s->h_start = s->h_min = spn_v3_dot(spn_world_position(w, 0), s->up);
}

/* Past the bottom and up again by follow_through of the drop? */
static bool whoosh_release(spn_shot *s)
{
    spn_world *w = s->world;
    double h = spn_v3_dot(spn_world_position(w, 0), s->up);
    double rise = spn_v3_dot(spn_world_velocity(w, 0), s->up);
    if (h < s->h_min) s->h_min = h;
    double drop = s->h_start - s->h_min;
    return drop > 1e-3 && rise > 0 && h - s->h_min >= s->def.follow_through * drop;
}

static void zipp_begin(spn_shot *s)
{
    spn_world *w = s->world;
    enter(s, SPN_SHOT_ZIPP);
    s->char_pos = spn_world_position(w, 0);
    s->char_vel = spn_world_velocity(w, 0);
    spn_world_set_mass(w, 0, s->seg_mass);
    for (uint32_t j = 0; j + 1 < s->n; j++)
        spn_world_set_spring_rest(w, j, (1 + s->def.slack) * spn_world_spring(w, j).length);
    spn_world_set_drag(w, s->def.air_drag);
    s->zipp_end = s->t + s->def.zipp_time;
}

static void zipp_fade(spn_shot *s)
{
    double fade = 0.4 * s->def.zipp_time;
    double u = fade > 0 ? (s->t - (s->zipp_end - fade)) / fade : 1;
    u = fmin(fmax(u, 0), 1);
    s->alpha = 1 - u * u * (3 - 2 * u);
}

static double phase_end(const spn_shot *s)
{
    switch (s->phase) {
    case SPN_SHOT_THWAP: return s->thwap_end;
    case SPN_SHOT_WHOOSH: return s->phase_start[SPN_SHOT_WHOOSH] + s->def.whoosh_max_time;
    case SPN_SHOT_ZIPP: return s->zipp_end;
    default: return s->t;
    }
}

static void next_phase(spn_shot *s)
{
    if (s->phase == SPN_SHOT_THWAP) whoosh_begin(s);
    else if (s->phase == SPN_SHOT_WHOOSH) zipp_begin(s);
    else enter(s, SPN_SHOT_DONE);
}

spn_status spn__springs_advance(spn_shot *s, double until)
{
    double end = phase_end(s), stop = fmin(until, end);
    double span = stop - s->t;
    int nsub = span > 0 ? (int)fmax(ceil(span / s->dt_sub - 1e-9), 1) : 0; /* >= 1: time always moves */
    double h = nsub > 0 ? span / nsub : 0;
    bool released = false;
    for (int k = 0; k < nsub && !released; k++) {
        if (s->phase == SPN_SHOT_THWAP) thwap_rests(s, s->t + h);
        spn_status st = spn_world_step(s->world, h);
        if (st != SPN_OK) return st;
        s->t = k + 1 == nsub ? stop : s->t + h;
        if (s->phase == SPN_SHOT_WHOOSH) released = whoosh_release(s);
        if (s->phase == SPN_SHOT_ZIPP) zipp_fade(s);
    }
    const spn_vec3 *x = spn_world_positions(s->world);
    for (uint32_t i = 0; i < s->n; i++) s->pos[i] = x[i];
    if (released || s->t >= end) next_phase(s);
    return SPN_OK;
}

/* A shot: definition, creation, the THWIP motion and the queries.
 *
 * THWIP follows Zimmerman's breakdown (source 004, "3D Overlay", "Soft Inverse
 * Kinematics", "Velocity Factor", "Putting it together"):
 * - The head flies the noisy path q(t) = p(t) + A (ns(u) side + nl(u) lift),
 *   u = t / T, with p the ballistic arc and side, lift normal to p'(t).
 * - Each strand point is "constrained in x": it sits a fixed path time behind
 *   the head, s_i = s_head - (n-1-i) T/(n-1), and new points come out of the
 *   hand as the head moves on. Only its offset (side, lift) is free.
 * - The pull (forward-reaching, FABRIK-like without the backward pass): the
 *   centre of pull of the point behind the head is the midpoint of the head's
 *   old and new states; each point moves along the line from its old state
 *   towards its centre of pull, to where that line meets its new s; the next
 *   point's centre is the midpoint of that line. States are (s, offset).
 * - The velocity factor: each point's offset carried on with its last change.
 * - The two are blended by linear interpolation with `blend`.
 * The source works in one plane with x along the path; we take the same
 * construction with a 2-component offset in the path's normal plane, so
 * gravity's arc is shared by every point and only the noise lags and stretches.
 *
 * Invariants: the hand (point 0) stays at the origin and the head (n-1) on the
 * noisy path; the motion advances in whole ticks (a tick = T / ((n-1) m), the
 * author's case is m = 1: the head moves one point spacing a tick) and frames
 * between ticks are interpolated, so the look does not depend on the frame
 * rate; contact falls exactly on the last tick. */
#include "shoot_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NOISE_SAMPLES 1024
#define MAX_TICK (1.0 / 120.0)

spn_shot_def spn_shot_def_default(void)
{
    spn_shot_def d;
    memset(&d, 0, sizeof d);
    d.origin = spn_v3(0, 1.5, 0);
    d.target = spn_v3(10, 9, 0);
    d.speed = 40;
    d.auto_speed = false;
    d.gravity = spn_v3(0, -9.81, 0);
    d.noise_amplitude = 0.05;
    d.noise_points = 3;
    d.points = 48;
    d.blend = 0.5;
    d.seed = 1;
    d.all_phases = true;
    d.taut = 0.98;
    d.wave_speed = 60;
    d.snap_time = 0.08;
    d.hold_time = 0.1;
    d.shake_amplitude = 1;
    d.shake_decay = 0.12;
    d.linear_density = 0.05;
    d.damping_ratio = 0.4;
    d.wave_damping = 20;
    d.sway_damping = 6;
    d.character_mass = 70;
    d.character_velocity = spn_v3(0, 0, 0);
    d.stretch = 0.05;
    d.follow_through = 0.5;
    d.whoosh_max_time = 3;
    d.zipp_time = 1.5;
    d.slack = 0.15;
    d.air_drag = 3;
    d.drift = spn_v3(0, 0, 1);
    return d;
}

const char *spn_shot_phase_name(spn_shot_phase phase)
{
    static const char *const names[] = {"thwip", "thwap", "whoosh", "zipp", "done"};
    return (unsigned)phase <= SPN_SHOT_DONE ? names[phase] : "unknown";
}

static spn_status check_range(const char *field, double v, double lo, double hi)
{
    if (!(v >= lo && v <= hi)) return spn_error(SPN_ERR_INVALID, "shot: %s must be in [%g, %g], got %g", field, lo, hi, v);
    return SPN_OK;
}

static spn_status check_def(const spn_shot_def *d)
{
    struct {
        const char *name;
        double v, lo, hi;
    } r[] = {
        {"noise_amplitude", d->noise_amplitude, 0, 0.5}, {"noise_points", d->noise_points, 2, 16},
        {"points", d->points, 4, 1024},                  {"blend", d->blend, 0, 0.95},
        {"taut", d->taut, 0.5, 1},                       {"wave_speed", d->wave_speed, 0.1, 1e4},
        {"snap_time", d->snap_time, 0, 10},              {"hold_time", d->hold_time, 0, 10},
        {"shake_amplitude", d->shake_amplitude, 0, 1e3}, {"shake_decay", d->shake_decay, 1e-3, 10},
        {"linear_density", d->linear_density, 1e-4, 10}, {"damping_ratio", d->damping_ratio, 0, 1},
        {"wave_damping", d->wave_damping, 0, 1000},      {"sway_damping", d->sway_damping, 0, 1000},
        {"character_mass", d->character_mass, 0.1, 1e4}, {"stretch", d->stretch, 0.005, 0.5},
        {"follow_through", d->follow_through, 0, 1},    {"whoosh_max_time", d->whoosh_max_time, 0, 60},
        {"zipp_time", d->zipp_time, 0, 60},              {"slack", d->slack, 0, 2},
                     {"air_drag", d->air_drag, 0, 100},
    };
    for (size_t i = 0; i < sizeof r / sizeof r[0]; i++) {
        spn_status st = check_range(r[i].name, r[i].v, r[i].lo, r[i].hi);
        if (st != SPN_OK) return st;
    }
    if (!spn_v3_finite(d->character_velocity))
        return spn_error(SPN_ERR_INVALID, "shot: character_velocity must be finite");
    if (!spn_v3_finite(d->drift)) return spn_error(SPN_ERR_INVALID, "shot: drift must be finite");
    return SPN_OK;
}

/* A point's world position from its path time and offset. */
static spn_vec3 place(const spn_shot *s, double t, const double *off)
{
    spn_vec3 side, lift;
    spn__path_frame(&s->path, t, &side, &lift);
    spn_vec3 p = spn_ballistic_position(&s->path, t);
    return spn_v3_add(p, spn_v3_add(spn_v3_scale(side, off[0]), spn_v3_scale(lift, off[1])));
}

static void head_offset(const spn_shot *s, double t, double *off)
{
    double u = t / s->path.flight_time;
    off[0] = s->amplitude * spn__noise_at(s->noise_side, s->noise_samples, u);
    off[1] = s->amplitude * spn__noise_at(s->noise_lift, s->noise_samples, u);
}

spn_vec3 spn_shot_head_path(const spn_shot *s, double t)
{
    if (t >= s->path.flight_time) return s->path.target;
    double off[2];
    head_offset(s, t, off);
    return place(s, t, off);
}

static spn_status allocate(spn_shot *s)
{
    size_t n = s->n;
    s->noise_side = malloc(NOISE_SAMPLES * sizeof *s->noise_side);
    s->noise_lift = malloc(NOISE_SAMPLES * sizeof *s->noise_lift);
    s->off = calloc(2 * n, sizeof *s->off);
    s->off_prev = calloc(2 * n, sizeof *s->off_prev);
    s->tick_a = malloc(n * sizeof *s->tick_a);
    s->tick_b = malloc(n * sizeof *s->tick_b);
    s->pos = malloc(n * sizeof *s->pos);
    s->rest0 = malloc(n * sizeof *s->rest0);
    s->wave_at = malloc(n * sizeof *s->wave_at);
    if (!s->noise_side || !s->noise_lift || !s->off || !s->off_prev || !s->tick_a || !s->tick_b || !s->pos ||
        !s->rest0 || !s->wave_at)
        return spn_error(SPN_ERR_NOMEM, "shot: out of memory for %u points", s->n);
    return SPN_OK;
}

static spn_status setup(spn_shot *s, const spn_shot_def *def)
{
    s->def = *def;
    spn_status st = check_def(def);
    if (st == SPN_OK)
        st = spn_ballistic_solve(def->origin, def->target, def->gravity, def->speed, def->auto_speed, &s->path);
    if (st != SPN_OK) return st;
    s->n = (uint32_t)def->points;
    if ((st = allocate(s)) != SPN_OK) return st;
    spn_rng rng;
    spn_rng_seed(&rng, def->seed);
    s->noise_samples = NOISE_SAMPLES;
    spn_smooth_noise(&rng, def->noise_points, s->noise_side, NOISE_SAMPLES);
    spn_smooth_noise(&rng, def->noise_points, s->noise_lift, NOISE_SAMPLES);
    s->amplitude = def->noise_amplitude * spn_v3_len(spn_v3_sub(def->target, def->origin));
    double spacing = s->path.flight_time / (s->n - 1);
    s->ticks_per_point = (uint32_t)ceil(spacing / MAX_TICK);
    s->ticks_total = (s->n - 1) * s->ticks_per_point;
    s->tick = s->path.flight_time / s->ticks_total;
    for (uint32_t i = 0; i < s->n; i++) s->tick_a[i] = s->tick_b[i] = s->pos[i] = def->origin;
    for (int p = 0; p <= SPN_SHOT_DONE; p++) s->phase_start[p] = -1;
    s->phase = SPN_SHOT_THWIP;
    s->phase_start[SPN_SHOT_THWIP] = 0;
    s->alpha = 1;
    return def->all_phases ? spn__springs_create(s) : SPN_OK;
}

spn_status spn_shot_create(const spn_shot_def *def, spn_shot **out)
{
    *out = NULL;
    spn_shot_def d = def ? *def : spn_shot_def_default();
    spn_shot *s = calloc(1, sizeof *s);
    if (!s) return spn_error(SPN_ERR_NOMEM, "shot: out of memory");
    spn_status st = setup(s, &d);
    if (st != SPN_OK) {
        spn_shot_destroy(s);
        return st;
    }
    *out = s;
    return SPN_OK;
}

void spn_shot_destroy(spn_shot *s)
{
    if (!s) return;
    spn_world_destroy(s->world);
    free(s->noise_side);
    free(s->noise_lift);
    free(s->off);
    free(s->off_prev);
    free(s->tick_a);
    free(s->tick_b);
    free(s->pos);
    free(s->rest0);
    free(s->wave_at);
    free(s);
}

/* One point's new offset: the pull towards its centre (path time cs, offset
 * coff), lerped with carrying on as it went over the last tick. */
static void pull_point(spn_shot *s, uint32_t i, double s_old, double s_new, double cs, const double *coff)
{
    double *o = s->off + 2 * i, *op = s->off_prev + 2 * i;
    double denom = cs - s_old, lam = 1;
    if (denom > 1e-12) lam = fmin(fmax((s_new - s_old) / denom, 0), 1);
    for (int c = 0; c < 2; c++) {
        double pull = o[c] + lam * (coff[c] - o[c]);
        double carry = o[c] + (o[c] - op[c]);
        op[c] = o[c];
        o[c] = pull + s->def.blend * (carry - pull);
    }
}

/* Advance the THWIP motion by one tick. */
static void thwip_tick(spn_shot *s)
{
    const uint32_t n = s->n, head = n - 1;
    const double dtk = s->tick, spacing = dtk * s->ticks_per_point;
    uint32_t j = ++s->ticks_done;
    double sh_old = (j - 1) * dtk, sh_new = j == s->ticks_total ? s->path.flight_time : j * dtk;
    double hnew[2];
    head_offset(s, sh_new, hnew);
    double cs = 0.5 * (sh_old + sh_new), coff[2];
    for (int c = 0; c < 2; c++) {
        coff[c] = 0.5 * (s->off[2 * head + c] + hnew[c]);
        s->off_prev[2 * head + c] = s->off[2 * head + c];
        s->off[2 * head + c] = hnew[c];
    }
    for (uint32_t i = head - 1; i >= 1; i--) {
        double s_new = sh_new - (head - i) * spacing;
        if (s_new <= 1e-12) break; /* still in the hand, and so is every point behind */
        double s_old = fmax(sh_old - (head - i) * spacing, 0);
        double old[2] = {s->off[2 * i], s->off[2 * i + 1]};
        pull_point(s, i, s_old, s_new, cs, coff);
        cs = 0.5 * (s_old + cs);
        coff[0] = 0.5 * (old[0] + coff[0]);
        coff[1] = 0.5 * (old[1] + coff[1]);
    }
    memcpy(s->tick_a, s->tick_b, n * sizeof *s->tick_a);
    for (uint32_t i = 1; i < n; i++) {
        double si = sh_new - (head - i) * spacing;
        s->tick_b[i] = si > 1e-12 ? place(s, i == head ? sh_new : si, s->off + 2 * i) : s->def.origin;
    }
    s->tick_b[head] = spn_shot_head_path(s, sh_new);
    s->tick_b[0] = s->def.origin;
}

/* Output at shot time t, between ticks ticks_done - 1 and ticks_done. */
static void thwip_output(spn_shot *s)
{
    double t_b = s->ticks_done == s->ticks_total ? s->path.flight_time : s->ticks_done * s->tick;
    double f = 1 - (t_b - s->t) / s->tick;
    f = fmin(fmax(f, 0), 1);
    for (uint32_t i = 0; i < s->n; i++)
        s->pos[i] = spn_v3_add(s->tick_a[i], spn_v3_scale(spn_v3_sub(s->tick_b[i], s->tick_a[i]), f));
    s->pos[s->n - 1] = spn_shot_head_path(s, s->t);
}

static void thwip_advance(spn_shot *s, double until)
{
    const double T = s->path.flight_time;
    if (until >= T) until = T;
    while (s->ticks_done < s->ticks_total && s->ticks_done * s->tick < until) thwip_tick(s);
    s->t = until;
    thwip_output(s);
    if (until < T) return;
    /* Contact: the strand is exactly the last tick's state. */
    memcpy(s->pos, s->tick_b, s->n * sizeof *s->pos);
    if (s->def.all_phases) {
        spn__thwap_begin(s);
    } else {
        s->phase = SPN_SHOT_DONE;
        s->phase_start[SPN_SHOT_DONE] = T;
    }
}

spn_status spn_shot_step(spn_shot *s, double dt)
{
    if (!(dt > 0 && dt <= 1)) return spn_error(SPN_ERR_INVALID, "shot: dt must be in (0, 1] s, got %g", dt);
    const double end = s->t + dt;
    /* Each pass reaches `end` or changes phase, so a handful of passes do;
     * the bound turns a logic error into a message instead of a hang. */
    for (int pass = 0; s->phase != SPN_SHOT_DONE && s->t < end; pass++) {
        if (pass > 2 * SPN_SHOT_DONE + 2)
            return spn_error(SPN_ERR_UNSTABLE, "shot: time stuck at %.17g s in %s", s->t, spn_shot_phase_name(s->phase));
        if (s->phase == SPN_SHOT_THWIP) {
            thwip_advance(s, end);
        } else {
            spn_status st = spn__springs_advance(s, end);
            if (st != SPN_OK) return st;
        }
    }
    s->t = end;
    return SPN_OK;
}

spn_shot_phase spn_shot_phase_now(const spn_shot *s) { return s->phase; }
double spn_shot_time(const spn_shot *s) { return s->t; }
double spn_shot_contact_time(const spn_shot *s) { return s->path.flight_time; }
const spn_ballistic *spn_shot_path(const spn_shot *s) { return &s->path; }
double spn_shot_strand_alpha(const spn_shot *s) { return s->phase == SPN_SHOT_DONE ? 0 : s->alpha; }

double spn_shot_phase_start(const spn_shot *s, spn_shot_phase phase)
{
    return (unsigned)phase <= SPN_SHOT_DONE ? s->phase_start[phase] : -1;
}

uint32_t spn_shot_strand(const spn_shot *s, const spn_vec3 **points)
{
    *points = s->pos;
    return s->phase == SPN_SHOT_DONE ? 0 : s->n;
}

double spn_shot_camera_shake(const spn_shot *s)
{
    double tc = s->phase_start[SPN_SHOT_THWAP];
    if (tc < 0 || s->t < tc) return 0;
    return s->def.shake_amplitude * exp(-(s->t - tc) / s->def.shake_decay);
}

spn_vec3 spn_shot_character(const spn_shot *s)
{
    if (s->phase == SPN_SHOT_WHOOSH) return spn_world_position(s->world, 0);
    if (s->phase == SPN_SHOT_ZIPP || (s->phase == SPN_SHOT_DONE && s->phase_start[SPN_SHOT_ZIPP] >= 0)) {
        double tau = s->t - s->phase_start[SPN_SHOT_ZIPP];
        return spn_v3_add(s->char_pos,
                          spn_v3_add(spn_v3_scale(s->char_vel, tau), spn_v3_scale(s->def.gravity, 0.5 * tau * tau)));
    }
    return s->def.origin;
}

spn_vec3 spn_shot_character_velocity(const spn_shot *s)
{
    if (s->phase == SPN_SHOT_WHOOSH) return spn_world_velocity(s->world, 0);
    if (s->phase == SPN_SHOT_ZIPP || (s->phase == SPN_SHOT_DONE && s->phase_start[SPN_SHOT_ZIPP] >= 0)) {
        double tau = s->t - s->phase_start[SPN_SHOT_ZIPP];
        return spn_v3_add(s->char_vel, spn_v3_scale(s->def.gravity, tau));
    }
    return spn_v3(0, 0, 0);
}

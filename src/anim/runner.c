/* The animation runner: steps a world frame by frame under a wind model and
 * prey, and hands the frames in a range to a callback.
 *
 * Frame f shows the state at t0 + f / fps; between frames the world takes
 * `substeps` equal steps. The run always starts from the first frame, whatever
 * range is asked for, so a frame is the same bits whether it is rendered in a
 * whole run or in a slice of it (--frame-range for render farms); the run
 * stops once the last frame of the range is handed over.
 *
 * Explicit solvers need dt below 2 / omega_max; omega_max^2 is bounded by
 * Gershgorin's theorem on M^-1 K: max over particles of 2 sum(k) / m. */
#include "anim_internal.h"

#include <math.h>
#include <string.h>

typedef struct runner {
    spn_anim_def def;
    spn_thesis_wind *thesis;
    spn_air_field *air;
    spn_impact *impact;
    double cg_tolerance; /* the world's, restored after the run */
    double last_step;    /* the step just taken [s] (advance_frame) */
} runner;

spn_anim_def spn_anim_def_default(void)
{
    spn_anim_def d;
    memset(&d, 0, sizeof d);
    d.duration = 5;
    d.fps = 25;
    d.substeps = 0;
    d.solver = SPN_INTEGRATOR_COUNT;
    d.first_frame = 0;
    d.last_frame = -1;
    d.wind = SPN_WIND_NONE;
    d.thesis = spn_thesis_wind_def_default();
    d.air = spn_air_def_default();
    d.wind_stop = -1;
    d.impact = spn_impact_def_default();
    d.seed = 1;
    return d;
}

int spn_anim_frame_count(const spn_anim_def *def) { return (int)lround(def->duration * def->fps) + 1; }

int spn_anim_stable_substeps(const spn_world *w, double fps, spn_integrator solver, double extra_stiffness)
{
    double frame = 1 / fps;
    if (solver == SPN_INTEGRATOR_IMPLICIT) return (int)fmax(1, ceil(frame / 2e-3));
    if (solver == SPN_INTEGRATOR_ADAPTIVE) return (int)fmax(1, ceil(frame / 5e-3));
    /* margin on the springs' bound (spn_world_stable_step) */
    const double reach = solver == SPN_INTEGRATOR_RK4 ? SPN_STABLE_REACH_RK4 : SPN_STABLE_REACH;
    const double stable = spn_world_stable_step(w, extra_stiffness);
    if (!(stable > 0)) return 1000; /* out of memory */
    const double dt = fmin(frame, reach * stable);
    double n = ceil(frame / dt);
    return n > 1e7 ? 10000000 : (int)fmax(1, n);
}

static void runner_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    runner *r = user;
    if (r->thesis) spn_thesis_wind_force(r->thesis, w, t, x, v, f);
    if (r->impact) spn_impact_force(r->impact, w, t, x, v, f);
}

static void thesis_only(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    runner *r = user;
    spn_thesis_wind_force(r->thesis, w, t, x, v, f);
}

static spn_status check_def(const spn_anim_def *d)
{
    if (!(d->duration >= 0) || !(d->duration <= 1e5)) return spn_error(SPN_ERR_INVALID, "duration must be in [0, 1e5] s");
    if (!(d->fps > 0) || !(d->fps <= 10000)) return spn_error(SPN_ERR_INVALID, "fps must be in (0, 10000]");
    if (d->substeps < 0) return spn_error(SPN_ERR_INVALID, "substeps must be >= 0");
    if (!(d->cg_tolerance >= 0 && d->cg_tolerance < 1)) return spn_error(SPN_ERR_INVALID, "solver tolerance must be in [0, 1)");
    int frames = spn_anim_frame_count(d);
    if (d->first_frame < 0 || d->first_frame >= frames)
        return spn_error(SPN_ERR_INVALID, "frame range starts at %d, outside 0..%d", d->first_frame, frames - 1);
    if (d->last_frame >= frames)
        return spn_error(SPN_ERR_INVALID, "frame range ends at %d, outside 0..%d", d->last_frame, frames - 1);
    if (d->last_frame >= 0 && d->last_frame < d->first_frame)
        return spn_error(SPN_ERR_INVALID, "frame range %d-%d is empty", d->first_frame, d->last_frame);
    if (d->nprey < 0 || (d->nprey > 0 && !d->prey)) return spn_error(SPN_ERR_INVALID, "prey list missing");
    return SPN_OK;
}

/* The web's box, grown by half its size to leave room for billowing, with
 * five nodes per smallest eddy (at most 48 an axis): the interpolation
 * stays within ~10% of that eddy. Slices 5 ms apart. */
spn_status spn__air_grid_over_web(spn_air_field *air, const spn_world *w, double small_scale)
{
    spn_vec3 lo, hi;
    spn__web_bounds(w, &lo, &hi);
    double size = fmax(fmax(hi.x - lo.x, hi.y - lo.y), fmax(hi.z - lo.z, 1e-3)), pad = 0.5 * size;
    lo = spn_v3_sub(lo, spn_v3(pad, pad, pad));
    hi = spn_v3_add(hi, spn_v3(pad, pad, pad));
    double h = small_scale / 5;
    int n[3];
    double ext[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
    for (int a = 0; a < 3; a++) n[a] = (int)fmin(48, fmax(3, ceil(ext[a] / h) + 1));
    return spn_air_set_grid(air, lo, hi, n[0], n[1], n[2], 5e-3);
}

/* The air field cached over the web's box (spn__air_grid_over_web). */
static spn_status make_air(runner *r, spn_world *w)
{
    spn_air_def ad = r->def.air;
    ad.seed = r->def.seed;
    if (r->def.wind_stop >= 0) ad.stop = fmin(ad.stop, r->def.wind_stop);
    if (r->def.wind != SPN_WIND_AIR) { /* still air for the prey */
        ad.speed = 0;
        ad.turbulence = 0;
        ad.gust = 0;
    }
    spn_status st = spn_air_create(&ad, &r->air);
    if (st != SPN_OK) return st;
    if (ad.turbulence > 0) st = spn__air_grid_over_web(r->air, w, ad.small_scale);
    if (st != SPN_OK) return st;
    spn_air_attach(r->air, w);
    return SPN_OK;
}

static spn_status setup(runner *r, spn_world **w)
{
    spn_status st = SPN_OK;
    if (r->def.solver != SPN_INTEGRATOR_COUNT) spn_world_set_integrator(*w, r->def.solver);
    r->cg_tolerance = spn_world_get_def(*w)->cg_tolerance;
    if (r->def.cg_tolerance > 0)
        st = spn_world_set_solver_tolerance(*w, r->def.cg_tolerance, spn_world_get_def(*w)->cg_max_iterations);
    if (st == SPN_OK && r->def.nprey > 0) st = spn_impact_create(w, r->def.prey, r->def.nprey, &r->def.impact, &r->impact);
    if (st == SPN_OK && r->def.wind == SPN_WIND_THESIS) {
        spn_thesis_wind_def td = r->def.thesis;
        td.seed = r->def.seed;
        st = spn_thesis_wind_create(&td, *w, &r->thesis);
        if (st == SPN_OK && r->impact) spn_impact_track_wind(r->impact, thesis_only, r);
    }
    if (st == SPN_OK && (r->def.wind == SPN_WIND_AIR || r->impact)) st = make_air(r, *w);
    if (st == SPN_OK && (r->thesis || r->impact)) spn_world_set_force_callback(*w, runner_force, r);
    return st;
}

static void teardown(runner *r, spn_world *w)
{
    if (r->def.cg_tolerance > 0) spn_world_set_solver_tolerance(w, r->cg_tolerance, spn_world_get_def(w)->cg_max_iterations);
    spn_world_set_force_callback(w, NULL, NULL);
    spn_world_set_break_callback(w, NULL, NULL);
    if (r->air) spn_world_set_air(w, NULL, NULL, r->def.air.rho, r->def.air.mu);
    spn_thesis_wind_destroy(r->thesis);
    spn_air_destroy(r->air);
    spn_impact_destroy(r->impact);
}

static spn_status one_step(runner *r, spn_world *w, double dt, uint64_t *steps)
{
    double t = spn_world_time(w);
    if (r->air) spn_air_prepare_held(r->air, t, t + dt);
    spn_status st = r->impact ? spn_impact_before_step(r->impact, w, dt) : SPN_OK;
    if (st == SPN_OK) st = spn_world_step(w, dt);
    if (st != SPN_OK) return st;
    (*steps)++;
    if (r->impact) spn_impact_after_step(r->impact, w, dt);
    return SPN_OK;
}

/* With the implicit solver a substep near a prey is split into equal steps
 * short enough for the contacts (spn_impact_step_limit, asked again before
 * every step), and a step is at most STEP_GROWTH times the one before it, so
 * steps come back to the frame's substep over a few steps instead of at
 * once: the solver's numerical damping, which grows with the step, changes
 * smoothly (docs/wind-and-prey.md, "Contact step schedule"). The schedule is
 * a function of the run from its first frame, so a frame is the same bits in
 * any frame range. */
#define STEP_GROWTH 2.0

static spn_status advance_frame(runner *r, spn_world *w, int substeps, double dt, uint64_t *steps, bool *stopped)
{
    const bool split = r->impact && spn_world_get_def(w)->integrator == SPN_INTEGRATOR_IMPLICIT;
    for (int s = 0; s < substeps; s++) {
        double left = dt;
        while (left > 0) {
            double h = left, limit = dt;
            if (split) limit = fmin(spn_impact_step_limit(r->impact, w, dt), STEP_GROWTH * r->last_step);
            int n = limit < left ? (int)fmin(1e6, ceil(left / limit)) : 1;
            if (n > 1) h = left / n;
            spn_status st = one_step(r, w, h, steps);
            if (st != SPN_OK) return st;
            r->last_step = h;
            left = n > 1 ? left - h : 0;
            if (r->def.stop && *r->def.stop) {
                *stopped = true;
                return SPN_OK;
            }
        }
    }
    return SPN_OK;
}

spn_status spn_animate(spn_world **w, const spn_anim_def *def, spn_anim_frame_fn fn, void *user,
                       spn_anim_report *report)
{
    spn_anim_report rep;
    memset(&rep, 0, sizeof rep);
    spn_status st = check_def(def);
    if (st != SPN_OK) return st;
    runner r;
    memset(&r, 0, sizeof r);
    r.def = *def;
    st = setup(&r, w);
    int frames = spn_anim_frame_count(def), last = def->last_frame < 0 ? frames - 1 : def->last_frame;
    double kc = r.impact ? spn_impact_contact_stiffness(r.impact) : 0;
    spn_integrator solver = spn_world_get_def(*w)->integrator;
    rep.substeps = def->substeps > 0 ? def->substeps : spn_anim_stable_substeps(*w, def->fps, solver, kc);
    /* The adaptive solver meets the contact forces explicitly (a callback), so
     * it needs the explicit step; the implicit one carries their stiffness
     * (spn_impact_before_step) and splits steps near prey (advance_frame).
     * Explicit solvers: a prey moves at most a tenth of its radius per step. */
    if (r.impact && def->substeps == 0 && solver == SPN_INTEGRATOR_ADAPTIVE) {
        int n = spn_anim_stable_substeps(*w, def->fps, SPN_INTEGRATOR_SYMPLECTIC, kc);
        if (n > rep.substeps) rep.substeps = n;
    }
    for (int i = 0; i < def->nprey && def->substeps == 0 && solver != SPN_INTEGRATOR_IMPLICIT; i++) {
        double v = spn_v3_len(def->prey[i].velocity), n = ceil(10 * v / (def->fps * def->prey[i].radius));
        if (n > rep.substeps && n < 1e7) rep.substeps = (int)n;
    }
    rep.dt = 1 / (def->fps * rep.substeps);
    r.last_step = rep.dt;
    double t0 = spn_world_time(*w);
    for (int f = 0; f <= last && st == SPN_OK; f++) {
        if (f > 0) {
            /* Land each frame on its exact time so rounding does not drift. */
            st = advance_frame(&r, *w, rep.substeps, rep.dt, &rep.steps, &rep.interrupted);
            if (st != SPN_OK || rep.interrupted) break;
            spn_world_set_time(*w, t0 + f / def->fps);
        }
        if (f >= def->first_frame && fn) {
            st = fn(user, f, *w);
            rep.frames++;
        }
        if (def->progress) def->progress(def->progress_user, f, last + 1);
    }
    if (r.impact) {
        rep.has_impact = true;
        spn_impact_report_get(r.impact, *w, &rep.impact);
    }
    teardown(&r, *w);
    if (report) *report = rep;
    return st;
}

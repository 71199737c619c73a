/* Forces and the explicit integrators (Euler, symplectic Euler, RK4).
 * Forces: springs with axial damping (Mehla eq. 4.14), gravity, viscous drag,
 * air drag on threads, and the user callback. Spring forces are computed per
 * spring, then gathered per particle through the CSR adjacency in a fixed
 * order, so the sums are bit-identical for any number of threads.
 * A step that produces a non-finite value restores the state from before it. */
#include "world_internal.h"

#include <math.h>
#include <string.h>

spn_vec3 spn__spring_force(const spn_world *w, uint32_t s, const spn_vec3 *x, const spn_vec3 *v)
{
    if (w->sflags[s] & SPN_SPRING_BROKEN) return spn_v3(0, 0, 0);
    uint32_t a = w->sa[s], b = w->sb[s];
    spn_vec3 l = spn_v3_sub(x[a], x[b]);
    double len = spn_v3_len(l);
    if (len <= 0) return spn_v3(0, 0, 0);
    double stretch = len - w->rest[s];
    if (stretch < 0 && (w->sflags[s] & SPN_SPRING_TENSION_ONLY)) return spn_v3(0, 0, 0);
    spn_vec3 ldot = spn_v3_sub(v[a], v[b]);
    double mag = w->k[s] * stretch + w->kd[s] * spn_v3_dot(ldot, l) / len;
    return spn_v3_scale(l, -mag / len);
}

void spn__eval_forces(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    const uint32_t ns = w->ns, np = w->np;
    spn_vec3 *fs = w->fs;
#pragma omp parallel for schedule(static) if (ns > 20000)
    for (uint32_t s = 0; s < ns; s++) fs[s] = spn__spring_force(w, s, x, v);

    const spn_vec3 g = w->def.gravity;
    const double drag = w->def.drag;
#pragma omp parallel for schedule(static) if (np > 10000)
    for (uint32_t i = 0; i < np; i++) {
        double m = w->mass[i];
        spn_vec3 fi = spn_v3(m * g.x - drag * m * v[i].x, m * g.y - drag * m * v[i].y, m * g.z - drag * m * v[i].z);
        for (uint32_t j = w->adj_start[i]; j < w->adj_start[i + 1]; j++) {
            uint32_t e = w->adj[j], s = e >> 1;
            spn_vec3 fe = fs[s];
            if (e & 1u) fi = spn_v3_sub(fi, fe);
            else fi = spn_v3_add(fi, fe);
        }
        f[i] = fi;
    }
    if (w->force_fn) w->force_fn(w->force_user, w, t, x, v, f);
}

double spn__kinetic_energy(const spn_world *w, const spn_vec3 *v)
{
    double e = 0;
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) e += 0.5 * w->mass[i] * spn_v3_dot(v[i], v[i]);
    return e;
}

double spn__elastic_energy(const spn_world *w, const spn_vec3 *x)
{
    double e = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        double d = spn_v3_len(spn_v3_sub(x[w->sa[s]], x[w->sb[s]])) - w->rest[s];
        if (d < 0 && (w->sflags[s] & SPN_SPRING_TENSION_ONLY)) continue;
        e += 0.5 * w->k[s] * d * d;
    }
    return e;
}

double spn__gravity_energy(const spn_world *w, const spn_vec3 *x)
{
    double e = 0;
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) e -= w->mass[i] * spn_v3_dot(w->def.gravity, x[i]);
    return e;
}

/* dx/dt = v, dv/dt = f/m for state (x, v) into (dx, dv). */
static void derivative(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *dx, spn_vec3 *dv)
{
    spn__eval_forces(w, t, x, v, w->f);
    for (uint32_t i = 0; i < w->np; i++) {
        double im = w->inv_mass[i];
        dx[i] = im > 0 ? v[i] : spn_v3(0, 0, 0);
        dv[i] = spn_v3_scale(w->f[i], im);
    }
}

static void step_euler(spn_world *w, double dt, bool symplectic)
{
    derivative(w, w->t, w->x, w->v, w->kx[0], w->kv[0]);
    for (uint32_t i = 0; i < w->np; i++) {
        if (w->inv_mass[i] == 0) continue;
        spn_vec3 vn = spn_v3_add(w->v[i], spn_v3_scale(w->kv[0][i], dt));
        w->x[i] = spn_v3_add(w->x[i], spn_v3_scale(symplectic ? vn : w->v[i], dt));
        w->v[i] = vn;
    }
}

static void step_rk4(spn_world *w, double dt)
{
    const uint32_t np = w->np;
    spn_vec3 **kx = w->kx, **kv = w->kv, *xt = w->xt, *vt = w->vt;
    static const double frac[3] = {0.5, 0.5, 1.0};
    derivative(w, w->t, w->x, w->v, kx[0], kv[0]);
    for (int stage = 0; stage < 3; stage++) {
        double h = frac[stage] * dt;
        for (uint32_t i = 0; i < np; i++) {
            xt[i] = spn_v3_add(w->x[i], spn_v3_scale(kx[stage][i], h));
            vt[i] = spn_v3_add(w->v[i], spn_v3_scale(kv[stage][i], h));
        }
        derivative(w, w->t + h, xt, vt, kx[stage + 1], kv[stage + 1]);
    }
    for (uint32_t i = 0; i < np; i++) {
        if (w->inv_mass[i] == 0) continue;
        spn_vec3 dx = spn_v3_add(spn_v3_add(kx[0][i], kx[3][i]), spn_v3_scale(spn_v3_add(kx[1][i], kx[2][i]), 2));
        spn_vec3 dv = spn_v3_add(spn_v3_add(kv[0][i], kv[3][i]), spn_v3_scale(spn_v3_add(kv[1][i], kv[2][i]), 2));
        w->x[i] = spn_v3_add(w->x[i], spn_v3_scale(dx, dt / 6));
        w->v[i] = spn_v3_add(w->v[i], spn_v3_scale(dv, dt / 6));
    }
}

/* Keep particles out of planes and spheres: project back to the surface and
 * reflect the normal velocity with restitution; friction scales tangential. */
static void collide_builtin(spn_world *w)
{
    for (uint32_t c = 0; c < w->ncolliders; c++) {
        const spn_collider *col = &w->colliders[c];
        for (uint32_t i = 0; i < w->np; i++) {
            if (w->inv_mass[i] == 0) continue;
            spn_vec3 n;
            double depth;
            if (col->kind == 0) {
                n = col->p;
                depth = col->d - spn_v3_dot(n, w->x[i]);
            } else {
                spn_vec3 r = spn_v3_sub(w->x[i], col->p);
                double len = spn_v3_len(r);
                n = len > 0 ? spn_v3_scale(r, 1 / len) : spn_v3(0, 1, 0);
                depth = col->d - len;
            }
            if (depth <= 0) continue;
            w->x[i] = spn_v3_add(w->x[i], spn_v3_scale(n, depth));
            double vn = spn_v3_dot(w->v[i], n);
            if (vn < 0) {
                spn_vec3 vt = spn_v3_sub(w->v[i], spn_v3_scale(n, vn));
                w->v[i] = spn_v3_add(spn_v3_scale(vt, 1 - col->friction), spn_v3_scale(n, -vn * col->restitution));
            }
        }
    }
}

static void collide_callback(spn_world *w)
{
    for (uint32_t i = 0; i < w->np; i++) {
        if (w->inv_mass[i] == 0) continue;
        spn_vec3 n = spn_v3(0, 0, 0);
        double keep = 1;
        double frac = w->collide_fn(w->collide_user, i, w->x0[i], w->x[i], &n, &keep);
        if (!(frac < 1)) continue;
        if (frac < 0) frac = 0;
        w->x[i] = spn_v3_add(w->x0[i], spn_v3_scale(spn_v3_sub(w->x[i], w->x0[i]), frac));
        double vn = spn_v3_dot(w->v[i], n);
        if (vn < 0) w->v[i] = spn_v3_sub(w->v[i], spn_v3_scale(n, (1 + keep) * vn));
    }
}

static int check_breakage(spn_world *w)
{
    int breaks = 0;
    if (!w->def.breakage) return 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        double len = spn_v3_len(spn_v3_sub(w->x[w->sa[s]], w->x[w->sb[s]]));
        if (len >= w->bmin[s] && len <= w->bmax[s]) continue;
        w->sflags[s] |= SPN_SPRING_BROKEN;
        breaks++;
        if (w->break_fn) w->break_fn(w->break_user, s, w->t, len);
    }
    return breaks;
}

/* Index of the first particle with a non-finite position or velocity, or np. */
static uint32_t first_bad_particle(const spn_world *w)
{
    for (uint32_t i = 0; i < w->np; i++)
        if (!spn_v3_finite(w->x[i]) || !spn_v3_finite(w->v[i])) return i;
    return w->np;
}

spn_status spn_world_step(spn_world *w, double dt)
{
    if (!(dt > 0) || !isfinite(dt)) return spn_error(SPN_ERR_INVALID, "time step must be positive and finite");
    spn_status st = spn_world_compile(w);
    if (st != SPN_OK) return st;
    memcpy(w->x0, w->x, w->np * sizeof *w->x);
    memcpy(w->v0, w->v, w->np * sizeof *w->v);
    memset(&w->last, 0, sizeof w->last);
    w->last.dt = dt;
    w->last.substeps = 1;
    switch (w->def.integrator) {
    case SPN_INTEGRATOR_EULER: step_euler(w, dt, false); break;
    case SPN_INTEGRATOR_SYMPLECTIC: step_euler(w, dt, true); break;
    case SPN_INTEGRATOR_RK4: step_rk4(w, dt); break;
    default:
        return spn_error(SPN_ERR_UNSUPPORTED, "solver '%s' is not available yet",
                         spn_integrator_name(w->def.integrator));
    }
    if (w->ncolliders) collide_builtin(w);
    if (w->collide_fn) collide_callback(w);
    uint32_t bad = first_bad_particle(w);
    if (bad < w->np) {
        memcpy(w->x, w->x0, w->np * sizeof *w->x);
        memcpy(w->v, w->v0, w->np * sizeof *w->v);
        return spn_error(SPN_ERR_UNSTABLE, "simulation blew up at step %llu (t = %g s): particle %u is not finite",
                         (unsigned long long)w->steps + 1, w->t + dt, bad);
    }
    w->t += dt;
    w->steps++;
    w->last.breaks = check_breakage(w);
    return SPN_OK;
}

spn_energy spn_world_energy(const spn_world *w)
{
    spn_energy e;
    e.kinetic = spn__kinetic_energy(w, w->v);
    e.elastic = spn__elastic_energy(w, w->x);
    e.gravitational = spn__gravity_energy(w, w->x);
    e.external_work = w->external_work;
    e.dissipated = w->dissipated;
    return e;
}

double spn_world_total_energy(const spn_world *w)
{
    spn_energy e = spn_world_energy(w);
    return e.kinetic + e.elastic + e.gravitational;
}

double spn_world_max_residual(spn_world *w, uint32_t *which)
{
    if (spn_world_compile(w) != SPN_OK) return NAN;
    memset(w->vt, 0, w->np * sizeof *w->vt);
    spn__eval_forces(w, w->t, w->x, w->vt, w->f);
    double best = 0;
    uint32_t arg = 0;
    for (uint32_t i = 0; i < w->np; i++) {
        if (w->inv_mass[i] == 0) continue;
        double m = spn_v3_len(w->f[i]);
        if (m > best) {
            best = m;
            arg = i;
        }
    }
    if (which) *which = arg;
    return best;
}

spn_settle_def spn_settle_def_default(void)
{
    spn_settle_def d;
    d.dt = 1e-3;
    d.max_kinetic = 1e-9;
    d.max_residual = 1e-6;
    d.max_time = 60;
    d.min_time = 0;
    d.check_interval = 0;
    return d;
}

spn_status spn_world_settle(spn_world *w, const spn_settle_def *def, spn_settle_report *report)
{
    spn_settle_def d = def ? *def : spn_settle_def_default();
    if (!(d.dt > 0) || !(d.max_time >= 0)) return spn_error(SPN_ERR_INVALID, "settle: dt and max_time must be positive");
    double interval = d.check_interval > 0 ? d.check_interval : 10 * d.dt;
    double t0 = w->t, next_check = t0 + d.min_time;
    uint64_t steps = 0;
    memset(report, 0, sizeof *report);
    report->reason = SPN_SETTLE_TIMEOUT;
    for (;;) {
        if (w->t >= next_check) {
            next_check = w->t + interval;
            double ke = spn__kinetic_energy(w, w->v);
            if (ke <= d.max_kinetic && spn_world_max_residual(w, NULL) <= d.max_residual) {
                report->reason = SPN_SETTLE_CONVERGED;
                break;
            }
        }
        if (w->t - t0 >= d.max_time) break;
        spn_status st = spn_world_step(w, d.dt);
        if (st != SPN_OK) return st;
        steps++;
    }
    report->time = w->t - t0;
    report->steps = steps;
    report->kinetic = spn__kinetic_energy(w, w->v);
    report->residual = spn_world_max_residual(w, NULL);
    report->total_energy = spn_world_total_energy(w);
    return SPN_OK;
}

double spn_cylinder_drag_coefficient(double re)
{
    /* White's correlation for a cylinder in cross-flow, fair from Re ~ 1e-3 to 2e5;
     * for silk (Re << 1) it approaches the Stokes-like 8 pi / (Re (2 - ln Re)) regime. */
    if (!(re > 0)) return 0;
    return 1.0 + 10.0 / pow(re, 2.0 / 3.0);
}

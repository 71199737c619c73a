/* What happens after the integrator moved the particles: collisions, Provot's
 * deformation limits, breakage.
 *
 * Collisions (Juhasz & Bercovici's model): a particle found inside a plane's
 * half-space or a sphere is put back on the surface; its normal velocity, if
 * it points inward, is reversed and scaled by the restitution, and its
 * tangential velocity loses the friction fraction. The per-particle callback
 * says how much of the move from the old to the new position is allowed and
 * how much reversed normal velocity is kept. Position projection means a
 * particle never ends a step inside a collider, whatever the step size.
 *
 * Provot (1995), as Mehla tried (section 5.1): after the step, each spring
 * stretched beyond (1 + max_strain) rest is shortened to that length by
 * moving its ends toward each other in proportion to their inverse masses;
 * velocities follow the moves (v += dx / dt) so the next step does not
 * undo them. Springs are visited in id order, several passes: the result
 * depends on the order, as Mehla observed, but is deterministic.
 *
 * Breakage: a spring outside [break_min, break_max] breaks (flagged, exerts
 * nothing from then on) and the callback hears of it once. */
#include "world_internal.h"

#include <math.h>

/* Energy that moving particle i can change: its kinetic and gravitational
 * energy and the elastic energy of its springs. */
static double particle_energy(const spn_world *w, uint32_t i)
{
    double e = 0.5 * w->mass[i] * spn_v3_dot(w->v[i], w->v[i]) - w->mass[i] * spn_v3_dot(w->def.gravity, w->x[i]);
    for (uint32_t j = w->adj_start[i]; j < w->adj_start[i + 1]; j++) {
        uint32_t s = w->adj[j] >> 1; /* internal order */
        if (w->hflags[s] & SPN_SPRING_BROKEN) continue;
        const spn__spring *sp = &w->hs[s];
        double d = spn_v3_len(spn_v3_sub(w->x[sp->a], w->x[spn__end_b(*sp)])) - sp->rest;
        if (d < 0 && (w->hflags[s] & SPN_SPRING_TENSION_ONLY)) continue;
        e += 0.5 * sp->k * d * d;
    }
    return e;
}

/* Depth of x inside collider c (> 0: inside) and the outward normal there. */
static double penetration(const spn_collider *c, spn_vec3 x, spn_vec3 *n)
{
    if (c->kind == 0) {
        *n = c->p;
        return c->d - spn_v3_dot(c->p, x);
    }
    spn_vec3 r = spn_v3_sub(x, c->p);
    double len = spn_v3_len(r);
    *n = len > 0 ? spn_v3_scale(r, 1 / len) : spn_v3(0, 1, 0);
    return c->d - len;
}

static void collide_builtin(spn_world *w, uint32_t i)
{
    for (uint32_t c = 0; c < w->ncolliders; c++) {
        const spn_collider *col = &w->colliders[c];
        spn_vec3 n;
        double depth = penetration(col, w->x[i], &n);
        if (!(depth > 0)) continue;
        w->x[i] = spn_v3_add(w->x[i], spn_v3_scale(n, depth));
        double vn = spn_v3_dot(w->v[i], n);
        if (vn < 0) {
            spn_vec3 vt = spn_v3_sub(w->v[i], spn_v3_scale(n, vn));
            w->v[i] = spn_v3_add(spn_v3_scale(vt, 1 - col->friction), spn_v3_scale(n, -vn * col->restitution));
        }
    }
}

static void collide_user(spn_world *w, uint32_t i)
{
    spn_vec3 n = spn_v3(0, 0, 0);
    double keep = 1;
    double frac = w->collide_fn(w->collide_user, i, w->x0[i], w->x[i], &n, &keep);
    if (!(frac < 1)) return;
    if (!(frac > 0)) frac = 0;
    if (!(keep >= 0)) keep = 0;
    w->x[i] = spn_v3_add(w->x0[i], spn_v3_scale(spn_v3_sub(w->x[i], w->x0[i]), frac));
    double vn = spn_v3_dot(w->v[i], n);
    if (vn < 0) w->v[i] = spn_v3_sub(w->v[i], spn_v3_scale(n, (1 + keep) * vn));
}

double spn__collide(spn_world *w, double dt)
{
    (void)dt;
    double lost = 0;
    for (uint32_t i = 0; i < w->np; i++) {
        if (w->inv_mass[i] == 0) continue;
        spn_vec3 x = w->x[i], v = w->v[i];
        double before = particle_energy(w, i);
        if (w->ncolliders) collide_builtin(w, i);
        if (w->collide_fn) collide_user(w, i);
        if (x.x != w->x[i].x || x.y != w->x[i].y || x.z != w->x[i].z || v.x != w->v[i].x || v.y != w->v[i].y ||
            v.z != w->v[i].z)
            lost += before - particle_energy(w, i);
    }
    return lost;
}

/* One Provot pass; true when some spring was shortened. */
static bool provot_pass(spn_world *w, double dt, double max_strain)
{
    bool moved = false;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        uint32_t a = w->sa[s], b = w->sb[s];
        double wa = w->inv_mass[a], wb = w->inv_mass[b];
        if (wa + wb == 0) continue;
        spn_vec3 l = spn_v3_sub(w->x[a], w->x[b]);
        double len = spn_v3_len(l), limit = w->rest[s] * (1 + max_strain);
        if (!(len > limit)) continue;
        spn_vec3 c = spn_v3_scale(l, (len - limit) / len / (wa + wb));
        spn_vec3 da = spn_v3_scale(c, -wa), db = spn_v3_scale(c, wb);
        w->x[a] = spn_v3_add(w->x[a], da);
        w->x[b] = spn_v3_add(w->x[b], db);
        w->v[a] = spn_v3_add(w->v[a], spn_v3_scale(da, 1 / dt));
        w->v[b] = spn_v3_add(w->v[b], spn_v3_scale(db, 1 / dt));
        moved = true;
    }
    return moved;
}

double spn__provot(spn_world *w, double dt)
{
    double before = spn_world_total_energy(w);
    for (int it = 0; it < w->def.provot_iterations; it++)
        if (!provot_pass(w, dt, w->def.provot_max_strain)) break;
    return before - spn_world_total_energy(w);
}

int spn__check_breakage(spn_world *w)
{
    if (!w->def.breakage || !w->any_limits) return 0;
    int breaks = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        double len = spn_v3_len(spn_v3_sub(w->x[w->sa[s]], w->x[w->sb[s]]));
        if (len >= w->bmin[s] && len <= w->bmax[s]) continue;
        w->sflags[s] |= SPN_SPRING_BROKEN;
        w->hflags[w->iperm[s]] |= SPN_SPRING_BROKEN;
        w->hs[w->iperm[s]] = spn__hot_spring(w, s);
        spn__lattice_drop(w);
        breaks++;
        if (w->break_fn) w->break_fn(w->break_user, s, w->t, len);
    }
    return breaks;
}

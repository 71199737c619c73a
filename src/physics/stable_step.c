/* The longest stable explicit step of a world's springs, by Gershgorin's
 * bound. Each free particle i of mass m with springs of stiffness k_s and
 * damping kd_s (intact ones, slack or not) has
 *   omega^2 <= 2 (sum k_s + extra) / m,   damping rate c <= 2 sum kd_s / m + drag
 * (drag: the world's viscous drag per unit mass),
 * and a damped oscillator stays stable under symplectic Euler for
 *   dt < 2 / (c / 2 + sqrt(c^2 / 4 + omega^2)).
 * The factor 2 bounds the spring's row of the stiffness (its own block and
 * the one coupling it to the other end) for particles of similar mass; it is
 * a bound for the springs alone: forces from a callback, air or colliders
 * are not in it (extra stands for a known stiffness of theirs).
 *
 * Two users: the animation runner's substeps per frame (spn_anim_stable_substeps,
 * with a margin per integrator), and the adaptive stepper's floor, which
 * this keeps from lying above the web's stable step (adaptive.c). */
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>

double spn__stable_step(const spn_world *w, double reach, double extra_stiffness, double *sums)
{
    const uint32_t np = w->np;
    double *ksum = sums, *csum = sums + np;
    for (uint32_t i = 0; i < 2 * np; i++) sums[i] = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        if (w->sflags[s] & SPN_SPRING_BROKEN) continue;
        ksum[w->sa[s]] += w->k[s];
        ksum[w->sb[s]] += w->k[s];
        csum[w->sa[s]] += w->kd[s];
        csum[w->sb[s]] += w->kd[s];
    }
    double dt = INFINITY; /* nothing bounds it: no free particle with a spring or drag */
    for (uint32_t i = 0; i < np; i++) {
        const double m = w->mass[i];
        if (w->inv_mass[i] == 0 || !(m > 0)) continue;
        const double om2 = 2 * (ksum[i] + extra_stiffness) / m, c = 2 * csum[i] / m + w->def.drag;
        const double rate = 0.5 * c + sqrt(0.25 * c * c + om2);
        if (rate > 0) dt = fmin(dt, 2 * reach / rate);
    }
    return dt;
}

double spn_world_stable_step(const spn_world *w, double extra_stiffness)
{
    double *sums = calloc(2 * (size_t)w->np + 1, sizeof *sums);
    if (!sums) return 0;
    const double dt = spn__stable_step(w, 1, extra_stiffness, sums);
    free(sums);
    return dt;
}

/* The woven web's shape found before its threads are laid (form finding).
 *
 * A spider does not leave its radii as it first draws them: it walks them
 * and tightens them, and the frame gives under their pull. Laid straight onto
 * the designed geometry at their strains, a woven web is far from rest: the
 * frame and the moorings stretch and bow under the radii, the radii lose most
 * of their strain (the geometric web's from 2% to 0.2%, a few to 1e-9), and
 * a web resting on nearly slack threads is where the settle's Newton solve
 * stalls and it falls back to seconds of stepping (docs/web-builders.md,
 * "Settling").
 *
 * Here every thread but the frame, the moorings and bridge lines (radii,
 * hub, signal, capture spiral, stabilimentum) first pulls at its laid
 * tension whatever its length: a spring of (almost) zero rest length whose
 * stiffness is that tension over its length, a force density. Such a thread
 * cannot go slack, and the static equilibrium of those pulls against the
 * elastic frame and moorings (and gravity) is a well-posed problem Newton
 * solves in a few steps. Each thread is then laid on the shape found at the
 * tension it pulls with there (its laid tension, changed by as much as its
 * length changed), so the web as built is at rest, every radius taut. Frame
 * and mooring threads keep the rest lengths they were laid with. Where the
 * solve falls short, and on webs of more than FORM_FIND_MAX_PARTICLES
 * particles, the web is left as laid. */
#include "web_internal.h"

#include "spinneret/equilibrium.h"

#include <math.h>
#include <stdlib.h>

/* Newton steps the form finding may take: on the species and geometric webs
 * measured it took 6-29, to 1e-9 N (docs/web-builders.md, "The woven web's
 * shape"). */
#define FORM_FIND_STEPS 60
/* Webs of more particles are left as designed (they settle at the cost of
 * their own settle). The cap takes in every species web up to the largest
 * --size: Zilla at 5 m has 1.1M particles. Measured 2026-12-05, build
 * with form finding, wall s and peak memory: Zilla 1 m (50k particles) 0.9
 * s, 143 MB; 2 m (185k) 3.2 s, 424 MB; 3 m (406k) 10 s, 1.0 GB; 5 m (1.1M)
 * 30 s, 2.6 GB; the other species at 5 m (323k-653k) 6-8 s, 0.8-1.1 GB.
 * With the multigrid refresh's scratch kept between Newton steps
 * (2026-12-06): 3 m 7.5 s, 5 m 23 s.
 * Until the multigrid's thin-aggregate rule (equilibrium_mg.c) and the
 * halved Newton steps (equilibrium.c) the 5 m Zilla web had not finished
 * after 18 minutes and 3.7 GB, and the cap was 200,000. */
#define FORM_FIND_MAX_PARTICLES 1500000
static uint32_t max_particles = FORM_FIND_MAX_PARTICLES;
static int max_steps = FORM_FIND_STEPS;

uint32_t spn__form_find_set_max_particles(uint32_t particles)
{
    const uint32_t old = max_particles;
    max_particles = particles;
    return old;
}

int spn__form_find_set_steps(int steps)
{
    const int old = max_steps;
    max_steps = steps;
    return old;
}

static bool elastic(uint32_t tag) { return tag == SPN_THREAD_FRAME || tag == SPN_THREAD_ANCHOR || tag == SPN_THREAD_BRIDGE; }

spn_status spn__web_form_find(spn_world *w, const double prestrain[SPN_WEB_KINDS], bool *found_out)
{
    const uint32_t ns = spn_world_spring_count(w), np = spn_world_particle_count(w);
    *found_out = false;
    if (np > max_particles) return SPN_OK;
    /* each thread's EA (0: not made a force density), rest length and
     * stiffness as laid, kept to be put back where the solve falls short */
    double *ea = malloc((ns ? ns : 1) * sizeof *ea), *rest = malloc((ns ? ns : 1) * sizeof *rest);
    double *k = malloc((ns ? ns : 1) * sizeof *k);
    spn_vec3 *x = malloc((np ? np : 1) * sizeof *x);
    if (!ea || !rest || !k || !x) {
        free(ea), free(rest), free(k), free(x);
        return spn_error(SPN_ERR_NOMEM, "out of memory finding the web's shape");
    }
    for (uint32_t i = 0; i < np; i++) x[i] = spn_world_position(w, i);
    for (uint32_t s = 0; s < ns; s++) {
        const spn_spring_info si = spn_world_spring(w, s);
        rest[s] = si.rest;
        k[s] = si.k;
        ea[s] = 0;
        if (si.broken || elastic(si.tag) || !(si.rest > 0 && si.length > 0)) continue;
        ea[s] = si.k * si.rest;
        const double pre = prestrain[si.tag < SPN_WEB_KINDS ? si.tag : 0];
        /* tension k (L - r) = ea pre at the laid length L, r a billionth of L */
        spn_world_set_spring_rest(w, s, 1e-9 * si.length);
        spn_world_set_spring_stiffness(w, s, ea[s] * pre / (si.length * (1 - 1e-9)), spn_world_spring_damping(w, s));
    }
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.max_iterations = max_steps;
    spn_equilibrium_report rep;
    spn_status st = spn_world_equilibrium(w, &d, &rep);
    const bool found = st == SPN_OK && rep.reason == SPN_EQUILIBRIUM_CONVERGED;
    for (uint32_t s = 0; s < ns; s++) {
        if (ea[s] == 0) continue;
        /* laid at the tension it pulls with in the shape found, so that the
         * web as built is that shape's equilibrium */
        const spn_spring_info si = spn_world_spring(w, s);
        const double r = found ? si.length / (1 + si.k * (si.length - si.rest) / ea[s]) : rest[s];
        spn_world_set_spring_rest(w, s, r);
        spn_world_set_spring_stiffness(w, s, found ? ea[s] / r : k[s], spn_world_spring_damping(w, s));
    }
    for (uint32_t i = 0; i < np; i++) {
        if (!found) spn_world_set_position(w, i, x[i]);
        spn_world_set_velocity(w, i, spn_v3(0, 0, 0));
    }
    free(ea), free(rest), free(k), free(x);
    *found_out = found;
    return st == SPN_ERR_NOMEM ? st : SPN_OK;
}

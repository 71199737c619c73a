/* Static equilibrium of a spring world: the positions where the springs,
 * gravity and a constant load balance, found directly (Newton's method on
 * the total potential) instead of by stepping time until the motion dies.
 * On a taut silk web this takes milliseconds where dynamic relaxation takes
 * minutes. See docs/physics-equilibrium.md for the method and its figures.
 *
 *   spn_equilibrium_def d = spn_equilibrium_def_default();
 *   d.load = spn_v3(0, 0, 1e-6);             // N on every free particle
 *   spn_equilibrium_report r;
 *   if (spn_world_equilibrium(w, &d, &r) == SPN_OK && r.reason == SPN_EQUILIBRIUM_CONVERGED) ...
 *
 * What is balanced: spring forces k(|l| - r) (tension-only springs push
 * nothing when slack), gravity m g, and the load. Damping, drag, air and the
 * force callback act only on moving webs and are not part of it. */
#ifndef SPINNERET_EQUILIBRIUM_H
#define SPINNERET_EQUILIBRIUM_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// How each Newton step's linear system is preconditioned for conjugate gradients.
typedef enum spn_precond {
    SPN_PRECOND_JACOBI = 0,  ///< the diagonal
    SPN_PRECOND_BLOCK_JACOBI, ///< each particle's 3x3 diagonal block, inverted
    SPN_PRECOND_MULTIGRID,   ///< smoothed-aggregation multigrid V-cycle over the spring graph, thread-line smoothing
    SPN_PRECOND_SGS,         ///< symmetric block Gauss-Seidel (sequential)
    SPN_PRECOND_AUTO,        ///< cyclic on a hub + rings x radials web (any radial count), else block Jacobi below 1,000 free particles and multigrid above (measured)
    SPN_PRECOND_CYCLIC,      ///< a hub + rings x radials web's rotational average solved exactly (Fourier modes around the rings)
    SPN_PRECOND_COUNT
} spn_precond;

/// "jacobi", "block-jacobi", "multigrid", "sgs", "auto", "cyclic".
SPN_API const char *spn_precond_name(spn_precond p);
/// The implicit step's CG preconditioner: SPN_PRECOND_BLOCK_JACOBI, SPN_PRECOND_MULTIGRID
/// (the hierarchy is kept across steps while no spring breaks), SPN_PRECOND_CYCLIC (a hub +
/// rings x radials web's rotational average solved exactly; the multigrid on other webs) or
/// SPN_PRECOND_AUTO (the default: from 4,096 particles the cyclic preconditioner on such a web at
/// any step and the multigrid on others at steps of 5 ms and up; on any web the multigrid from the
/// step after one that took block Jacobi over 100 CG iterations, at that step's length and longer
/// (under 4,096 particles not in steps with contacts); where it would take the multigrid, a web of up
/// to 65,536 free particles gets a sparse Cholesky factor of a step's matrix instead, kept over the
/// steps while its solves stay short;
/// block Jacobi otherwise). Results agree to the
/// solver tolerance; a clone of a world mid-run continues within it, not bit for bit
/// (the clone builds its hierarchy afresh). Changing the choice drops a kept hierarchy (the next step
/// that wants one builds it for the new choice).
SPN_API spn_status spn_world_set_implicit_preconditioner(spn_world *w, spn_precond p);
/// The implicit step's preconditioner as set (SPN_PRECOND_AUTO until then).
SPN_API spn_precond spn_world_implicit_preconditioner(const spn_world *w);
/// Parse a name as above; SPN_ERR_INVALID naming the choices otherwise.
SPN_API spn_status spn_precond_parse(const char *name, spn_precond *out);

typedef struct spn_equilibrium_def {
    double tolerance;     ///< stop when max |F_i| <= tolerance * force_scale; default 1e-6
    double abs_tolerance; ///< ... or when max |F_i| <= this [N]; default 0
    double force_scale;   ///< [N]; <= 0: the largest spring tension at the start, or, in a
                          ///< slack world, the largest external force on a particle. Default 0
    int max_iterations;   ///< Newton iterations, default 200
    int max_cg_iterations; ///< per linear solve, default 5000
    spn_precond preconditioner; ///< default SPN_PRECOND_AUTO
    bool gravity;         ///< include the world's gravity; default true
    spn_vec3 load;        ///< constant force on every free particle [N]; default 0
    const spn_vec3 *loads; ///< NULL or particle_count forces [N] added per particle
    int threads;          ///< 0: the world's setting; 1: one thread; n: n threads. Same bits for any
} spn_equilibrium_def;

SPN_API spn_equilibrium_def spn_equilibrium_def_default(void);

typedef enum spn_equilibrium_reason {
    SPN_EQUILIBRIUM_CONVERGED = 0, ///< the residual is under the tolerance
    SPN_EQUILIBRIUM_MAX_ITERATIONS, ///< max_iterations Newton steps did not get there
    SPN_EQUILIBRIUM_STALLED        ///< no step lowered the energy (rounding, or no unique rest state)
} spn_equilibrium_reason;

/// "converged", "max-iterations", "stalled".
SPN_API const char *spn_equilibrium_reason_name(spn_equilibrium_reason r);

typedef struct spn_equilibrium_report {
    spn_equilibrium_reason reason;
    int iterations;        ///< Newton steps taken
    int cg_iterations;     ///< conjugate-gradient iterations over all steps
    int backtracks;        ///< line-search halvings over all steps
    double residual;       ///< max |F_i| over free particles at the end [N]
    double residual_start; ///< ... at the start [N]
    double force_scale;    ///< the scale the tolerance was relative to [N]
    double energy_change;  ///< potential energy end - start [J] (<= 0)
    double max_displacement; ///< largest distance a particle moved [m]
    uint32_t worst;        ///< the particle with the largest residual at the end
    spn_precond preconditioner; ///< the one used (auto resolved)
} spn_equilibrium_report;

/// Move the free particles of `w` to a static equilibrium (velocities set to
/// zero), starting from where they are. SPN_OK when the run ended normally
/// (read report.reason: converged or not); SPN_ERR_INVALID for a bad
/// definition (the field named), SPN_ERR_UNSTABLE when the world holds a
/// non-finite value or the iteration produced one (the world is then left as
/// it was), SPN_ERR_NOMEM. `def` NULL: defaults; `report` may be NULL.
SPN_API spn_status spn_world_equilibrium(spn_world *w, const spn_equilibrium_def *def,
                                         spn_equilibrium_report *report);

#ifdef __cplusplus
}
#endif
#endif

/* Shared by the benchmark programs: the benchmark scenes (the standard orb web
 * at 5k, 100k and 1M particles, a cloth, a hanging chain), a clock, and an
 * independent float64 check of static equilibrium. */
#ifndef SPN_BENCH_COMMON_H
#define SPN_BENCH_COMMON_H

#include <spinneret/spinneret.h>

/// A size of the standard orb web: rings x radials (+ hub) particles.
typedef struct bench_orb_size {
    const char *name; ///< "5k", "100k", "1M"
    int rings, radials;
} bench_orb_size;

/// The three standard sizes, the same as the Bullet peer's.
extern const bench_orb_size BENCH_ORB_SIZES[3];

/// The standard orb web with silk values (spn_orb_scene_def_default), `threads` threads.
spn_world *bench_orb(const bench_orb_size *size, int threads);
/// The standard web's out-of-plane load: its pretension T0 (EA times the
/// pre-strain of spn_orb_scene_def_default) spread evenly over the free
/// particles of `w`, per particle; T0 into *t0 when not NULL.
spn_vec3 bench_orb_load(const spn_world *w, double *t0);
/// A 64 x 64 cloth, 1 m, 0.1 kg, k 500 N/m, pinned at its four corners (a hammock).
spn_world *bench_cloth(int threads);
/// A chain of 200 segments between anchors 1 m apart, 1.2 m long, 0.1 kg.
spn_world *bench_chain(int threads);

/// Monotonic seconds.
double bench_now(void);

/// One-minute load average, -1 if unknown: on a shared machine the wall-clock
/// figures mean little when it exceeds the core count.
double bench_load_average(void);

/// CPU seconds of this process (all threads): on a shared machine the
/// single-thread figure that wall time would give on an idle one.
double bench_cpu_now(void);

/// Largest net static force on a free particle [N], computed here from the
/// public API alone (positions, masses, k, rest, tension-only): springs,
/// gravity and a uniform `load` per free particle. Not the solver's code.
double bench_residual(const spn_world *w, spn_vec3 load);

/// Move `w` to equilibrium (springs, gravity, uniform `load`) by Newton with
/// the exact Hessian and a banded Cholesky solve, until the largest net force
/// is <= tol [N]. Returns the Newton iterations, or -1 on failure. The
/// reference for the sag check: independent of the library's solver.
int bench_reference_newton(spn_world *w, spn_vec3 load, double tol, int max_iter);

#endif

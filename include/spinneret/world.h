/* The spring world: particles joined by springs, stepped by one of several
 * integrators. Build it (add particles and springs), then step it; the world
 * compiles itself into flat arrays on the first step after any addition.
 *
 * Units are SI. A particle with mass 0 or `fixed` set does not move.
 * Spring force on particle a from b (Mehla 2005, eq. 4.14), l = x_a - x_b:
 *   f_a = -[k(|l| - r) + kd (l' . l)/|l|] l/|l|,   f_b = -f_a
 * A tension-only spring exerts nothing while |l| < r. */
#ifndef SPINNERET_WORLD_H
#define SPINNERET_WORLD_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct spn_world spn_world;

typedef enum spn_integrator {
    SPN_INTEGRATOR_EULER = 0,      ///< explicit (forward) Euler
    SPN_INTEGRATOR_SYMPLECTIC,     ///< semi-implicit Euler: v first, then x with the new v
    SPN_INTEGRATOR_RK4,            ///< classical Runge-Kutta, Mehla's method
    SPN_INTEGRATOR_ADAPTIVE,       ///< energy-stable adaptive sub-stepping (Juhasz & Bercovici)
    SPN_INTEGRATOR_IMPLICIT,       ///< linearised backward Euler (Baraff & Witkin 1998), CG solve
    SPN_INTEGRATOR_COUNT
} spn_integrator;

/// "euler", "symplectic", "rk4", "adaptive", "implicit".
SPN_API const char *spn_integrator_name(spn_integrator integrator);
/// Parse a name as above; SPN_ERR_INVALID naming the choices otherwise.
SPN_API spn_status spn_integrator_parse(const char *name, spn_integrator *out);

/// How a world is made. Start from spn_world_def_default(): zero is a real
/// value for gravity and drag, so zero never means "default".
typedef struct spn_world_def {
    spn_vec3 gravity;          ///< m/s^2, default (0, -9.81, 0)
    double drag;               ///< viscous drag per unit mass [1/s]: f = -drag * m * v; default 0
    spn_integrator integrator; ///< default SPN_INTEGRATOR_SYMPLECTIC
    double dt_min;             ///< adaptive: smallest sub-step [s], default 1e-7; the stepper goes under it
                               ///< to 0.8 of the springs' stable step (spn_world_stable_step) where that is shorter
    double dt_factor;          ///< adaptive: growth / halving factor, default 2
    double energy_jump;        ///< blow-up bound: total energy may not grow by more than this
                               ///< factor (relative to the larger of |E| and the elastic scale) in one step; default 1e3
    int threads;               ///< 0: OpenMP's default; 1: single-threaded; n: n threads
    bool breakage;             ///< break springs that leave [break_min, break_max]; default true
    double cg_tolerance;       ///< implicit: relative residual of the CG solve, default 1e-10
    int cg_max_iterations;     ///< implicit: default 1000
    double provot_max_strain;  ///< Provot deformation limit (0 = off), e.g. 0.1 = 10%
    int provot_iterations;     ///< Provot passes per step, default 4
    uint64_t seed;             ///< for anything random in the world, default 1
    uint32_t parallel_min;     ///< loops over fewer items than this run on one thread
                               ///< (waking threads costs more), default 32768; a lattice
                               ///< web's steps inside spn_world_advance from an eighth of it,
                               ///< on threads or one as timing shows faster (docs/physics-lattice.md)
} spn_world_def;

SPN_API spn_world_def spn_world_def_default(void);

/// A particle to add.
typedef struct spn_particle_def {
    spn_vec3 position;
    spn_vec3 velocity;
    double mass;      ///< kg; 0 means fixed
    bool fixed;       ///< does not move (inverse mass 0)
    uint32_t tag;     ///< user tag (web builders: anchor, hub, ...)
} spn_particle_def;

SPN_API spn_particle_def spn_particle_def_default(void);

/// A spring to add.
typedef struct spn_spring_def {
    uint32_t a, b;       ///< particle ids
    double k;            ///< stiffness [N/m]
    double kd;           ///< axial damping [N s/m]
    double rest;         ///< rest length [m]; negative: the current distance
    double break_min;    ///< breaks when shorter than this [m] (0: never)
    double break_max;    ///< breaks when longer than this [m] (INFINITY: never)
    bool tension_only;   ///< silk: goes slack, never pushes
    uint32_t tag;        ///< user tag (web builders: thread kind, see web.h)
    uint32_t stage;      ///< construction stage (web builders: frame, radii, ...)
    uint32_t order;      ///< construction order within the world
} spn_spring_def;

SPN_API spn_spring_def spn_spring_def_default(void);

/// A spring as it is now.
typedef struct spn_spring_info {
    uint32_t a, b;
    double k, kd, rest, break_min, break_max;
    bool tension_only, broken;
    uint32_t tag, stage, order;
    double length;   ///< current length [m]
    double tension;  ///< current elastic force k(|l| - r), 0 if broken or slack [N]
} spn_spring_info;

/// A world with these settings (NULL: spn_world_def_default()); NULL only when
/// out of memory. Settings out of range are kept: spn_world_compile, and so
/// the first step, refuses them with SPN_ERR_INVALID naming the field.
SPN_API spn_world *spn_world_create(const spn_world_def *def);
SPN_API void spn_world_destroy(spn_world *w);
/// A deep copy (particles, springs, state, settings; callbacks too).
SPN_API spn_world *spn_world_clone(const spn_world *w);
/// Make `dst` what spn_world_clone(src) would give, reusing dst's particle and
/// spring arrays where they are large enough: a snapshot taken every frame
/// into the same world costs no new memory (a clone of a 1M-particle web
/// spent most of its time on fresh pages). dst's own state, compiled data
/// and contacts are dropped. SPN_ERR_NOMEM leaves dst valid to destroy.
SPN_API spn_status spn_world_copy_into(spn_world *dst, const spn_world *src);
SPN_API const spn_world_def *spn_world_get_def(const spn_world *w);

/* ---- construction ---------------------------------------------------- */

/// Add a particle; its id is written to `id` (ids are dense from 0).
SPN_API spn_status spn_world_add_particle(spn_world *w, const spn_particle_def *def, uint32_t *id);
/// Add a spring between existing particles; its id is written to `id`.
SPN_API spn_status spn_world_add_spring(spn_world *w, const spn_spring_def *def, uint32_t *id);
/// Remove the springs whose `remove[i]` is true; the others keep their order
/// and are renumbered densely. Particles are kept.
SPN_API spn_status spn_world_remove_springs(spn_world *w, const bool *remove);
/// What a removed particle or spring maps to in spn_world_remove_particles.
#define SPN_REMOVED UINT32_MAX
/// Remove the `count` particles ids[0..count) and every spring with an end
/// among them, in place: everything else about the world stays (its
/// definition, callbacks with their user pointers, air, colliders, tag
/// diameters and hysteresis, lattice switch, precision, implicit
/// preconditioner, metadata, time, energy ledger), and the particles and
/// springs that remain keep their order and state bit for bit, renumbered
/// densely: a survivor's new id is its old id minus the number of removed ids
/// below it. Contacts keep their order, their particle ids renumbered.
/// `particle_map` (particle_count entries, as before the call) and
/// `spring_map` (spring_count entries), when not NULL, get each old id's new
/// id, or SPN_REMOVED. The world compiles again at the next step. Not from a
/// callback during a step. SPN_ERR_INVALID naming the ids[] entry that is out
/// of range, repeats an earlier one, or is a particle a contact uses; the
/// world is then unchanged. (Built-in colliders are fixed in space, tied to
/// no particle.)
SPN_API spn_status spn_world_remove_particles(spn_world *w, const uint32_t *ids, uint32_t count,
                                              uint32_t *particle_map, uint32_t *spring_map);
/// Number the particles anew, in place: order[k] is the old id of the
/// particle that becomes particle k (a permutation of 0 .. particle_count-1).
/// Each particle keeps its state and fields bit for bit under its new id;
/// springs keep their ids and order, their ends renumbered; contacts their
/// order, their particle ids renumbered; everything else stays, as in
/// spn_world_remove_particles. Why: the steps read a spring's two ends, and
/// on two threads a spring whose ends lie in different threads' ranges moves
/// data between cores every step; a numbering where particles near each other
/// are near in number (spn_world_locality_order) makes the parallel general
/// path pay (docs/physics.md, "Particle order"). The world compiles again at
/// the next step. Not from a callback during a step. SPN_ERR_INVALID naming
/// the order[] entry that is out of range or repeats an earlier one; the
/// world is then unchanged.
SPN_API spn_status spn_world_reorder_particles(spn_world *w, const uint32_t *order);
/// An order for spn_world_reorder_particles that numbers particles near each
/// other in space near each other: along a Z-order (Morton) curve through the
/// positions' bounding box, 21 bits an axis, ties by id. order: particle_count
/// entries. SPN_ERR_INVALID when w or order is NULL or a position is not
/// finite (naming the particle).
SPN_API spn_status spn_world_locality_order(const spn_world *w, uint32_t *order);
/// Build the flat stepping arrays now (stepping does it when needed).
SPN_API spn_status spn_world_compile(spn_world *w);
/// How the next Euler, symplectic or RK4 step of a compiled world runs:
/// "lattice" when its springs are exactly a hub + rings x radials web
/// (particle 0 the hub, 1 + ring * radials + radial the rest, as
/// spn_scene_orb numbers them) with no spring broken, no force callback and
/// no air drag: a stencil over rows, no spring records read; otherwise
/// "general". Both give the same trajectory (bit-identical on webs numbered
/// like spn_scene_orb below two sweep blocks, round-off apart otherwise).
SPN_API const char *spn_world_step_path(const spn_world *w);
/// Allow (the default) or forbid the lattice stencil, e.g. to measure or test
/// the general path on a regular web.
SPN_API void spn_world_set_lattice(spn_world *w, bool allow);
/// Whether the lattice stencil is allowed (spn_world_set_lattice).
SPN_API bool spn_world_lattice_allowed(const spn_world *w);
/// Arithmetic of the lattice path's Euler, symplectic and RK4 steps.
typedef enum spn_precision {
    SPN_PRECISION_FLOAT64 = 0, ///< the default: every step in double precision
    SPN_PRECISION_FLOAT32      ///< float32 springs and state, float64 differences (docs/physics-lattice.md)
} spn_precision;
/// Opt in to (or out of) the float32 lattice step. It applies only where
/// spn_world_step_path says "lattice" and the integrator is Euler,
/// symplectic or RK4, and only inside spn_world_advance calls of 2 or more
/// steps that keep one state copy per call (no callbacks, colliders, Provot
/// limits or breakable springs): a single step pays more to load and write
/// back the float32 state than it saves. Everything else stays float64.
/// Positions are kept as float32 displacements from the float64 positions,
/// which are brought up to date every 64 steps and at the end of the call;
/// spring differences carry the float64 geometry (relative error
/// ~1e-7 of a segment, so ~5e-6 of a 2% stretch). Same input, same bits on
/// any thread count; not the float64 path's bits, and spn_world_advance(n)
/// differs from n spn_world_step calls (float64) by float32 round-off.
SPN_API void spn_world_set_precision(spn_world *w, spn_precision precision);
SPN_API spn_precision spn_world_precision(const spn_world *w);

/* ---- reading and writing state --------------------------------------- */

SPN_API uint32_t spn_world_particle_count(const spn_world *w);
SPN_API uint32_t spn_world_spring_count(const spn_world *w);
/// Arrays of particle_count entries, valid until the next addition.
SPN_API const spn_vec3 *spn_world_positions(const spn_world *w);
SPN_API const spn_vec3 *spn_world_velocities(const spn_world *w);
SPN_API spn_vec3 spn_world_position(const spn_world *w, uint32_t i);
SPN_API spn_vec3 spn_world_velocity(const spn_world *w, uint32_t i);
SPN_API double spn_world_mass(const spn_world *w, uint32_t i);
SPN_API bool spn_world_is_fixed(const spn_world *w, uint32_t i);
SPN_API uint32_t spn_world_particle_tag(const spn_world *w, uint32_t i);
/// The definition that adds particle i again as it is now (position,
/// velocity, mass, fixed, tag): for copying a world's particles into another.
SPN_API spn_particle_def spn_world_particle_def(const spn_world *w, uint32_t i);
/// Position [m] and velocity [m/s] of particle i. SPN_ERR_INVALID naming the
/// particle, and nothing changed, when the vector is not finite (as
/// spn_world_add_particle refuses), and when a fixed particle is given a
/// velocity other than 0: fixed particles do not move (free one first with
/// spn_world_set_fixed). A fixed particle can be moved by hand (set_position).
SPN_API spn_status spn_world_set_position(spn_world *w, uint32_t i, spn_vec3 p);
SPN_API spn_status spn_world_set_velocity(spn_world *w, uint32_t i, spn_vec3 v);
/// Pin (fixed = true) or free a particle. Freeing one with mass 0 keeps it fixed.
SPN_API void spn_world_set_fixed(spn_world *w, uint32_t i, bool fixed);
/// Mass of particle i [kg] (0: fixed, as in spn_particle_def). SPN_ERR_INVALID
/// naming the particle, and nothing changed, when it is negative or not
/// finite (as spn_world_add_particle refuses).
SPN_API spn_status spn_world_set_mass(spn_world *w, uint32_t i, double mass);
SPN_API void spn_world_set_particle_tag(spn_world *w, uint32_t i, uint32_t tag);

SPN_API spn_spring_info spn_world_spring(const spn_world *w, uint32_t s);
/// The definition that adds spring s again as it is now (ends, stiffness,
/// damping, rest and break lengths, tension-only, tag, stage, order): for
/// copying a world's springs, and cheaper than spn_world_spring, which also
/// measures the spring. Whether it is broken: spn_world_spring_is_broken.
SPN_API spn_spring_def spn_world_spring_def(const spn_world *w, uint32_t s);
SPN_API bool spn_world_spring_is_broken(const spn_world *w, uint32_t s);
/// Rest length of spring s [m]. SPN_ERR_INVALID naming the spring, and
/// nothing changed, when it is negative or not finite (spn_world_add_spring
/// reads a negative rest as "the current length"; here it is refused).
SPN_API spn_status spn_world_set_spring_rest(spn_world *w, uint32_t s, double rest);
/// Stiffness k [N/m] and axial damping kd [N s/m] of spring s. SPN_ERR_INVALID
/// naming the spring and the field, and nothing changed, when either is
/// negative or not finite (as spn_world_add_spring refuses).
SPN_API spn_status spn_world_set_spring_stiffness(spn_world *w, uint32_t s, double k, double kd);
SPN_API void spn_world_set_spring_tag(spn_world *w, uint32_t s, uint32_t tag);
/// Break lengths of spring s as spn_spring_def has them (0, INFINITY: never);
/// SPN_ERR_INVALID naming the spring when either is NaN.
SPN_API spn_status spn_world_set_spring_breaks(spn_world *w, uint32_t s, double break_min, double break_max);
/// Break a spring by hand: flagged broken, it exerts no force from now on (its
/// stiffness is kept in spn_spring_info for the record); no callback.
SPN_API void spn_world_break_spring(spn_world *w, uint32_t s);

SPN_API void spn_world_set_integrator(spn_world *w, spn_integrator integrator);
/// Gravity [m/s^2]; SPN_ERR_INVALID, and nothing changed, when a component
/// is not finite (as a web file's world settings refuse it).
SPN_API spn_status spn_world_set_gravity(spn_world *w, spn_vec3 g);
/// Viscous drag per unit mass [1/s] (spn_world_def.drag); SPN_ERR_INVALID,
/// and nothing changed, when it is negative or not finite (as a web file's
/// world settings and spn_settle_def refuse it).
SPN_API spn_status spn_world_set_drag(spn_world *w, double drag);
SPN_API double spn_world_time(const spn_world *w);
SPN_API void spn_world_set_time(spn_world *w, double t);
SPN_API uint64_t spn_world_step_count(const spn_world *w);

/// Free-form metadata (a JSON object as text) carried into web files.
SPN_API spn_status spn_world_set_metadata(spn_world *w, const char *json_object);
SPN_API const char *spn_world_metadata(const spn_world *w);

/* ---- forces and events ------------------------------------------------ */

/// External force callback, called once per force evaluation (RK4 calls it
/// four times a step) with the state being evaluated. Add to `f`; do not
/// overwrite. `x`, `v`, `f` have particle_count entries.
typedef void (*spn_force_fn)(void *user, const spn_world *w, double t,
                             const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f);
SPN_API void spn_world_set_force_callback(spn_world *w, spn_force_fn fn, void *user);
/// The force callback (NULL: none); its user pointer into `user` when not NULL.
SPN_API spn_force_fn spn_world_force_callback(const spn_world *w, void **user);

/// Air velocity at a point and time [m/s], for aerodynamic drag on threads.
/// Called from one thread, once per particle that ends a tagged segment (at
/// its position) per force evaluation, in a fixed order, so it may keep state
/// (with spn_world_set_air_resolution set: at cell centres, only as it says).
/// A segment feels the mean of its two ends' air relative to them.
typedef spn_vec3 (*spn_air_fn)(void *user, double t, spn_vec3 position);
/// Air and its properties: segments whose tag has a diameter (below) feel drag
/// from the air velocity relative to them, normal component only, with a drag
/// coefficient from the cylinder Reynolds number. rho [kg/m^3], mu [Pa s].
SPN_API void spn_world_set_air(spn_world *w, spn_air_fn fn, void *user, double rho, double mu);
/// Declare the air function pure: its result depends on its arguments and on
/// nothing it changes, so it may be called from several threads at once and
/// in any order (spn_air_sample is; spn_air_attach declares it). The samples
/// of a force evaluation are then taken on the world's threads when the
/// spring pass takes them (from parallel_min segments). Same results on any
/// thread count. spn_world_set_air clears it.
SPN_API void spn_world_set_air_pure(spn_world *w, bool pure);
/// The air at many points at once: out[i] the air velocity at position[i],
/// i < n, at time t.
typedef void (*spn_air_batch_fn)(void *user, double t, const spn_vec3 *position, spn_vec3 *out, size_t n);
/// Optional, beside the air function (same user pointer): one that samples
/// many points in a call, giving at each what the air function gives there,
/// bit for bit (spn_air_sample_batch is spn_air_sample's, and spn_air_attach
/// sets it). The world then takes its samples through it, a run of particles
/// at a time (from several threads when pure). NULL: one call per particle.
/// spn_world_set_air clears it.
SPN_API void spn_world_set_air_batch(spn_world *w, spn_air_batch_fn fn);
/// Sample the air coarser than every force evaluation, for an air function
/// that is itself interpolated (spn_air_attach sets this for a field on a
/// grid: spn_air_resolution). A particle's air is then taken at the centre
/// of its cell of `spacing` [m], (floor(x / spacing) + 1/2) spacing in each
/// coordinate, at the two times k interval and (k + 1) interval [s] around
/// the evaluation's time t, and interpolated linearly between them in t.
/// The world keeps the two samples (as float) and takes them again only when
/// the cell or k changes, so a web swaying slowly samples its air once an
/// interval, not once a step. What a particle feels is a function of its
/// position and the time alone: the same on any thread count, after a copy
/// and in a replayed step. Both 0 (the default, and what spn_world_set_air
/// sets): the air at the particle itself at t, every evaluation.
/// SPN_ERR_INVALID for anything but two positive finite numbers or two zeros.
SPN_API spn_status spn_world_set_air_resolution(spn_world *w, double interval, double spacing);
/// The interval and spacing of spn_world_set_air_resolution (0, 0: exact).
SPN_API void spn_world_air_resolution(const spn_world *w, double *interval, double *spacing);
/// The air function (NULL: still air); its user pointer, rho and mu into the
/// arguments that are not NULL (rho 1.204, mu 1.81e-5 until set).
SPN_API spn_air_fn spn_world_air(const spn_world *w, void **user, double *rho, double *mu);
/// The power of the air's drag on the free particles at the world's state
/// and time [W], positive when the air drives the web: each tagged segment's
/// force (half on each end) dotted with its ends' velocities, as the next
/// step's force evaluation gives it, samples and all. 0 without air (no air
/// function, or no thread with a diameter); NAN if the world does not
/// compile. Call it between steps: it uses the step's scratch.
SPN_API double spn_world_air_power(spn_world *w);
/// Thread diameter [m] for springs with `tag` (0: no aerodynamic drag).
SPN_API void spn_world_set_tag_diameter(spn_world *w, uint32_t tag, double diameter);
/// The diameter set for `tag` (0 when none).
SPN_API double spn_world_tag_diameter(const spn_world *w, uint32_t tag);
/// Drag coefficient of a cylinder in cross-flow at Reynolds number `re`:
/// Lamb's Oseen result 8 pi / (Re (2.002 - ln Re)) below Re 0.5, White's
/// 1 + 10 Re^(-2/3) above Re 2, blended in ln Re between (docs/physics.md).
SPN_API double spn_cylinder_drag_coefficient(double re);

/// Called after the step in which spring `s` broke, with the time and length.
typedef void (*spn_break_fn)(void *user, uint32_t s, double t, double length);
SPN_API void spn_world_set_break_callback(spn_world *w, spn_break_fn fn, void *user);
/// The break callback (NULL: none); its user pointer into `user` when not NULL.
SPN_API spn_break_fn spn_world_break_callback(const spn_world *w, void **user);

/// Per-particle collision callback (Juhasz & Bercovici): the particle `i`
/// moves from `from` to `to` this step. Return the fraction of the move
/// allowed, in [0, 1] (1: no contact). On contact set `normal` (unit) and
/// `keep`: the normal velocity is reversed and multiplied by `keep`.
typedef double (*spn_collide_fn)(void *user, uint32_t i, spn_vec3 from, spn_vec3 to,
                                 spn_vec3 *normal, double *keep);
SPN_API void spn_world_set_collide_callback(spn_world *w, spn_collide_fn fn, void *user);
/// The collision callback (NULL: none); its user pointer into `user` when not NULL.
SPN_API spn_collide_fn spn_world_collide_callback(const spn_world *w, void **user);

/// Built-in colliders. Restitution in [0, 1] keeps that fraction of the normal
/// speed; friction in [0, 1] removes that fraction of the tangential speed on contact.
SPN_API spn_status spn_world_add_plane(spn_world *w, spn_vec3 normal, double offset,
                                       double restitution, double friction);
SPN_API spn_status spn_world_add_sphere(spn_world *w, spn_vec3 centre, double radius,
                                        double restitution, double friction);
/// Planes and spheres added so far.
SPN_API uint32_t spn_world_collider_count(const spn_world *w);

/* ---- silk hysteresis and stiff contacts (hysteresis.c, contact.c) ------- */

/// Silk's hysteresis for springs with `tag`: while stretched (s = |l| - r > 0)
/// the axial force becomes k s (1 + eta tanh(s' / (rate0 r))), eta = loss /
/// (2 - loss), so loading from slack to any length and back loses `loss` of the
/// work done, whatever the rate above a strain rate of `rate0` [1/s] (below
/// it the term is a dashpot). loss in [0, 1); 0 (the default of every tag)
/// turns it off. Applied as an axial damping coefficient set from the state
/// before each step (the secant eta k s tanh(.) / s'), so the implicit solver
/// carries it at any step and its loss is counted in spn_energy.dissipated;
/// explicit integrators get it capped at the stable m / (2 dt).
SPN_API spn_status spn_world_set_tag_hysteresis(spn_world *w, uint32_t tag, double loss, double rate0);
/// The loss set for `tag` (0 when none, to round-off of the stored eta
/// otherwise); its rate0 into `rate0` when not NULL (0 when none).
SPN_API double spn_world_tag_hysteresis(const spn_world *w, uint32_t tag, double *rate0);
/// Axial damping coefficient spring s used in the last step [N s/m]: kd plus
/// the hysteresis secant.
SPN_API double spn_world_spring_damping(const spn_world *w, uint32_t s);

/// A one-sided contact between particle p and the point (1 - u) x_a + u x_b
/// of a segment, for the implicit solver: the world applies the force
/// k y n to p (and -(1 - u), -u of it to a and b), where y = depth - n . (dg)
/// follows the separation g = x_p - (1 - u) x_a - u x_b from the step's
/// start, inside backward Euler's system (its stiffness -k n n^T joins the
/// springs'), so a stiff contact between a heavy body and 1e-10 kg thread
/// particles needs no explicit-sized step. A pushing contact (pull false)
/// acts while y > 0, a pulling one (a tether, pull true) while y < 0: a
/// contact whose y ends the step on the wrong side is dropped and the step
/// solved again without it (an active set), so contacts never stick.
typedef struct spn_contact {
    uint32_t p, a, b;
    double u;
    spn_vec3 n;     ///< unit
    double k;       ///< stiffness [N/m]
    double depth;   ///< y at the step's start [m]
    bool pull;      ///< a tether: acts while y < 0
    bool active;    ///< set by the world: in force at the end of the last step
} spn_contact;
/// Contacts for the following implicit steps (copied; n = 0 clears). Their
/// potential k y^2 / 2 is the caller's to count: spn_energy does not hold it,
/// and their forces are not external work. Other integrators ignore them.
SPN_API spn_status spn_world_set_contacts(spn_world *w, const spn_contact *contacts, uint32_t n);
/// The contacts as the last step left them (`active` filled in).
SPN_API const spn_contact *spn_world_contacts(const spn_world *w, uint32_t *n);

/* ---- stepping --------------------------------------------------------- */

/// What the last call to spn_world_step did.
typedef struct spn_step_report {
    double dt;            ///< outer step asked for
    int substeps;         ///< sub-steps taken (adaptive; 1 otherwise)
    int halvings;         ///< times a sub-step was halved (adaptive)
    int floored;          ///< adaptive: sub-steps taken at the floor (def.dt_min, or 0.8 of the springs'
                          ///< stable step where shorter) although they gained energy (many, and a
                          ///< blow-up: forces outside the springs need a lower dt_min)
    int cg_iterations;    ///< implicit: CG iterations summed over sub-steps
    int breaks;           ///< springs broken in this step
    int blocked;          ///< spn_world_advance: steps taken several to a pass over memory
                          ///< (the lattice step of a big web, docs/physics-lattice.md)
    int cuts;             ///< implicit with an energy limit (spn_world_set_energy_limit): times a
                          ///< step's move was halved because the whole move would have created
                          ///< energy (threads going slack within it, a solve out of CG iterations)
} spn_step_report;

/// Advance by dt seconds. On SPN_ERR_UNSTABLE the world keeps its state from
/// before the step and the message names the step and the particle.
SPN_API spn_status spn_world_step(spn_world *w, double dt);
/// Take n steps of dt (n >= 1) in one call, the per-call work paid once: the
/// same states, bit for bit, as n calls of spn_world_step. Explicit and RK4
/// runs without callbacks, colliders, Provot limits or breakable springs keep
/// one copy of the state per call instead of one per step. Stops at the first
/// failing step: on SPN_ERR_UNSTABLE the steps before it stand and the world
/// has its state from before it, the message naming it as spn_world_step
/// does. spn_world_last_step() then sums the report over the steps taken.
SPN_API spn_status spn_world_advance(spn_world *w, double dt, int n);
SPN_API spn_step_report spn_world_last_step(const spn_world *w);
/// The longest stable symplectic Euler step of the world's springs [s], by
/// Gershgorin's bound on each free particle (omega^2 <= 2 (sum k + extra) / m,
/// damping rate <= 2 sum kd / m + drag), with no margin: take a fraction of it.
/// Forces from callbacks, air and colliders are not in it (pass a known
/// stiffness of theirs per particle as extra_stiffness). INFINITY when nothing
/// bounds it (no free particle with a spring or drag); 0 when out of memory.
SPN_API double spn_world_stable_step(const spn_world *w, double extra_stiffness);
/// The fraction of spn_world_stable_step the library steps symplectic Euler
/// at (the animation runner's sub-steps, the adaptive stepper's floor), and
/// RK4, whose stability interval is 2.8 / 2 times as long.
#define SPN_STABLE_REACH 0.8
#define SPN_STABLE_REACH_RK4 1.4
/// The implicit solver's CG stop, changeable between steps (an interactive
/// viewer wants a looser one): relative residual in (0, 1), iteration cap >= 1.
SPN_API spn_status spn_world_set_solver_tolerance(spn_world *w, double cg_tolerance, int cg_max_iterations);
/// Implicit steps held to creating no energy. A step whose whole move would
/// raise the kinetic, elastic and gravitational energy above where it was
/// (net of the force callback's and air's work, beyond round-off) is halved
/// along its move until it does not; spn_step_report.cuts counts the
/// halvings, and the energy a cut step takes out is booked as dissipated. The
/// single linearised step goes wrong where threads go slack within it and,
/// worst, where its CG solve stopped at cg_max_iterations: on a species web
/// just built such steps ran away. spn_web_settle steps with
/// SPN_ENERGY_LIMIT_UNFINISHED. Off (the default), a step keeps its velocity
/// whole, which an animation wants (a halved move slows the whole web, not
/// only what went wrong). Steps with contacts are never cut: a prey's push is
/// work the balance does not see. docs/physics.md, "The energy limit".
typedef enum spn_energy_limit {
    SPN_ENERGY_LIMIT_OFF = 0,    ///< steps taken whole (default)
    SPN_ENERGY_LIMIT_UNFINISHED, ///< only steps whose CG solve stopped short (its cap, or a breakdown)
    SPN_ENERGY_LIMIT_ALWAYS      ///< every step
} spn_energy_limit;
/// SPN_ERR_INVALID for a value outside the enum.
SPN_API spn_status spn_world_set_energy_limit(spn_world *w, spn_energy_limit limit);
SPN_API spn_energy_limit spn_world_energy_limit(const spn_world *w);

/* ---- energy and equilibrium ------------------------------------------ */

typedef struct spn_energy {
    double kinetic;       ///< sum 1/2 m v^2 [J]
    double elastic;       ///< sum 1/2 k (|l| - r)^2 over intact, non-slack springs
    double gravitational; ///< sum -m g . x
    double external_work; ///< work done so far by the force callback and air (net of the thread's drag)
    double dissipated;    ///< energy removed so far by damping, drag, collisions and Provot passes
} spn_energy;

SPN_API spn_energy spn_world_energy(const spn_world *w);
/// Kinetic + elastic + gravitational.
SPN_API double spn_world_total_energy(const spn_world *w);
/// Largest net static force (springs, gravity, callback at zero velocity) on a
/// free particle [N]; its id in `which` when not NULL.
SPN_API double spn_world_max_residual(spn_world *w, uint32_t *which);

typedef struct spn_settle_def {
    double dt;             ///< step [s], default 1e-3
    double max_kinetic;    ///< kinetic energy threshold [J], default 1e-9
    double max_residual;   ///< residual force threshold [N], default 1e-6
    double max_time;       ///< give up after this much simulated time [s], default 60
    double min_time;       ///< do not test before this time [s], default 0
    double check_interval; ///< simulated seconds between tests, default 10*dt
    /// Air drag [1/s] the world has at least while settling, its own restored
    /// after: it changes the path to rest and how long it takes, not the rest
    /// state. Default 0 (the world's own drag).
    double drag;
} spn_settle_def;

SPN_API spn_settle_def spn_settle_def_default(void);

typedef enum spn_settle_reason {
    SPN_SETTLE_CONVERGED = 0, ///< both thresholds met
    SPN_SETTLE_TIMEOUT        ///< max_time passed first
} spn_settle_reason;

typedef struct spn_settle_report {
    spn_settle_reason reason;
    double time;         ///< simulated time spent [s]
    uint64_t steps;
    double kinetic;      ///< at the end [J]
    double residual;     ///< largest residual force at the end [N]
    double total_energy; ///< at the end [J]
    /// spn_web_settle: Newton steps of the static equilibrium it solves for
    /// first (0: none); `steps` 0 and reason CONVERGED: that solve found the
    /// rest state, and no time was stepped
    int newton_steps;
} spn_settle_report;

/// Step until at rest or out of time. SPN_OK on both outcomes (read the
/// report's reason); SPN_ERR_UNSTABLE when the run blew up.
SPN_API spn_status spn_world_settle(spn_world *w, const spn_settle_def *def, spn_settle_report *report);

#ifdef __cplusplus
}
#endif
#endif

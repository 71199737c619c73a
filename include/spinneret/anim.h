/* Webs in motion: the thesis' wind (Mehla 2005, fig. 5.45), a turbulent air
 * field for aerodynamic drag on threads, prey that strikes and breaks the web,
 * and the animation runner that steps a world frame by frame.
 * The wind models are force or air callbacks for the spring world (world.h);
 * the runner knows nothing of rendering: it hands each frame to a callback. */
#ifndef SPINNERET_ANIM_H
#define SPINNERET_ANIM_H

#include <signal.h>

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the thesis' wind (Mehla 2005, section 5.3.9, fig. 5.45) ----------- */

/// The constants of fig. 5.45. Every call of `windgen` advances an angle
/// counter by one; every `period` counts a new factor is drawn uniformly from
/// [-random_max, random_max]; the wind vector is (r W sin a, r W sin a, -W sin a)
/// with W = mass * gravity * gain. Each free particle gets the vector scaled by
/// exp(distance to the centre mass / (radius * falloff)).
typedef struct spn_thesis_wind_def {
    double mass;        ///< MASS [kg], default 1e-8 (the thesis' particle mass)
    double gravity;     ///< GRAVITY [m/s^2], default 9.8
    double gain;        ///< the factor 10 in WIND = MASS * GRAVITY * 10
    double random_max;  ///< factors drawn from [-random_max, random_max], default 3
    int period;         ///< counts between new factors, default 50
    double tick;        ///< simulated seconds per count, default 0.02 (the thesis' time step)
    bool radians;       ///< false (default): the counter is in degrees; true: sin(counter) in radians
    double falloff;     ///< alpha = radius * falloff, default 50
    int64_t centre;     ///< centre mass; -1 (default): the hub particle, else the one nearest the centroid
    double radius;      ///< web radius [m]; 0 (default): farthest particle from the centre
    uint64_t seed;      ///< the factors are successive spn_rng_range draws from this seed, default 1
} spn_thesis_wind_def;

typedef struct spn_thesis_wind spn_thesis_wind;

SPN_API spn_thesis_wind_def spn_thesis_wind_def_default(void);
/// Make the wind for world `w` (centre and radius are found now).
SPN_API spn_status spn_thesis_wind_create(const spn_thesis_wind_def *def, const spn_world *w, spn_thesis_wind **out);
SPN_API void spn_thesis_wind_destroy(spn_thesis_wind *wind);
/// `wind_vector` of fig. 5.45 at time t (counter = floor(t / tick)) [N].
SPN_API spn_vec3 spn_thesis_wind_vector(spn_thesis_wind *wind, double t);
/// The centre particle and radius in use.
SPN_API uint32_t spn_thesis_wind_centre(const spn_thesis_wind *wind);
SPN_API double spn_thesis_wind_radius(const spn_thesis_wind *wind);
/// A spn_force_fn: pass the wind as `user` to spn_world_set_force_callback.
SPN_API void spn_thesis_wind_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v,
                                   spn_vec3 *f);

/* ---- air: a turbulent velocity field U(x, t) ---------------------------- */

/// Mean wind with slow gusts and turbulence. Turbulence is a sum of random
/// Fourier modes with a Kolmogorov k^(-5/3) energy spectrum between
/// `integral_scale` and `small_scale`, divergence-free, carried along by the
/// mean wind (Taylor's frozen turbulence) and decorrelating with the eddy
/// turnover rate of each scale. Gusts scale the mean speed by a smooth random
/// process of unit variance and typical period `gust_period`.
typedef struct spn_air_def {
    double speed;          ///< mean speed [m/s], default 1
    spn_vec3 direction;    ///< mean direction (normalised), default (0, 0, -1)
    double gust;           ///< gust strength: std of the mean speed / speed, default 0.3
    double gust_period;    ///< typical gust period [s], default 4
    double turbulence;     ///< intensity: rms turbulent speed / speed, default 0.15
    double integral_scale; ///< largest eddies [m], default 1
    double small_scale;    ///< smallest eddies [m], default 0.15 (smaller ones average out over the threads)
    int modes;             ///< Fourier modes, default 64
    double rho;            ///< air density [kg/m^3], default 1.204
    double mu;             ///< air viscosity [Pa s], default 1.81e-5
    uint64_t seed;         ///< default 1
    double stop;           ///< the air is still from this time on [s], default INFINITY (never)
} spn_air_def;

typedef struct spn_air_field spn_air_field;

SPN_API spn_air_def spn_air_def_default(void);
SPN_API spn_status spn_air_create(const spn_air_def *def, spn_air_field **out);
SPN_API void spn_air_destroy(spn_air_field *air);
/// The field evaluated exactly [m/s].
SPN_API spn_vec3 spn_air_velocity(const spn_air_field *air, double t, spn_vec3 p);
/// Mean wind (gusts included, no turbulence) at time t [m/s].
SPN_API spn_vec3 spn_air_mean(const spn_air_field *air, double t);
/// Cache the field on a grid over the box [lo, hi] for fast sampling; points
/// outside are clamped to the box. Then spn_air_prepare(t0, t1) before each
/// step makes the time slices covering [t0, t1] ready, and spn_air_sample
/// interpolates (times outside the prepared slices are evaluated exactly).
/// A slice holds the grid rows (along x) the samples have touched since the
/// grid was set, and two more on each side, all of them before the first
/// sample; a point in a row a slice lacks is evaluated exactly until the
/// next spn_air_prepare, which adds its rows.
SPN_API spn_status spn_air_set_grid(spn_air_field *air, spn_vec3 lo, spn_vec3 hi, int nx, int ny, int nz,
                                    double slice_dt);
SPN_API spn_status spn_air_prepare(spn_air_field *air, double t0, double t1);
/// A spn_air_fn: pass the field as `user` to spn_world_set_air.
SPN_API spn_vec3 spn_air_sample(void *user, double t, spn_vec3 p);
/// A spn_air_batch_fn: spn_air_sample at each of p[0..n), the same bits,
/// with the points in vector lanes (several times faster on a grid).
SPN_API void spn_air_sample_batch(void *user, double t, const spn_vec3 *p, spn_vec3 *out, size_t n);
/// The resolution a world samples this field at (spn_world_set_air_resolution):
/// the slices' interval and a sixteenth of the grid's smallest cell. false,
/// and zeros, without a grid (the field is then exact at every sample).
SPN_API bool spn_air_resolution(const spn_air_field *air, double *interval, double *spacing);
/// spn_air_prepare for the steps [t0, t1] of a world that samples the field
/// at its resolution: the slices of the whole intervals the steps fall in.
SPN_API spn_status spn_air_prepare_held(spn_air_field *air, double t0, double t1);
/// Attach the field to a world: spn_world_set_air with its rho and mu (declared
/// pure: spn_world_set_air_pure), its batch sampler, its resolution on a grid
/// (spn_air_resolution; then prepare steps with spn_air_prepare_held), and the
/// thread diameters of spn_thread_diameter for every thread kind.
SPN_API void spn_air_attach(spn_air_field *air, spn_world *w);

/// Diameter [m] used for aerodynamic drag on a thread kind (spring tag):
/// dragline kinds a few um, the capture spiral larger for its glue droplets.
SPN_API double spn_thread_diameter(uint32_t tag);
/// Strain at which a thread kind breaks (Gosline et al. 1999: dragline 0.27,
/// viscid capture silk 2.7); INFINITY for kinds that never break.
SPN_API double spn_thread_breaking_strain(uint32_t tag);

/// Strain at which a thread kind yields (dragline ~0.04); past it the thread
/// flows plastically with `SPN_POST_YIELD` of its stiffness; INFINITY: elastic.
SPN_API double spn_thread_yield_strain(uint32_t tag);
#define SPN_POST_YIELD 0.3

/// Fraction of the work of a loading cycle a thread kind dissipates (silk's
/// hysteresis: Gosline et al. 1999, dragline 0.65; viscid capture silk more,
/// Denny 1976); 0 for kinds that are not silk.
SPN_API double spn_thread_hysteresis(uint32_t tag);
/// Strain rate [1/s] above which the hysteresis is rate-independent (below
/// it, a dashpot; see spn_world_set_tag_hysteresis). A strike strains the
/// frame and anchors at 0.01-1 /s (docs/wind-and-prey.md): at 0.1 the law
/// was half a dashpot there and the web gave back 50% instead of 35%.
#define SPN_HYSTERESIS_RATE 1e-3

/* ---- prey ---------------------------------------------------------------- */

/// Particle tag given to prey particles.
#define SPN_PARTICLE_PREY 64u

typedef struct spn_prey_def {
    spn_vec3 position;  ///< centre at t = 0 [m]
    spn_vec3 velocity;  ///< [m/s]
    double mass;        ///< [kg]
    double radius;      ///< [m]
} spn_prey_def;

/// Parse "x,y,z;vx,vy,vz;mass;radius".
SPN_API spn_status spn_prey_parse(const char *text, spn_prey_def *out);

typedef struct spn_impact_def {
    double contact_stiffness;  ///< penalty stiffness [N/m]; 0 (default): the stiffest spring's k
    double breaking_scale;     ///< multiplies every breaking strain, default 1
    bool breakage;             ///< set break lengths from the breaking strains, default true
    bool prey_gravity;         ///< prey fall (a pellet); false (default): they fly, lift balancing weight
    bool plastic;              ///< threads yield past spn_thread_yield_strain (silk's hysteresis), default true
    double glue_strength;      ///< capture-thread glue: a droplet holding the prey lets go past this pull [N],
                               ///< default 4e-5 (tens of uN, Opell & Hendricks 2007); 0: not sticky
    double glue_adhesion;      ///< glue per metre of capture thread in contact with the prey [N/m]: a
                               ///< segment's droplets hold together this times the length of it inside
                               ///< the prey (at least glue_strength); default 0.05 (50 uN/mm, Opell &
                               ///< Hendricks 2009); 0: one droplet per segment
    bool hysteresis;           ///< silk threads dissipate spn_thread_hysteresis of each loading cycle, default
                               ///< true (with the implicit solver; explicit steps go without)
    double glue_outline;       ///< the prey's sticky outline (legs, wings) as a multiple of its radius: once
                               ///< it has touched the web, capture thread within this distance of its centre
                               ///< glues to it; default 2.5 (a 4 mm body spans 2 cm); 1: the sphere only
} spn_impact_def;

SPN_API spn_impact_def spn_impact_def_default(void);

/// Energy bookkeeping per thread kind [J].
typedef struct spn_kind_energy {
    uint32_t tag;
    double elastic;     ///< elastic energy now minus at the start
    double damping;     ///< dissipated by the springs' damping and silk's hysteresis
    double plastic;     ///< dissipated by yielding (permanent stretch)
    double broken;      ///< elastic energy lost when springs broke
    uint32_t breaks;    ///< springs broken
} spn_kind_energy;

typedef enum spn_prey_outcome {
    SPN_PREY_MISSED = 0,   ///< never touched a thread
    SPN_PREY_STOPPED,      ///< arrested by the web (under half its first speed), no longer touching it
    SPN_PREY_PASSED,       ///< went through the web (beyond it, or flying on at half its first speed or more)
    SPN_PREY_BOUNCED,      ///< thrown back (in front of the web, or flying back at half its first speed)
    SPN_PREY_HELD          ///< stopped and still in contact with the web (touching it or glued)
} spn_prey_outcome;

SPN_API const char *spn_prey_outcome_name(spn_prey_outcome outcome);

#define SPN_KIND_SLOTS 32

typedef struct spn_impact_report {
    int nprey;
    spn_prey_outcome outcome[8];  ///< per prey (first 8)
    double prey_kinetic_start;    ///< [J], all prey
    double prey_kinetic_end;
    double total_start;           ///< kinetic + elastic + gravity + contact at t = 0 [J]
    double total_now;             ///< the same now
    double air_work;              ///< work done by the air on the web (negative: drag absorbed) [J]
    double wind_work;             ///< work of the force callback wind [J]
    double viscous;               ///< dissipated by the world's viscous drag [J]
    double solver;                ///< dissipated by the implicit solver itself (backward Euler) [J]
    double glue;                  ///< lost when glue droplets let go [J]
    int glue_held;                ///< droplets holding prey at the end
    double glue_strength_held;    ///< their strengths summed: the most the glue can hold the prey with [N]
    double contact_energy;        ///< penalty energy stored in contacts now [J]
    double web_kinetic;           ///< kinetic energy of the web now (still swinging) [J]
    double balance_error;         ///< |total_now + dissipated + broken - air - wind - total_start| [J]
    uint32_t breaks;
    double web_radius;            ///< largest distance of a web particle from the hub [m]
    double break_distance_max;    ///< broken springs' largest distance from the strike point [m]
    double break_distance_mean;
    int nkinds;
    spn_kind_energy kinds[SPN_KIND_SLOTS];
    /* When the strike ended (every prey arrested or through; -1: not yet), and
     * where the prey's lost energy was then, before the web's ringing is damped. */
    double strike_time;
    double strike_prey_kinetic_lost, strike_air, strike_web_kinetic, strike_glue;
    double strike_absorbed[SPN_KIND_SLOTS]; ///< per kind, in the order of `kinds`
} spn_impact_report;

typedef struct spn_impact spn_impact;

/// Add prey particles to `*w` and make its springs breakable. With breakage
/// on, `*w` is replaced by a copy with break lengths (the old one is
/// destroyed) that keeps everything set on it: its definition, state,
/// callbacks, air, tag diameters and hysteresis, colliders, contacts, lattice
/// switch, precision and implicit preconditioner.
SPN_API spn_status spn_impact_create(spn_world **w, const spn_prey_def *prey, int nprey, const spn_impact_def *def,
                                     spn_impact **out);
SPN_API void spn_impact_destroy(spn_impact *impact);
/// A spn_force_fn adding the sphere-segment contact forces (user = impact).
SPN_API void spn_impact_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v,
                              spn_vec3 *f);
/// The contact stiffness in use [N/m].
SPN_API double spn_impact_contact_stiffness(const spn_impact *impact);
/// Particle id of prey i.
SPN_API uint32_t spn_impact_prey_particle(const spn_impact *impact, int i);
/// Tell the ledger the world's force callback carries a wind (its work term);
/// the air's work it takes from the world (spn_world_air_power).
SPN_API void spn_impact_track_wind(spn_impact *impact, spn_force_fn fn, void *user);
/// Before every step of `dt`: with the implicit solver, hand the world the
/// prey's contacts (spn_world_set_contacts) so it integrates them implicitly.
SPN_API spn_status spn_impact_before_step(spn_impact *impact, spn_world *w, double dt);
/// The step the prey need now [s], `dt` at most: 3% of a radius of travel
/// at the prey's speed while it touches a thread or is glued; for each thread
/// closing in, max(3% of a radius, 0.8 of the gap) at the closing speed;
/// no limit from threads it moves away from.
SPN_API double spn_impact_step_limit(const spn_impact *impact, const spn_world *w, double dt);
/// Update the energy ledger after a step of `dt` (call after every step).
SPN_API void spn_impact_after_step(spn_impact *impact, spn_world *w, double dt);
SPN_API void spn_impact_report_get(spn_impact *impact, const spn_world *w, spn_impact_report *report);
/// Write the report as JSON.
SPN_API spn_status spn_impact_report_write(const spn_impact_report *report, spn_sink *sink);

/* ---- the animation runner ------------------------------------------------ */

typedef enum spn_wind_kind {
    SPN_WIND_NONE = 0,
    SPN_WIND_THESIS,   ///< fig. 5.45 as a force callback
    SPN_WIND_AIR       ///< the air field through aerodynamic drag
} spn_wind_kind;

typedef struct spn_anim_def {
    double duration;           ///< seconds, default 5
    double fps;                ///< frames per second, default 25
    int substeps;              ///< steps per frame; 0 (default): chosen for stability
    spn_integrator solver;     ///< SPN_INTEGRATOR_COUNT (default): keep the world's
    double cg_tolerance;       ///< implicit: CG relative residual for the run; 0 (default): keep the world's
    int first_frame;           ///< frames handed to the callback: first..last, default 0
    int last_frame;            ///< -1 (default): to the end
    spn_wind_kind wind;
    spn_thesis_wind_def thesis;
    spn_air_def air;
    double wind_stop;          ///< air: the wind stops at this time [s] (air.stop, the earlier); <0 (default): never
    const spn_prey_def *prey;  ///< prey to throw, may be NULL
    int nprey;
    spn_impact_def impact;
    uint64_t seed;             ///< seeds the wind models (overrides theirs), default 1
    volatile sig_atomic_t *stop; ///< when set non-zero the run stops after the current step
    /// Called after each frame is simulated (rendered or not), for progress bars.
    void (*progress)(void *user, int frame, int frames);
    void *progress_user;
} spn_anim_def;

SPN_API spn_anim_def spn_anim_def_default(void);

/// Frames are numbered from 0 (the initial state) to round(duration * fps).
SPN_API int spn_anim_frame_count(const spn_anim_def *def);

/// Called with each frame in [first_frame, last_frame]; a non-OK status stops the run.
typedef spn_status (*spn_anim_frame_fn)(void *user, int frame, const spn_world *w);

typedef struct spn_anim_report {
    int frames;            ///< frames handed to the callback
    int substeps;          ///< steps per frame used
    double dt;             ///< step [s]
    uint64_t steps;
    bool interrupted;
    bool has_impact;
    spn_impact_report impact;
} spn_anim_report;

/// Animate `*w` (prey may replace the world, see spn_impact_create).
SPN_API spn_status spn_animate(spn_world **w, const spn_anim_def *def, spn_anim_frame_fn fn, void *user,
                               spn_anim_report *report);

/// Explicit steps per frame for stability: the highest spring-mass frequency
/// of the world (plus `extra_stiffness` per particle) with a safety margin.
SPN_API int spn_anim_stable_substeps(const spn_world *w, double fps, spn_integrator solver, double extra_stiffness);

#ifdef __cplusplus
}
#endif
#endif

/* Web shooting: a strand shot from a hand to a target and played through four
 * phases, as procedural animation a game can advance every frame.
 *
 *   THWIP   the shot: the head flies a ballistic arc (smallest elevation that
 *           reaches the target) with smooth noise laid across it; the strand
 *           behind follows by a soft forward-reaching pull blended with each
 *           point's own velocity (after G. Zimmerman's breakdown, source 004).
 *   THWAP   contact: the strand becomes a chain of springs anchored at the
 *           target; tension runs back to the hand as a recoil wave and the
 *           strand snaps taut; a camera-shake value decays from the impact.
 *   WHOOSH  the character (a mass at the hand end) swings on the stretchy strand
 *           as a pendulum and follows through past the bottom of the arc.
 *   ZIPP    release: the hand end lets go; the strand goes slack, falls and
 *           drifts in the air, fades, and is gone after a set time.
 *
 * Every array a shot needs, the spring world included, is allocated by
 * spn_shot_create; spn_shot_step allocates nothing, so many shots can run at
 * 60 Hz in a game loop. Each phase starts from the exact state (positions and
 * velocities) the previous one ended in. Units SI; see docs/shooting.md. */
#ifndef SPINNERET_SHOOT_H
#define SPINNERET_SHOOT_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the ballistic path ----------------------------------------------- */

/// A solved ballistic shot: p(t) = origin + velocity t + gravity t^2 / 2,
/// passing through target at t = flight_time.
typedef struct spn_ballistic {
    spn_vec3 origin, target, gravity;
    spn_vec3 velocity;   ///< launch velocity [m/s]
    double speed;        ///< launch speed used [m/s]
    double min_speed;    ///< least speed that reaches the target [m/s]
    double elevation;    ///< launch angle above the plane normal to gravity [rad]
    double flight_time;  ///< time to reach the target [s]
} spn_ballistic;

/// Least launch speed that reaches `target` from `origin` under `gravity`:
/// v^2 = g (y + sqrt(x^2 + y^2)) with x the horizontal distance, y the rise.
SPN_API double spn_ballistic_min_speed(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity);
/// Solve for the smallest elevation that reaches `target` at `speed`. When the
/// target is out of reach: SPN_ERR_INVALID naming the speed needed, unless
/// `auto_speed`, which then uses the least speed that reaches it.
SPN_API spn_status spn_ballistic_solve(spn_vec3 origin, spn_vec3 target, spn_vec3 gravity, double speed,
                                       bool auto_speed, spn_ballistic *out);
SPN_API spn_vec3 spn_ballistic_position(const spn_ballistic *b, double t);
SPN_API spn_vec3 spn_ballistic_velocity(const spn_ballistic *b, double t);

/* ---- the smooth noise -------------------------------------------------- */

/// Zimmerman's smooth noise: `points` random values in [0, 1] spread over
/// `samples` samples, then three rounds of (trapezoidal integration, tilt so the
/// curve ends where it starts, scale into [-1, 1]). out[0] = out[samples-1] = 0,
/// max |out| = 1; a few gentle hills (more points, more hills).
/// points in [2, 256], samples in [points, 1 << 20].
SPN_API spn_status spn_smooth_noise(spn_rng *rng, int points, double *out, int samples);

/* ---- the shot ------------------------------------------------------------ */

typedef enum spn_shot_phase {
    SPN_SHOT_THWIP = 0, ///< in flight
    SPN_SHOT_THWAP,     ///< stuck at the target, snapping taut
    SPN_SHOT_WHOOSH,    ///< the character swings
    SPN_SHOT_ZIPP,      ///< released, falling and fading
    SPN_SHOT_DONE       ///< gone (no strand)
} spn_shot_phase;

/// "thwip", "thwap", "whoosh", "zipp", "done".
SPN_API const char *spn_shot_phase_name(spn_shot_phase phase);

/// How a shot is made. Start from spn_shot_def_default().
typedef struct spn_shot_def {
    /* THWIP: the shot */
    spn_vec3 origin;           ///< the hand [m], default (0, 1.5, 0)
    spn_vec3 target;           ///< where the strand sticks [m], default (10, 9, 0)
    double speed;              ///< launch speed [m/s], default 40
    bool auto_speed;           ///< out of reach: use the least speed that reaches, default false
    spn_vec3 gravity;          ///< [m/s^2], default (0, -9.81, 0)
    double noise_amplitude;    ///< largest sideways offset as a fraction of |target - origin|, default 0.05 (0: no noise)
    int noise_points;          ///< random points per noise curve (2: one hill; 3 and up: mostly two), default 3, in [2, 16]
    int points;                ///< strand resolution (polyline points), default 48, in [4, 1024]
    double blend;              ///< velocity factor: 0 pure pull, 1 pure velocity, default 0.5, in [0, 0.95]
    uint64_t seed;             ///< noise seed, default 1
    bool all_phases;           ///< false: the shot ends (DONE) at contact; default true
    /* THWAP: contact */
    double taut;               ///< taut rest length / |target - origin|, default 0.98, in [0.5, 1]
    double wave_speed;         ///< recoil wave speed back along the strand [m/s], default 60
    double snap_time;          ///< time one stretch of strand takes to tighten [s], default 0.08
    double hold_time;          ///< THWAP lasts until the wave reaches the hand plus this [s], default 0.1
    double shake_amplitude;    ///< camera shake at contact, default 1
    double shake_decay;        ///< shake time constant [s], default 0.12
    double linear_density;     ///< strand mass per length [kg/m], default 0.05
    double damping_ratio;      ///< per-segment damping as a fraction of critical, default 0.4
    double wave_damping;       ///< damping of ringing, relative to neighbours [1/s], default 20
    double sway_damping;       ///< THWAP, WHOOSH: damping relative to a rigid swing [1/s], default 6
    /* WHOOSH: the swing */
    double character_mass;     ///< [kg], default 70
    spn_vec3 character_velocity; ///< at the start of the swing [m/s], default (0, 0, 0)
    double stretch;            ///< strand strain under the character's weight, default 0.05, in [0.005, 0.5]
    double follow_through;     ///< release after regaining this fraction of the drop, default 0.5, in [0, 1]
    double whoosh_max_time;    ///< release at the latest after this swing time [s], default 3
    /* ZIPP: the release */
    double zipp_time;          ///< the released strand is gone after this [s], default 1.5
    double slack;              ///< the released strand's rest grows by this fraction of its length, default 0.15
    double air_drag;           ///< drag on the released strand [1/s], default 3
    spn_vec3 drift;            ///< air velocity carrying the released strand [m/s], default (0, 0, 1)
} spn_shot_def;

SPN_API spn_shot_def spn_shot_def_default(void);

typedef struct spn_shot spn_shot;

/// Check the definition, solve the path, draw the noise and allocate
/// everything the shot will need (including its spring world).
/// SPN_ERR_INVALID names the field; an unreachable target names the speed needed.
SPN_API spn_status spn_shot_create(const spn_shot_def *def, spn_shot **out);
SPN_API void spn_shot_destroy(spn_shot *shot);

/// Advance by dt seconds (0 < dt <= 1). Allocates nothing. Phase changes fall
/// inside the step at their exact times. SPN_ERR_UNSTABLE if the springs blew up.
SPN_API spn_status spn_shot_step(spn_shot *shot, double dt);

SPN_API spn_shot_phase spn_shot_phase_now(const spn_shot *shot);
/// Time since the shot was fired [s].
SPN_API double spn_shot_time(const spn_shot *shot);
/// Start time of `phase` [s], or a negative value if it has not begun.
SPN_API double spn_shot_phase_start(const spn_shot *shot, spn_shot_phase phase);
/// The strand as a polyline from the hand end to the head (anchored end);
/// returns the point count (0 when DONE). Points not yet spun out sit at the
/// hand. Valid until the next step.
SPN_API uint32_t spn_shot_strand(const spn_shot *shot, const spn_vec3 **points);
/// The character (the hand end, or after release, the character in free flight).
SPN_API spn_vec3 spn_shot_character(const spn_shot *shot);
SPN_API spn_vec3 spn_shot_character_velocity(const spn_shot *shot);
/// Camera shake in [0, shake_amplitude]: zero before contact, then decaying.
SPN_API double spn_shot_camera_shake(const spn_shot *shot);
/// Opacity of the strand in [0, 1]: fades to 0 at the end of ZIPP.
SPN_API double spn_shot_strand_alpha(const spn_shot *shot);
/// The solved path (without noise).
SPN_API const spn_ballistic *spn_shot_path(const spn_shot *shot);
/// The noisy path the head flies along, at time t in [0, flight_time].
SPN_API spn_vec3 spn_shot_head_path(const spn_shot *shot, double t);
/// When the head reaches the target: the path's flight time [s].
SPN_API double spn_shot_contact_time(const spn_shot *shot);

#ifdef __cplusplus
}
#endif
#endif

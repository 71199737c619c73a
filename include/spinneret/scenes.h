/* Shared scenes: small, well-understood worlds used by the tests, benchmarks,
 * examples and the viewer alike (a hanging chain, a cloth square, the
 * standard rings-by-radials orb web). */
#ifndef SPINNERET_SCENES_H
#define SPINNERET_SCENES_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The standard orb web: a hub particle, `rings` concentric rings crossed by
/// `radials` radii, the outermost ring fixed. Every segment is laid
/// `prestrain` beyond its rest length so the web is taut; a segment of rest
/// length r has k = ea / r and its mass (linear_density * r) shared by its ends.
/// Particles: 1 + rings * radials. Tags: radii SPN_THREAD_RADIUS, rings
/// SPN_THREAD_CAPTURE, the outermost ring SPN_THREAD_FRAME.
typedef struct spn_orb_scene_def {
    spn_vec3 centre;        ///< default (0, 0, 0)
    double radius;          ///< outer ring radius [m], default 0.15
    double hub_radius;      ///< first ring radius [m], default radius / rings
    int rings;              ///< default 20
    int radials;            ///< default 24
    double prestrain;       ///< default 0.02
    double ea;              ///< axial stiffness EA [N], default 0.07
    double damping_ratio;   ///< kd = damping_ratio * 2 sqrt(k m_seg), default 0.02
    double linear_density;  ///< kg/m, default 1e-6 (a few-um dragline)
    bool tension_only;      ///< silk does not push; default true
} spn_orb_scene_def;

SPN_API spn_orb_scene_def spn_orb_scene_def_default(void);
/// Particles in the standard web for `rings` x `radials` (1 + rings * radials).
SPN_API uint32_t spn_orb_scene_particles(int rings, int radials);
/// Build the standard web into a new world made from `world_def` (NULL: defaults).
SPN_API spn_status spn_scene_orb(const spn_world_def *world_def, const spn_orb_scene_def *def, spn_world **out);

/// A chain of `segments` springs between two fixed ends `a` and `b`, of total
/// rest length `length` (longer than |b - a| for a sagging chain), total mass
/// `mass`, each spring of stiffness k. Particles laid on the straight line.
SPN_API spn_status spn_scene_chain(const spn_world_def *world_def, spn_vec3 a, spn_vec3 b, int segments,
                                   double length, double mass, double k, double kd, spn_world **out);

/// A square cloth of nx x ny particles in the x-z plane at height y = height,
/// side `size`, total `mass`, stretch springs k along rows and columns and
/// shear springs k/2 along diagonals; the corners listed in `pinned_corners`
/// (bit 0: (0,0), bit 1: (nx-1,0), bit 2: (0,ny-1), bit 3: (nx-1,ny-1)) fixed.
SPN_API spn_status spn_scene_cloth(const spn_world_def *world_def, int nx, int ny, double size, double height,
                                   double mass, double k, double kd, unsigned pinned_corners, spn_world **out);

#ifdef __cplusplus
}
#endif
#endif

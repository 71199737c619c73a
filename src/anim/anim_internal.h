/* Shared between the files of src/anim: web geometry helpers and the world
 * copy that fixes breaking lengths. */
#ifndef SPN_ANIM_INTERNAL_H
#define SPN_ANIM_INTERNAL_H

#include "spinneret/anim.h"
#include "spinneret/web.h"

/* The hub particle: the first tagged SPN_PARTICLE_HUB, else the free particle
 * nearest the centroid of the free particles (all particles if none is free). */
uint32_t spn__hub_particle(const spn_world *w);
/* Largest distance from particle `centre` to a web particle (prey excluded). */
double spn__web_radius(const spn_world *w, uint32_t centre);
/* Bounding box of the web particles (prey excluded). */
void spn__web_bounds(const spn_world *w, spn_vec3 *lo, spn_vec3 *hi);
/* The length spring `in` breaks at, `strain` its kind's breaking strain:
 * rest * (1 + strain), or, for a spring already that long (a rest length
 * that is no silk's slack, as the physical builder's), its length now
 * times (1 + strain). */
double spn__break_length(spn_spring_info in, double strain);
/* A copy of `w` that steps as w would (spn_world_clone plus the contacts:
 * every setting and callback), but that its intact springs of a breakable
 * kind get break_max = min(break_max, spn__break_length(strain * scale)). */
spn_status spn__world_with_breaks(const spn_world *w, double scale, spn_world **out);

/* Cache `air` on the grid the animation runner uses for web `w` (runner.c):
 * its box grown by half its size, five nodes per smallest eddy of
 * `small_scale` [m], slices 5 ms apart. */
spn_status spn__air_grid_over_web(spn_air_field *air, const spn_world *w, double small_scale);

#endif

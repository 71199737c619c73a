/* Process-wide limits that keep a typo or a hostile file from asking for an
 * absurd amount of memory: a world may hold at most spn_max_particles()
 * particles and spn_max_springs() springs. Worlds refuse to grow past them
 * (SPN_ERR_NOMEM naming the count and the limit), and readers check declared
 * counts before allocating anything. One setting per process, read by every
 * thread; set it before building worlds. */
#ifndef SPINNERET_LIMITS_H
#define SPINNERET_LIMITS_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Default particle limit: 4 million (about 0.5 GB of world for an orb web).
#define SPN_DEFAULT_MAX_PARTICLES 4000000u
/// Springs allowed per particle allowed (a cloth has about 4; webs about 2).
#define SPN_SPRINGS_PER_PARTICLE 8u

SPN_API uint32_t spn_max_particles(void);
/// spn_max_particles() * SPN_SPRINGS_PER_PARTICLE, capped at UINT32_MAX - 1.
SPN_API uint32_t spn_max_springs(void);
/// Set the particle limit (1 .. UINT32_MAX - 1; 0 restores the default).
SPN_API void spn_set_max_particles(uint32_t n);
/// SPN_OK when `particles` and `springs` are within the limits, else
/// SPN_ERR_NOMEM (a size limit) with "WHAT: N particles is more than the limit of M ...".
SPN_API spn_status spn_check_counts(const char *what, uint64_t particles, uint64_t springs);

#ifdef __cplusplus
}
#endif

#endif

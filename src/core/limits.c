/* Process-wide size limits (see limits.h). A plain static: it is set once,
 * before any world is built, by the program's --max-particles. */
#include "spinneret/limits.h"

#include <stdint.h>

static uint32_t max_particles = SPN_DEFAULT_MAX_PARTICLES;

uint32_t spn_max_particles(void)
{
    return max_particles;
}

uint32_t spn_max_springs(void)
{
    uint64_t s = (uint64_t)max_particles * SPN_SPRINGS_PER_PARTICLE;
    return s >= UINT32_MAX ? UINT32_MAX - 1 : (uint32_t)s;
}

void spn_set_max_particles(uint32_t n)
{
    max_particles = n == 0 ? SPN_DEFAULT_MAX_PARTICLES : n >= UINT32_MAX ? UINT32_MAX - 1 : n;
}

spn_status spn_check_counts(const char *what, uint64_t particles, uint64_t springs)
{
    if (particles > spn_max_particles())
        return spn_error(SPN_ERR_NOMEM,
                         "%s: %llu particles is more than the limit of %u (raise it with --max-particles N)",
                         what ? what : "world", (unsigned long long)particles, spn_max_particles());
    if (springs > spn_max_springs())
        return spn_error(SPN_ERR_NOMEM,
                         "%s: %llu springs is more than the limit of %u (%u per particle allowed; raise it with "
                         "--max-particles N)",
                         what ? what : "world", (unsigned long long)springs, spn_max_springs(),
                         SPN_SPRINGS_PER_PARTICLE);
    return SPN_OK;
}

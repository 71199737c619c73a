/* Vectors and the portable RNG. xoshiro256** seeded through splitmix64, as
 * its authors recommend, so any 64-bit seed gives a well-mixed state. */
#include "spinneret/core.h"

#include <math.h>

double spn_v3_len(spn_vec3 a) { return sqrt(spn_v3_dot(a, a)); }

spn_vec3 spn_v3_norm(spn_vec3 a)
{
    double l = spn_v3_len(a);
    return l > 0 ? spn_v3_scale(a, 1.0 / l) : spn_v3(0, 0, 0);
}

bool spn_v3_finite(spn_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void spn_rng_seed(spn_rng *rng, uint64_t seed)
{
    for (int i = 0; i < 4; i++) rng->s[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t spn_rng_next(spn_rng *rng)
{
    uint64_t *s = rng->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double spn_rng_uniform(spn_rng *rng) { return (double)(spn_rng_next(rng) >> 11) * 0x1.0p-53; }

double spn_rng_range(spn_rng *rng, double lo, double hi) { return lo + (hi - lo) * spn_rng_uniform(rng); }

uint32_t spn_rng_below(spn_rng *rng, uint32_t n)
{
    /* Lemire's multiply-shift; the tiny bias is irrelevant for our uses. */
    return (uint32_t)(((spn_rng_next(rng) >> 32) * (uint64_t)n) >> 32);
}

double spn_rng_normal(spn_rng *rng)
{
    double u1 = spn_rng_uniform(rng), u2 = spn_rng_uniform(rng);
    if (u1 < 1e-300) u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

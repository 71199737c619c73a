/* Spinneret core: status codes, error messages, vectors, the seeded RNG and
 * atomic output files. Everything else in the library builds on this header. */
#ifndef SPINNERET_CORE_H
#define SPINNERET_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define SPN_API __attribute__((visibility("default")))
#define SPN_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define SPN_API
#define SPN_PRINTF(f, a)
#endif

/// Result of any operation that can fail. The message of the last failure in
/// this thread is available through spn_last_error().
typedef enum spn_status {
    SPN_OK = 0,
    SPN_ERR_INVALID,     ///< a bad argument or value (names the field)
    SPN_ERR_IO,          ///< a file could not be read or written
    SPN_ERR_FORMAT,      ///< a file's contents are malformed
    SPN_ERR_NOMEM,       ///< allocation failed or a size limit was passed
    SPN_ERR_UNSTABLE,    ///< the simulation blew up (NaN, infinity, energy jump)
    SPN_ERR_UNSUPPORTED, ///< a feature is missing (in this build or this file)
    SPN_ERR_INTERRUPTED  ///< stopped by a signal or a callback
} spn_status;

/// Library version, "MAJOR.MINOR.PATCH".
SPN_API const char *spn_version(void);

/// The message of the last error set in this thread ("" when none).
SPN_API const char *spn_last_error(void);
/// Set the last error message and return `status` (for `return spn_error(...)`).
SPN_API spn_status spn_error(spn_status status, const char *fmt, ...) SPN_PRINTF(2, 3);
/// Name of a status code ("ok", "invalid", ...).
SPN_API const char *spn_status_name(spn_status status);

#define SPN_PI 3.14159265358979323846

/// A 3-vector in metres, metres per second or newtons. Layout-compatible with double[3].
typedef struct spn_vec3 {
    double x, y, z;
} spn_vec3;

static inline spn_vec3 spn_v3(double x, double y, double z) { spn_vec3 v = {x, y, z}; return v; }
static inline spn_vec3 spn_v3_add(spn_vec3 a, spn_vec3 b) { return spn_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline spn_vec3 spn_v3_sub(spn_vec3 a, spn_vec3 b) { return spn_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline spn_vec3 spn_v3_scale(spn_vec3 a, double s) { return spn_v3(a.x * s, a.y * s, a.z * s); }
static inline double spn_v3_dot(spn_vec3 a, spn_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline spn_vec3 spn_v3_cross(spn_vec3 a, spn_vec3 b)
{
    return spn_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
SPN_API double spn_v3_len(spn_vec3 a);
/// Unit vector along `a`, or the zero vector when `a` is zero.
SPN_API spn_vec3 spn_v3_norm(spn_vec3 a);
SPN_API bool spn_v3_finite(spn_vec3 a);

/// Portable seeded generator (xoshiro256**): the same seed gives the same
/// sequence on every platform. Never use rand().
typedef struct spn_rng {
    uint64_t s[4];
} spn_rng;

SPN_API void spn_rng_seed(spn_rng *rng, uint64_t seed);
SPN_API uint64_t spn_rng_next(spn_rng *rng);
/// Uniform in [0, 1).
SPN_API double spn_rng_uniform(spn_rng *rng);
/// Uniform in [lo, hi).
SPN_API double spn_rng_range(spn_rng *rng, double lo, double hi);
/// Uniform integer in [0, n), n > 0.
SPN_API uint32_t spn_rng_below(spn_rng *rng, uint32_t n);
/// Standard normal (Box-Muller, deterministic).
SPN_API double spn_rng_normal(spn_rng *rng);

/// An output file written to a temporary name beside `path` and renamed into
/// place on commit, so a failed run never leaves a half-written file or
/// clobbers a good one.
typedef struct spn_atomic_file {
    FILE *fp;           ///< write here between open and commit
    char *path;         ///< final path
    char *tmp_path;     ///< temporary path in the same folder
} spn_atomic_file;

/// Create the temporary file. With `open_stream` false no FILE is opened (for
/// writers such as cairo that take a path: write to `tmp_path`, then commit).
SPN_API spn_status spn_atomic_open(spn_atomic_file *f, const char *path, bool open_stream);
/// Flush, close and rename into place. On failure the temporary is removed.
SPN_API spn_status spn_atomic_commit(spn_atomic_file *f);
/// Close and remove the temporary file; the final path is untouched.
SPN_API void spn_atomic_abort(spn_atomic_file *f);

/// A byte sink: writers emit through it so the same code writes to files,
/// memory and tests.
typedef struct spn_sink {
    spn_status (*write)(void *ctx, const void *data, size_t size);
    void *ctx;
} spn_sink;

SPN_API spn_sink spn_sink_file(FILE *fp);
SPN_API spn_status spn_sink_printf(spn_sink *sink, const char *fmt, ...) SPN_PRINTF(2, 3);

/// Growable in-memory buffer usable as a sink.
typedef struct spn_buffer {
    char *data;
    size_t size, capacity;
} spn_buffer;
SPN_API spn_sink spn_sink_buffer(spn_buffer *buf);
SPN_API void spn_buffer_free(spn_buffer *buf);

#ifdef __cplusplus
}
#endif
#endif

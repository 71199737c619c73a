/* Writing the web file (docs/web-format.md): a JSON object streamed through a
 * sink, columnar arrays on one line each, no tree built in memory, so saving a
 * large web costs no more than the text itself. The binary file's header is
 * the same document without its columns (web_binary.c writes the rest).
 *
 * Invariants: every float is written with the fewest digits (15, 16 or 17)
 * that strtod reads back to the same bits, so save -> load is exact, -0.0
 * included. A non-finite value is never written: the writer stops with an
 * error naming the particle or spring (a NaN in a file would make it
 * unreadable), and spn_web_save then leaves no file behind. */
#include "io_internal.h"

#include "spinneret/web.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_status spn__error_prefix(spn_status status, const char *prefix)
{
    char copy[1024];
    snprintf(copy, sizeof copy, "%s", spn_last_error());
    return spn_error(status, "%s: %s", prefix, copy);
}

/* The text goes out buffered (out.c); a writer error set in `st` stops it. */
typedef spn__out writer;

/* Each put_* is a no-op once a write failed, so the callers read straight. */
static void put(writer *wr, const char *text) { spn__out_put(wr, text, strlen(text)); }

static void put_double(writer *wr, double v)
{
    char buf[40];
    spn__format_double(buf, v);
    put(wr, buf);
}

static void put_u64(writer *wr, unsigned long long v)
{
    char buf[24];
    size_t n = sizeof buf;
    do buf[--n] = (char)('0' + v % 10);
    while (v /= 10);
    spn__out_put(wr, buf + n, sizeof buf - n);
}

static void put_vec3(writer *wr, spn_vec3 v)
{
    put(wr, "[");
    put_double(wr, v.x);
    put(wr, ", ");
    put_double(wr, v.y);
    put(wr, ", ");
    put_double(wr, v.z);
    put(wr, "]");
}

/* The metadata is re-printed by cJSON: the file is valid JSON even when the
 * world's metadata text was not, and a bad text is an error, not a bad file. */
static void put_metadata(writer *wr, const spn_world *w)
{
    if (wr->st != SPN_OK) return;
    cJSON *meta = cJSON_Parse(spn_world_metadata(w));
    if (!cJSON_IsObject(meta)) {
        cJSON_Delete(meta);
        wr->st = spn_error(SPN_ERR_INVALID, "world metadata is not a JSON object; not saved");
        return;
    }
    char *text = cJSON_PrintUnformatted(meta);
    cJSON_Delete(meta);
    if (!text) {
        wr->st = spn_error(SPN_ERR_NOMEM, "out of memory printing the metadata");
        return;
    }
    put(wr, "  \"metadata\": ");
    put(wr, text);
    put(wr, ",\n");
    cJSON_free(text);
}

static void put_settings(writer *wr, const spn_world *w)
{
    const spn_world_def *d = spn_world_get_def(w);
    put(wr, "  \"world\": {\n    \"gravity\": ");
    put_vec3(wr, d->gravity);
    put(wr, ",\n    \"drag\": ");
    put_double(wr, d->drag);
    put(wr, ",\n    \"integrator\": \"");
    put(wr, spn_integrator_name(d->integrator));
    put(wr, "\",\n    \"time\": ");
    put_double(wr, spn_world_time(w));
    put(wr, ",\n    \"breakage\": ");
    put(wr, d->breakage ? "true" : "false");
    const struct {
        const char *key;
        double value;
    } tuning[] = {{"dt_min", d->dt_min},
                  {"dt_factor", d->dt_factor},
                  {"energy_jump", d->energy_jump},
                  {"cg_tolerance", d->cg_tolerance},
                  {"cg_max_iterations", (double)d->cg_max_iterations},
                  {"provot_max_strain", d->provot_max_strain},
                  {"provot_iterations", (double)d->provot_iterations}};
    for (size_t i = 0; i < sizeof tuning / sizeof tuning[0]; i++) {
        put(wr, ",\n    \"");
        put(wr, tuning[i].key);
        put(wr, "\": ");
        put_double(wr, tuning[i].value);
    }
    /* Seeds past 2^53 do not survive a JSON number; they go as a string. */
    put(wr, ",\n    \"seed\": ");
    if (d->seed <= SPN__MAX_EXACT_INT) put_u64(wr, d->seed);
    else {
        put(wr, "\"");
        put_u64(wr, d->seed);
        put(wr, "\"");
    }
    put(wr, "\n  },\n");
}

static void put_thread_kinds(writer *wr)
{
    put(wr, "  \"thread_kinds\": {");
    const char *sep = "";
    for (uint32_t tag = 0; tag < 256; tag++) {
        const char *name = spn_thread_kind_name(tag);
        if (!name) continue;
        put(wr, sep);
        put(wr, "\"");
        put(wr, name);
        put(wr, "\": ");
        put_u64(wr, tag);
        sep = ", ";
    }
    put(wr, "},\n");
}

/* Values of one column for item i, read from the world. */
typedef double (*double_fn)(const spn_world *w, uint32_t i);
typedef unsigned long long (*int_fn)(const spn_world *w, uint32_t i);

static void put_double_column(writer *wr, const spn_world *w, const char *key, uint32_t n, double_fn get,
                              bool null_when_inf, const char *what)
{
    put(wr, ",\n    \"");
    put(wr, key);
    put(wr, "\": [");
    for (uint32_t i = 0; i < n && wr->st == SPN_OK; i++) {
        double v = get(w, i);
        if (i) put(wr, ", ");
        if (null_when_inf && isinf(v) && v > 0) put(wr, "null");
        else if (!isfinite(v))
            wr->st = spn_error(SPN_ERR_INVALID, "%s %u: %s is not finite; not saved", what, i, key);
        else put_double(wr, v);
    }
    put(wr, "]");
}

static void put_int_column(writer *wr, const spn_world *w, const char *key, uint32_t n, int_fn get)
{
    put(wr, ",\n    \"");
    put(wr, key);
    put(wr, "\": [");
    for (uint32_t i = 0; i < n && wr->st == SPN_OK; i++) {
        if (i) put(wr, ", ");
        put_u64(wr, get(w, i));
    }
    put(wr, "]");
}

static void put_vec3_column(writer *wr, const spn_world *w, const char *key, const spn_vec3 *v)
{
    uint32_t n = spn_world_particle_count(w);
    put(wr, ",\n    \"");
    put(wr, key);
    put(wr, "\": [");
    for (uint32_t i = 0; i < n && wr->st == SPN_OK; i++) {
        if (!spn_v3_finite(v[i])) {
            wr->st = spn_error(SPN_ERR_INVALID, "particle %u: %s is not finite; not saved", i, key);
            break;
        }
        const double c[3] = {v[i].x, v[i].y, v[i].z};
        for (int j = 0; j < 3; j++) {
            if (i || j) put(wr, ", ");
            put_double(wr, c[j]);
        }
    }
    put(wr, "]");
}

static double p_mass(const spn_world *w, uint32_t i) { return spn_world_mass(w, i); }
static unsigned long long p_fixed(const spn_world *w, uint32_t i) { return spn_world_is_fixed(w, i); }
static unsigned long long p_tag(const spn_world *w, uint32_t i) { return spn_world_particle_tag(w, i); }

static void put_particles(writer *wr, const spn_world *w, bool columns)
{
    uint32_t n = spn_world_particle_count(w);
    put(wr, "  \"particles\": {\n    \"count\": ");
    put_u64(wr, n);
    if (!columns) {
        put(wr, "\n  },\n");
        return;
    }
    put_vec3_column(wr, w, "position", spn_world_positions(w));
    put_vec3_column(wr, w, "velocity", spn_world_velocities(w));
    put_double_column(wr, w, "mass", n, p_mass, false, "particle");
    put_int_column(wr, w, "fixed", n, p_fixed);
    put_int_column(wr, w, "tag", n, p_tag);
    put(wr, "\n  },\n");
}

static double s_k(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).k; }
static double s_kd(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).kd; }
static double s_rest(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).rest; }
static double s_bmin(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).break_min; }
static double s_bmax(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).break_max; }
static unsigned long long s_a(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).a; }
static unsigned long long s_b(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).b; }
static unsigned long long s_tension(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).tension_only; }
static unsigned long long s_broken(const spn_world *w, uint32_t s) { return spn_world_spring_is_broken(w, s); }
static unsigned long long s_tag(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).tag; }
static unsigned long long s_stage(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).stage; }
static unsigned long long s_order(const spn_world *w, uint32_t s) { return spn_world_spring_def(w, s).order; }

static void put_springs(writer *wr, const spn_world *w, bool columns)
{
    uint32_t n = spn_world_spring_count(w);
    put(wr, "  \"springs\": {\n    \"count\": ");
    put_u64(wr, n);
    if (!columns) {
        put(wr, "\n  }\n");
        return;
    }
    put_int_column(wr, w, "a", n, s_a);
    put_int_column(wr, w, "b", n, s_b);
    put_double_column(wr, w, "k", n, s_k, false, "spring");
    put_double_column(wr, w, "kd", n, s_kd, false, "spring");
    put_double_column(wr, w, "rest", n, s_rest, false, "spring");
    put_double_column(wr, w, "break_min", n, s_bmin, false, "spring");
    put_double_column(wr, w, "break_max", n, s_bmax, true, "spring");
    put_int_column(wr, w, "tension_only", n, s_tension);
    put_int_column(wr, w, "broken", n, s_broken);
    put_int_column(wr, w, "tag", n, s_tag);
    put_int_column(wr, w, "stage", n, s_stage);
    put_int_column(wr, w, "order", n, s_order);
    put(wr, "\n  }\n");
}

/* The document; without its columns it is the binary file's header. */
static spn_status write_document(const spn_world *w, spn_sink *sink, bool columns)
{
    writer wr;
    spn__out_init(&wr, sink);
    put(&wr, "{\n  \"format\": \"" SPN__WEB_FORMAT_NAME "\",\n  \"version\": ");
    put_u64(&wr, SPN_WEB_FORMAT_VERSION);
    put(&wr, ",\n  \"units\": \"SI\",\n");
    put_metadata(&wr, w);
    put_settings(&wr, w);
    put_thread_kinds(&wr);
    put_particles(&wr, w, columns);
    put_springs(&wr, w, columns);
    put(&wr, "}\n");
    return spn__out_finish(&wr);
}

spn_status spn_web_write(const spn_world *w, spn_sink *sink)
{
    if (!w || !sink) return spn_error(SPN_ERR_INVALID, "spn_web_write: world and sink are required");
    return write_document(w, sink, true);
}

spn_status spn__web_write_header(const spn_world *w, spn_sink *sink) { return write_document(w, sink, false); }

bool spn_web_path_is_binary(const char *path)
{
    size_t n = path ? strlen(path) : 0, e = strlen(SPN_WEB_BINARY_EXTENSION);
    return n > e && strcmp(path + n - e, SPN_WEB_BINARY_EXTENSION) == 0;
}

spn_status spn_web_save(const spn_world *w, const char *path)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, true);
    if (st != SPN_OK) return st;
    spn_sink sink = spn_sink_file(f.fp);
    st = spn_web_path_is_binary(path) ? spn_web_write_binary(w, &sink) : spn_web_write(w, &sink);
    if (st != SPN_OK) {
        spn__error_prefix(st, path);
        spn_atomic_abort(&f);
        return st;
    }
    return spn_atomic_commit(&f);
}

/* The binary web file (docs/web-format.md, "Binary file"): the same content
 * as the JSON file, for webs too big to read and write as text in good time
 * (a million particles: 309 MB of JSON read in about 12 s, cJSON's tree of
 * 20 million numbers, and written in 2.0 s on this project's machine). A
 * short frame, the JSON document without its columns as the header, then
 * every column as raw little-endian numbers in a fixed order whose lengths
 * follow from the header's counts.
 *
 * Invariants: the columns are checked by the JSON reader's own calls
 * (web_read.c), so both files refuse the same values with the same field
 * names; the file's length must be exactly what its counts call for; a value
 * the JSON writer refuses (a non-finite number) is refused here too, before
 * the sink sees a byte of the columns. */
#include "io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* "\x89SPNWEB\n": the high byte catches 7-bit transfers, the newline
 * line-ending conversions, and no JSON text starts with either. */
static const unsigned char MAGIC[8] = {0x89, 'S', 'P', 'N', 'W', 'E', 'B', '\n'};
enum { LAYOUT_VERSION = 1, FRAME_BYTES = 16 };

/* The columns in file order: every float64 column, then the 32-bit ones,
 * then the bytes, so each starts aligned when the header is padded to 8. */
enum {
    C_POSITION, C_VELOCITY, C_MASS, C_K, C_KD, C_REST, C_BREAK_MIN, C_BREAK_MAX,
    C_PTAG, C_A, C_B, C_STAG, C_STAGE, C_ORDER,
    C_FIXED, C_TENSION_ONLY, C_BROKEN, C_COUNT
};
static const struct {
    const char *path;
    unsigned char width, bytes; /* entries per item, bytes per entry */
    bool springs;               /* one item per spring, else per particle */
} LAYOUT[C_COUNT] = {
    {"particles.position", 3, 8, false}, {"particles.velocity", 3, 8, false}, {"particles.mass", 1, 8, false},
    {"springs.k", 1, 8, true},           {"springs.kd", 1, 8, true},          {"springs.rest", 1, 8, true},
    {"springs.break_min", 1, 8, true},   {"springs.break_max", 1, 8, true},   {"particles.tag", 1, 4, false},
    {"springs.a", 1, 4, true},           {"springs.b", 1, 4, true},           {"springs.tag", 1, 4, true},
    {"springs.stage", 1, 4, true},       {"springs.order", 1, 4, true},       {"particles.fixed", 1, 1, false},
    {"springs.tension_only", 1, 1, true}, {"springs.broken", 1, 1, true},
};

/* In 64 bits whatever size_t is: counts up to SPN__WEB_MAX_COUNT make
 * columns of gigabytes, and a 32-bit size_t must not wrap before the file's
 * length is compared with them. */
static uint64_t column_bytes(int c, size_t np, size_t ns)
{
    return (uint64_t)(LAYOUT[c].springs ? ns : np) * LAYOUT[c].width * LAYOUT[c].bytes;
}

uint64_t spn__web_binary_size(size_t np, size_t ns)
{
    uint64_t total = 0;
    for (int c = 0; c < C_COUNT; c++) total += column_bytes(c, np, ns);
    return total;
}

size_t spn__web_binary_offset(const char *path, size_t np, size_t ns)
{
    uint64_t at = 0; /* below the file's length once that has been checked */
    for (int c = 0; c < C_COUNT && strcmp(LAYOUT[c].path, path) != 0; c++) at += column_bytes(c, np, ns);
    return (size_t)at;
}

bool spn__web_is_binary(const void *data, size_t size)
{
    return size >= sizeof MAGIC && memcmp(data, MAGIC, sizeof MAGIC) == 0;
}

/* ---- writing ------------------------------------------------------------- */

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> 8 * i);
}

static void put_f64(unsigned char *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(u >> 8 * i);
}

/* Entry j of item i of column c: a double for the float64 columns, a whole
 * number for the others; false, with the error set, for a float no web file
 * may hold (any non-finite value but break_max's +infinity, "never"). */
static bool entry(const spn_world *w, int c, uint32_t i, int j, double *d, uint32_t *u)
{
    if (!LAYOUT[c].springs) {
        switch (c) {
        case C_POSITION:
        case C_VELOCITY: {
            const spn_vec3 v = (c == C_POSITION ? spn_world_positions(w) : spn_world_velocities(w))[i];
            *d = j == 0 ? v.x : j == 1 ? v.y : v.z;
            break;
        }
        case C_MASS: *d = spn_world_mass(w, i); break;
        case C_PTAG: *u = spn_world_particle_tag(w, i); break;
        default: *u = spn_world_is_fixed(w, i); break;
        }
    } else {
        const spn_spring_def s = spn_world_spring_def(w, i);
        switch (c) {
        case C_K: *d = s.k; break;
        case C_KD: *d = s.kd; break;
        case C_REST: *d = s.rest; break;
        case C_BREAK_MIN: *d = s.break_min; break;
        case C_BREAK_MAX: *d = s.break_max; break;
        case C_A: *u = s.a; break;
        case C_B: *u = s.b; break;
        case C_STAG: *u = s.tag; break;
        case C_STAGE: *u = s.stage; break;
        case C_ORDER: *u = s.order; break;
        case C_TENSION_ONLY: *u = s.tension_only; break;
        default: *u = spn_world_spring_is_broken(w, i); break;
        }
    }
    if (LAYOUT[c].bytes != 8 || isfinite(*d) || (c == C_BREAK_MAX && *d == INFINITY)) return true;
    spn_error(SPN_ERR_INVALID, "%s %u: %s is not finite; not saved", LAYOUT[c].springs ? "spring" : "particle", i,
              strchr(LAYOUT[c].path, '.') + 1);
    return false;
}

/* Every value checked before the first byte goes out, so a refused world
 * leaves a sink (a buffer, a socket) with nothing written. */
static spn_status check_values(const spn_world *w, uint32_t np, uint32_t ns)
{
    for (int c = 0; c < C_COUNT; c++) {
        if (LAYOUT[c].bytes != 8) continue;
        const uint32_t n = LAYOUT[c].springs ? ns : np;
        double d = 0;
        uint32_t u = 0;
        for (uint32_t i = 0; i < n; i++)
            for (int j = 0; j < LAYOUT[c].width; j++)
                if (!entry(w, c, i, j, &d, &u)) return SPN_ERR_INVALID;
    }
    return SPN_OK;
}

spn_status spn_web_write_binary(const spn_world *w, spn_sink *sink)
{
    if (!w || !sink) return spn_error(SPN_ERR_INVALID, "spn_web_write_binary: world and sink are required");
    const uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    spn_status st = check_values(w, np, ns);
    if (st != SPN_OK) return st;
    spn_buffer header = {0};
    spn_sink hs = spn_sink_buffer(&header);
    st = spn__web_write_header(w, &hs);
    if (st == SPN_OK && header.size > UINT32_MAX) st = spn_error(SPN_ERR_INVALID, "web file header too long");
    if (st != SPN_OK) {
        spn_buffer_free(&header);
        return st;
    }
    spn__out o;
    spn__out_init(&o, sink);
    unsigned char *frame = spn__out_room(&o, FRAME_BYTES);
    memcpy(frame, MAGIC, sizeof MAGIC);
    put_u32(frame + 8, LAYOUT_VERSION);
    put_u32(frame + 12, (uint32_t)header.size);
    spn__out_put(&o, header.data, header.size);
    const size_t pad = (8 - (FRAME_BYTES + header.size) % 8) % 8;
    spn_buffer_free(&header);
    memset(spn__out_room(&o, pad), 0, pad);
    for (int c = 0; c < C_COUNT && o.st == SPN_OK; c++) {
        const uint32_t n = LAYOUT[c].springs ? ns : np;
        for (uint32_t i = 0; i < n; i++)
            for (int j = 0; j < LAYOUT[c].width; j++) {
                double d = 0;
                uint32_t u = 0;
                entry(w, c, i, j, &d, &u); /* checked above */
                if (LAYOUT[c].bytes == 8) put_f64(spn__out_room(&o, 8), d);
                else if (LAYOUT[c].bytes == 4) put_u32(spn__out_room(&o, 4), u);
                else *spn__out_room(&o, 1) = (unsigned char)u;
            }
    }
    return spn__out_finish(&o);
}

/* ---- reading -------------------------------------------------------------- */

spn_status spn__web_parse_binary(const unsigned char *data, size_t size, const char *name, spn_world **out)
{
    *out = NULL;
    if (size < FRAME_BYTES)
        return spn_error(SPN_ERR_FORMAT, "%s: binary web file cut short: %zu bytes, its frame alone takes %d", name,
                         size, FRAME_BYTES);
    const uint32_t version = spn__get_u32(data + 8), hlen = spn__get_u32(data + 12);
    if (version != LAYOUT_VERSION)
        return spn_error(SPN_ERR_FORMAT, "%s: binary web file layout %u not supported (this build reads layout %d)",
                         name, version, LAYOUT_VERSION);
    const size_t start = FRAME_BYTES + (size_t)hlen, pad = (8 - start % 8) % 8;
    if (hlen > size - FRAME_BYTES || pad > size - start)
        return spn_error(SPN_ERR_FORMAT, "%s: binary web file cut short: its header claims %u bytes, %zu follow", name,
                         hlen, size - FRAME_BYTES);
    cJSON *root = NULL;
    spn_status st = spn__web_parse_text((const char *)data + FRAME_BYTES, hlen, name, "header", &root);
    for (size_t i = start; i < start + pad && st == SPN_OK; i++)
        if (data[i]) st = spn_error(SPN_ERR_FORMAT, "%s: byte %zu: the padding after the header is not zero", name, i);
    if (st == SPN_OK) st = spn__web_read_root(name, root, data + start + pad, size - start - pad, NULL, out);
    cJSON_Delete(root);
    return st;
}

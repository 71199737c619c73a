/* Shared between the files of src/io: the web file's name and limits, and
 * small helpers for numbers and messages. */
#ifndef SPN_IO_INTERNAL_H
#define SPN_IO_INTERNAL_H

#include "spinneret/io.h"

#include <stdint.h>
#include <string.h>

#define SPN__WEB_FORMAT_NAME "spinneret-web"
/* Integers up to 2^53 survive a JSON number (a double) exactly. */
#define SPN__MAX_EXACT_INT 9007199254740992ull
/* Largest particle or spring count a web file may claim, and the largest file
 * read: beyond these a claim is refused before anything is allocated. */
#define SPN__WEB_MAX_COUNT 100000000u
#define SPN__WEB_MAX_BYTES ((size_t)1 << 30)

/* `v` with the fewest digits (15, 16 or 17) that read back to the same bits,
 * as %.{15,16,17}g print it (shortest.c): by integer arithmetic where it
 * can, else by spn__format_double_printf, which prints and reads back each. */
void spn__format_double(char out[40], double v);
void spn__format_double_printf(char out[40], double v);
/* Output to a sink in pieces of up to 16 KiB (out.c). After a failed write,
 * or once a writer sets `st` to an error, nothing more reaches the sink. */
typedef struct spn__out {
    spn_sink *sink;
    spn_status st;
    size_t used;
    char buf[1 << 14];
} spn__out;
void spn__out_init(spn__out *o, spn_sink *sink);
void spn__out_put(spn__out *o, const void *data, size_t n);
/* n bytes (n <= 16 KiB) to fill in place, in order with the other output */
unsigned char *spn__out_room(spn__out *o, size_t n);
/* Everything written; the first error, if any. */
spn_status spn__out_finish(spn__out *o);

/* The web document without its columns: the binary file's header. */
spn_status spn__web_write_header(const spn_world *w, spn_sink *sink);
/* The binary file (web_binary.c): `data` starts with its magic. */
spn_status spn__web_parse_binary(const unsigned char *data, size_t size, const char *name, spn_world **out);
/* Does data[0..size) start with the binary file's magic? */
bool spn__web_is_binary(const void *data, size_t size);
/* Bytes of a binary file's columns for np particles and ns springs, and
 * where the column named `path` ("particles.mass") starts in them. */
uint64_t spn__web_binary_size(size_t np, size_t ns);
size_t spn__web_binary_offset(const char *path, size_t np, size_t ns);
/* Little-endian numbers, whatever the host's byte order. */
static inline double spn__get_f64(const unsigned char *p)
{
    uint64_t u = 0;
    for (int i = 7; i >= 0; i--) u = u << 8 | p[i];
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}
static inline uint32_t spn__get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* JSON text parsed into *root (web_read.c), or refused naming `name` and,
 * when not NULL, the `part` of the file ("header"): empty, a NUL byte, a
 * syntax error or text after the document, with its line and column. */
struct cJSON;
spn_status spn__web_parse_text(const char *text, size_t size, const char *name, const char *part,
                               struct cJSON **root);
/* The columns of a JSON web file read straight from its text (web_lift.c):
 * each array of numbers and nulls that is a field of the top-level
 * "particles" or "springs" object, as doubles (null as NaN), and the text
 * with each such array replaced by "[]" (the skeleton, NUL-terminated),
 * which is valid JSON exactly when the text is. count 0: nothing taken,
 * no skeleton. Fails only for want of memory. */
enum { SPN__LIFT_MAX = 32 };
typedef struct spn__lifted_col {
    char path[32]; /* "particles.position" */
    double *v;
    size_t n;
} spn__lifted_col;
typedef struct spn__lifted {
    spn__lifted_col col[SPN__LIFT_MAX];
    int count;
    char *skeleton;
    size_t skeleton_size;
} spn__lifted;
spn_status spn__web_lift(const char *text, size_t size, spn__lifted *l);
const spn__lifted_col *spn__lifted_find(const spn__lifted *l, const char *path);
void spn__lifted_free(spn__lifted *l);
/* spn_web_parse for JSON text, with the columns read by web_lift.c or
 * (lift false, for the tests' and fuzzers' comparisons) all by cJSON. */
spn_status spn__web_parse_json(const char *text, size_t size, const char *name, bool lift, spn_world **out);

/* A parsed document (web_read.c): its header checked, then read into a world;
 * `payload` NULL for a JSON file, or the binary file's columns; `lifted`
 * the columns taken from a JSON file's text, or NULL. */
spn_status spn__web_read_root(const char *name, const struct cJSON *root, const unsigned char *payload,
                              size_t payload_size, const spn__lifted *lifted, spn_world **out);

/* Put "prefix: " before the last error message; returns `status`. */
spn_status spn__error_prefix(spn_status status, const char *prefix);

#endif

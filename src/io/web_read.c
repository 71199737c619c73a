/* Reading the web file (docs/web-format.md). The text is parsed by cJSON, then
 * every field is checked before it reaches the world, and the first bad value
 * is reported as "FILE: FIELD[INDEX]: what is wrong". A binary file
 * (web_binary.c) has the same document as its header and its columns as raw
 * numbers; they pass the same checks here, read by the same column calls, as
 * do the big columns of a JSON file read straight from its text
 * (web_lift.c), which give every entry and message that cJSON's would.
 *
 * Invariants: on any failure *out is NULL and everything built is freed (never
 * a half-built world). Array lengths are checked against the declared counts
 * before the world is made, so a huge count with short arrays is refused
 * without allocating; counts are capped by SPN__WEB_MAX_COUNT. Unknown fields
 * inside the known objects are refused (a misspelt optional field would
 * otherwise be silently ignored); free-form data belongs in "metadata". */
#include "io_internal.h"

#include "spinneret/limits.h"

#include <cjson/cJSON.h>
#include <errno.h>
#if defined(__unix__)
#include <sys/mman.h>
#include <sys/stat.h>
#endif
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

typedef struct reader {
    const char *name;              /* the file, for messages */
    const unsigned char *payload;  /* a binary file's columns (web_binary.c); NULL for JSON */
    size_t particles, springs;     /* the counts, for the columns' offsets in the payload */
    const spn__lifted *lifted;     /* a JSON file's columns read from its text, or NULL */
} reader;

static spn_status bad(const reader *r, const char *fmt, ...) SPN_PRINTF(2, 3);
static spn_status bad(const reader *r, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return spn_error(SPN_ERR_FORMAT, "%s: %s", r->name, msg);
}

static const char *type_name(const cJSON *j)
{
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an invalid value";
}

/* Every key of `obj` must be one of `allowed` (NULL-terminated), once: cJSON
 * would quietly take the first of two equal keys. */
static spn_status check_keys(const reader *r, const cJSON *obj, const char *path, const char *const *allowed)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        bool known = false;
        for (const char *const *k = allowed; *k && !known; k++) known = strcmp(*k, c->string) == 0;
        if (!known) return bad(r, "%s%s%s: unknown field", path, *path ? "." : "", c->string);
        for (const cJSON *d = obj->child; d != c; d = d->next)
            if (strcmp(d->string, c->string) == 0)
                return bad(r, "%s%s%s: field appears twice", path, *path ? "." : "", c->string);
    }
    return SPN_OK;
}

static spn_status get_object(const reader *r, const cJSON *parent, const char *key, bool required, const cJSON **out)
{
    *out = cJSON_GetObjectItemCaseSensitive(parent, key);
    if (!*out) return required ? bad(r, "missing field '%s'", key) : SPN_OK;
    if (!cJSON_IsObject(*out)) return bad(r, "%s: expected an object, got %s", key, type_name(*out));
    return SPN_OK;
}

static spn_status finite_number(const reader *r, const cJSON *j, const char *field, double *out)
{
    if (!cJSON_IsNumber(j)) return bad(r, "%s: expected a number, got %s", field, type_name(j));
    if (!isfinite(j->valuedouble)) return bad(r, "%s: number out of range", field);
    *out = j->valuedouble;
    return SPN_OK;
}

/* On failure *out is 0, so callers may convert it to an integer type
 * unconditionally (a refused value can be outside that type's range). */
static spn_status whole_number(const reader *r, const cJSON *j, const char *field, double max, double *out)
{
    double v = 0;
    *out = 0;
    spn_status st = finite_number(r, j, field, &v);
    if (st != SPN_OK) return st;
    if (v < 0 || v > max || floor(v) != v)
        return bad(r, "%s: expected a whole number in [0, %.0f], got %.17g", field, max, v);
    *out = v;
    return SPN_OK;
}

/* ---- columns -----------------------------------------------------------
 * A column walks a JSON array in step with the item index, checking each
 * entry; `width` entries per item (3 for vectors). */

typedef struct column {
    const cJSON *next;        /* entry to read next; NULL for a missing optional column */
    const unsigned char *bin; /* a binary file's column, its first entry; NULL for JSON */
    const double *lift;       /* a column read from the JSON text (web_lift.c; null as NaN), or NULL */
    char path[64];            /* "particles.mass" */
    uint32_t index;           /* entry index of `next` */
    int width;                /* entries per item: 3 for vectors */
} column;

static spn_status column_open(const reader *r, const cJSON *section, const char *sect, const char *key,
                              bool required, size_t count, int width, column *col)
{
    snprintf(col->path, sizeof col->path, "%s.%s", sect, key);
    col->next = NULL;
    col->bin = NULL;
    col->lift = NULL;
    col->index = 0;
    col->width = width;
    if (r->payload) { /* every column is there, its length checked with the file's */
        col->bin = r->payload + spn__web_binary_offset(col->path, r->particles, r->springs);
        return SPN_OK;
    }
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(section, key);
    if (!arr) return required ? bad(r, "missing field '%s'", col->path) : SPN_OK;
    if (!cJSON_IsArray(arr)) return bad(r, "%s: expected an array, got %s", col->path, type_name(arr));
    const spn__lifted_col *lifted = spn__lifted_find(r->lifted, col->path); /* then arr is its "[]" */
    size_t want = count * (size_t)width, have = lifted ? lifted->n : 0;
    for (const cJSON *c = arr->child; c && have <= want; c = c->next) have++;
    if (have != want)
        return bad(r, "%s: has %s%zu entries, expected %zu (%s.count = %zu%s)", col->path, have > want ? "more than " : "",
                   have > want ? want : have, want, sect, count, width == 3 ? ", 3 per particle" : "");
    col->next = arr->child;
    col->lift = lifted ? lifted->v : NULL;
    return SPN_OK;
}

/* A lifted entry as the cJSON item it stands for: a number, or null (NaN);
 * only for the messages, which then read as for any other JSON entry. */
static const cJSON *as_item(double v, cJSON *tmp)
{
    memset(tmp, 0, sizeof *tmp);
    tmp->type = isnan(v) ? cJSON_NULL : cJSON_Number;
    tmp->valuedouble = v;
    return tmp;
}

/* The next entry of a JSON column that is there: its cJSON item, or the
 * lifted one as such an item in *tmp. */
static const cJSON *json_take(column *col, cJSON *tmp)
{
    const cJSON *j = col->lift ? as_item(col->lift[col->index], tmp) : col->next;
    if (!col->lift) col->next = j->next;
    col->index++;
    return j;
}

/* The next entry as a finite number, or `dflt` for a missing column. */
static spn_status col_number(const reader *r, column *col, double dflt, double *out)
{
    if (!col->next && !col->bin && !col->lift) {
        *out = dflt;
        return SPN_OK;
    }
    const cJSON *j = col->next;
    const double v = j ? j->valuedouble
                       : col->lift ? col->lift[col->index] : spn__get_f64(col->bin + 8 * (size_t)col->index);
    if (j) col->next = j->next;
    col->index++;
    if ((!j || cJSON_IsNumber(j)) && isfinite(v)) { /* the field's name is only made for a message */
        *out = v;
        return SPN_OK;
    }
    const uint32_t i = col->index - 1;
    char field[96];
    if (col->width == 3)
        snprintf(field, sizeof field, "%s[%u] (particle %u, %c)", col->path, i, i / 3, "xyz"[i % 3]);
    else snprintf(field, sizeof field, "%s[%u]", col->path, i);
    cJSON tmp;
    if (col->lift) j = as_item(v, &tmp);
    if (!j) return bad(r, "%s: %s is not allowed", field, isnan(v) ? "NaN" : "an infinity");
    return finite_number(r, j, field, out);
}

/* The next entry as a number that is finite and not negative. */
static spn_status col_nonneg(const reader *r, column *col, double dflt, const char *what, double *out)
{
    uint32_t i = col->index;
    spn_status st = col_number(r, col, dflt, out);
    if (st == SPN_OK && *out < 0) return bad(r, "%s[%u]: negative %s %.17g", col->path, i, what, *out);
    return st;
}

static spn_status col_uint32(const reader *r, column *col, uint32_t *out)
{
    if (col->bin) {
        *out = spn__get_u32(col->bin + 4 * (size_t)col->index++);
        return SPN_OK;
    }
    if (!col->next && !col->lift) {
        *out = 0;
        return SPN_OK;
    }
    cJSON tmp;
    const cJSON *j = json_take(col, &tmp);
    const double u = j->valuedouble;
    if (cJSON_IsNumber(j) && u >= 0 && u <= 4294967295.0 && floor(u) == u) {
        *out = (uint32_t)u;
        return SPN_OK;
    }
    char field[96];
    snprintf(field, sizeof field, "%s[%u]", col->path, col->index - 1);
    double v = 0;
    spn_status st = whole_number(r, j, field, 4294967295.0, &v);
    *out = (uint32_t)v;
    return st;
}

/* A flag: true, false, 1 or 0. */
static spn_status col_flag(const reader *r, column *col, bool *out)
{
    *out = false;
    if (col->bin) {
        const uint32_t i = col->index++;
        const unsigned v = col->bin[i];
        if (v > 1) return bad(r, "%s[%u]: expected 0 or 1, got %u", col->path, i, v);
        *out = v == 1;
        return SPN_OK;
    }
    if (!col->next && !col->lift) return SPN_OK;
    cJSON tmp;
    const uint32_t i = col->index;
    const cJSON *j = json_take(col, &tmp);
    if (cJSON_IsBool(j)) *out = cJSON_IsTrue(j);
    else if (cJSON_IsNumber(j) && (j->valuedouble == 0 || j->valuedouble == 1)) *out = j->valuedouble == 1;
    else if (cJSON_IsNumber(j)) return bad(r, "%s[%u]: expected 0, 1, true or false, got %.17g", col->path, i, j->valuedouble);
    else return bad(r, "%s[%u]: expected 0, 1, true or false, got %s", col->path, i, type_name(j));
    return SPN_OK;
}

/* break_max: a length, or null for "never". */
static spn_status col_break_max(const reader *r, column *col, double *out)
{
    if (col->bin && spn__get_f64(col->bin + 8 * (size_t)col->index) == INFINITY) { /* "never", as null in JSON */
        col->index++;
        *out = INFINITY;
        return SPN_OK;
    }
    if (col->lift && isnan(col->lift[col->index])) { /* null */
        col->index++;
        *out = INFINITY;
        return SPN_OK;
    }
    if (col->next && cJSON_IsNull(col->next)) {
        col->next = col->next->next;
        col->index++;
        *out = INFINITY;
        return SPN_OK;
    }
    return col_nonneg(r, col, INFINITY, "length", out);
}

static spn_status col_vec3(const reader *r, column *col, spn_vec3 *out)
{
    double c[3] = {0, 0, 0};
    for (int j = 0; j < 3; j++) {
        spn_status st = col_number(r, col, 0, &c[j]);
        if (st != SPN_OK) return st;
    }
    *out = spn_v3(c[0], c[1], c[2]);
    return SPN_OK;
}

/* ---- sections ------------------------------------------------------------ */

static spn_status read_count(const reader *r, const cJSON *section, const char *sect, size_t *count)
{
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(section, "count");
    char field[32];
    snprintf(field, sizeof field, "%s.count", sect);
    if (!j) return bad(r, "missing field '%s'", field);
    double v = 0;
    spn_status st = whole_number(r, j, field, SPN__WEB_MAX_COUNT, &v);
    *count = (size_t)v;
    return st;
}

typedef struct particle_columns {
    column position, velocity, mass, fixed, tag;
} particle_columns;

static spn_status open_particles(const reader *r, const cJSON *sec, size_t n, particle_columns *pc)
{
    static const char *const keys[] = {"count", "position", "velocity", "mass", "fixed", "tag", NULL};
    static const char *const binary_keys[] = {"count", NULL};
    spn_status st = check_keys(r, sec, "particles", r->payload ? binary_keys : keys);
    if (st == SPN_OK) st = column_open(r, sec, "particles", "position", true, n, 3, &pc->position);
    if (st == SPN_OK) st = column_open(r, sec, "particles", "velocity", false, n, 3, &pc->velocity);
    if (st == SPN_OK) st = column_open(r, sec, "particles", "mass", true, n, 1, &pc->mass);
    if (st == SPN_OK) st = column_open(r, sec, "particles", "fixed", false, n, 1, &pc->fixed);
    if (st == SPN_OK) st = column_open(r, sec, "particles", "tag", false, n, 1, &pc->tag);
    return st;
}

static spn_status read_particles(const reader *r, particle_columns *pc, size_t n, spn_world *w)
{
    for (size_t i = 0; i < n; i++) {
        spn_particle_def p = spn_particle_def_default();
        spn_status st = col_vec3(r, &pc->position, &p.position);
        if (st == SPN_OK) st = col_vec3(r, &pc->velocity, &p.velocity);
        if (st == SPN_OK) st = col_nonneg(r, &pc->mass, 0, "mass", &p.mass);
        if (st == SPN_OK) st = col_flag(r, &pc->fixed, &p.fixed);
        if (st == SPN_OK) st = col_uint32(r, &pc->tag, &p.tag);
        if (st == SPN_OK) st = spn_world_add_particle(w, &p, NULL);
        if (st != SPN_OK) return st == SPN_ERR_FORMAT ? st : spn__error_prefix(st, r->name);
    }
    return SPN_OK;
}

typedef struct spring_columns {
    column a, b, k, kd, rest, break_min, break_max, tension_only, broken, tag, stage, order;
} spring_columns;

static spn_status open_springs(const reader *r, const cJSON *sec, size_t n, spring_columns *sc)
{
    static const char *const keys[] = {"count", "a", "b", "k", "kd", "rest", "break_min", "break_max",
                                       "tension_only", "broken", "tag", "stage", "order", NULL};
    struct {
        const char *key;
        bool required;
        column *col;
    } cols[] = {{"a", true, &sc->a},
                {"b", true, &sc->b},
                {"k", true, &sc->k},
                {"kd", false, &sc->kd},
                {"rest", true, &sc->rest},
                {"break_min", false, &sc->break_min},
                {"break_max", false, &sc->break_max},
                {"tension_only", false, &sc->tension_only},
                {"broken", false, &sc->broken},
                {"tag", false, &sc->tag},
                {"stage", false, &sc->stage},
                {"order", false, &sc->order}};
    static const char *const binary_keys[] = {"count", NULL};
    spn_status st = check_keys(r, sec, "springs", r->payload ? binary_keys : keys);
    for (size_t i = 0; i < sizeof cols / sizeof cols[0] && st == SPN_OK; i++)
        st = column_open(r, sec, "springs", cols[i].key, cols[i].required, n, 1, cols[i].col);
    return st;
}

static spn_status spring_ends(const reader *r, spring_columns *sc, uint32_t np, spn_spring_def *s)
{
    uint32_t i = sc->a.index;
    spn_status st = col_uint32(r, &sc->a, &s->a);
    if (st == SPN_OK) st = col_uint32(r, &sc->b, &s->b);
    if (st != SPN_OK) return st;
    if (s->a >= np) return bad(r, "springs.a[%u]: particle %u does not exist (%u particles)", i, s->a, np);
    if (s->b >= np) return bad(r, "springs.b[%u]: particle %u does not exist (%u particles)", i, s->b, np);
    if (s->a == s->b) return bad(r, "springs.b[%u]: spring joins particle %u to itself", i, s->a);
    return SPN_OK;
}

static spn_status read_spring(const reader *r, spring_columns *sc, uint32_t np, spn_spring_def *s, bool *broken)
{
    uint32_t i = sc->a.index;
    spn_status st = spring_ends(r, sc, np, s);
    if (st == SPN_OK) st = col_nonneg(r, &sc->k, 0, "stiffness", &s->k);
    if (st == SPN_OK) st = col_nonneg(r, &sc->kd, 0, "damping", &s->kd);
    if (st == SPN_OK) st = col_nonneg(r, &sc->rest, 0, "rest length", &s->rest);
    if (st == SPN_OK) st = col_nonneg(r, &sc->break_min, 0, "length", &s->break_min);
    if (st == SPN_OK) st = col_break_max(r, &sc->break_max, &s->break_max);
    if (st == SPN_OK) st = col_flag(r, &sc->tension_only, &s->tension_only);
    if (st == SPN_OK) st = col_flag(r, &sc->broken, broken);
    if (st == SPN_OK) st = col_uint32(r, &sc->tag, &s->tag);
    if (st == SPN_OK) st = col_uint32(r, &sc->stage, &s->stage);
    if (st == SPN_OK) st = col_uint32(r, &sc->order, &s->order);
    if (st == SPN_OK && s->break_max < s->break_min)
        return bad(r, "springs.break_max[%u]: %.17g is less than break_min %.17g", i, s->break_max, s->break_min);
    return st;
}

static spn_status read_springs(const reader *r, spring_columns *sc, size_t n, spn_world *w)
{
    uint32_t np = spn_world_particle_count(w);
    for (size_t i = 0; i < n; i++) {
        spn_spring_def s = spn_spring_def_default();
        bool broken = false;
        uint32_t id = 0;
        spn_status st = read_spring(r, sc, np, &s, &broken);
        if (st == SPN_OK) st = spn_world_add_spring(w, &s, &id);
        if (st != SPN_OK) return st == SPN_ERR_FORMAT ? st : spn__error_prefix(st, r->name);
        if (broken) spn_world_break_spring(w, id);
    }
    return SPN_OK;
}

/* ---- the "world" object: settings, each optional with the default of
 * spn_world_def_default() ------------------------------------------------- */

static spn_status setting_number(const reader *r, const cJSON *sec, const char *key, double lo, double hi,
                                 double *out)
{
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(sec, key);
    if (!j) return SPN_OK;
    char field[48];
    snprintf(field, sizeof field, "world.%s", key);
    double v = 0;
    spn_status st = finite_number(r, j, field, &v);
    if (st != SPN_OK) return st;
    if (v < lo || v > hi) return bad(r, "%s: %.17g is out of range [%g, %g]", field, v, lo, hi);
    *out = v;
    return SPN_OK;
}

static spn_status setting_gravity(const reader *r, const cJSON *sec, spn_vec3 *g)
{
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(sec, "gravity");
    if (!j) return SPN_OK;
    if (!cJSON_IsArray(j)) return bad(r, "world.gravity: expected an array of 3 numbers, got %s", type_name(j));
    if (cJSON_GetArraySize(j) != 3)
        return bad(r, "world.gravity: expected 3 numbers, got %d", cJSON_GetArraySize(j));
    double c[3];
    const cJSON *e = j->child;
    for (int i = 0; i < 3; i++, e = e->next) {
        char field[32];
        snprintf(field, sizeof field, "world.gravity[%d]", i);
        spn_status st = finite_number(r, e, field, &c[i]);
        if (st != SPN_OK) return st;
    }
    *g = spn_v3(c[0], c[1], c[2]);
    return SPN_OK;
}

static spn_status setting_integrator(const reader *r, const cJSON *sec, spn_integrator *out)
{
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(sec, "integrator");
    if (!j) return SPN_OK;
    if (!cJSON_IsString(j)) return bad(r, "world.integrator: expected a string, got %s", type_name(j));
    if (spn_integrator_parse(j->valuestring, out) != SPN_OK)
        return bad(r, "world.integrator: unknown integrator '%.60s' (euler, symplectic, rk4, adaptive, implicit)",
                   j->valuestring);
    return SPN_OK;
}

/* A seed: a whole number up to 2^53, or a decimal string for larger ones. */
static spn_status setting_seed(const reader *r, const cJSON *sec, uint64_t *seed)
{
    const cJSON *j = cJSON_GetObjectItemCaseSensitive(sec, "seed");
    if (!j) return SPN_OK;
    if (cJSON_IsString(j)) {
        const char *s = j->valuestring;
        char *end = NULL;
        errno = 0;
        unsigned long long v = strtoull(s, &end, 10);
        if (*s < '0' || *s > '9' || *end || errno == ERANGE)
            return bad(r, "world.seed: expected a whole number, got '%.40s'", s);
        *seed = v;
        return SPN_OK;
    }
    double v = 0;
    spn_status st = whole_number(r, j, "world.seed", (double)SPN__MAX_EXACT_INT, &v);
    *seed = (uint64_t)v;
    return st;
}

static spn_status read_settings(const reader *r, const cJSON *sec, spn_world_def *d, double *time)
{
    static const char *const keys[] = {"gravity",      "drag",         "integrator",        "time",
                                       "breakage",     "dt_min",       "dt_factor",         "energy_jump",
                                       "cg_tolerance", "cg_max_iterations", "provot_max_strain", "provot_iterations",
                                       "seed",         NULL};
    if (!sec) return SPN_OK;
    double cg_iter = d->cg_max_iterations, provot_iter = d->provot_iterations;
    spn_status st = check_keys(r, sec, "world", keys);
    if (st == SPN_OK) st = setting_gravity(r, sec, &d->gravity);
    if (st == SPN_OK) st = setting_integrator(r, sec, &d->integrator);
    if (st == SPN_OK) st = setting_number(r, sec, "drag", 0, HUGE_VAL, &d->drag);
    if (st == SPN_OK) st = setting_number(r, sec, "time", -HUGE_VAL, HUGE_VAL, time);
    if (st == SPN_OK) st = setting_number(r, sec, "dt_min", 0, HUGE_VAL, &d->dt_min);
    if (st == SPN_OK) st = setting_number(r, sec, "dt_factor", 1, HUGE_VAL, &d->dt_factor);
    if (st == SPN_OK) st = setting_number(r, sec, "energy_jump", 0, HUGE_VAL, &d->energy_jump);
    if (st == SPN_OK) st = setting_number(r, sec, "cg_tolerance", 0, HUGE_VAL, &d->cg_tolerance);
    if (st == SPN_OK) st = setting_number(r, sec, "cg_max_iterations", 1, 1e9, &cg_iter);
    if (st == SPN_OK) st = setting_number(r, sec, "provot_max_strain", 0, HUGE_VAL, &d->provot_max_strain);
    if (st == SPN_OK) st = setting_number(r, sec, "provot_iterations", 0, 1e9, &provot_iter);
    if (st == SPN_OK) st = setting_seed(r, sec, &d->seed);
    if (st != SPN_OK) return st;
    const cJSON *brk = cJSON_GetObjectItemCaseSensitive(sec, "breakage");
    if (brk && !cJSON_IsBool(brk)) return bad(r, "world.breakage: expected true or false, got %s", type_name(brk));
    if (brk) d->breakage = cJSON_IsTrue(brk);
    d->cg_max_iterations = (int)cg_iter;
    d->provot_iterations = (int)provot_iter;
    return SPN_OK;
}

/* The whole document, once parsed: header, settings, then the two sections,
 * all columns opened (lengths checked) before the world is created. A binary
 * file's payload (r->payload, `payload_size` bytes) must hold exactly the
 * columns its counts call for. */
static spn_status read_document(reader *r, const cJSON *root, size_t payload_size, spn_world **out)
{
    static const char *const keys[] = {"format", "version", "units", "metadata", "world",
                                       "thread_kinds", "particles", "springs", NULL};
    const cJSON *meta = NULL, *settings = NULL, *kinds = NULL, *ps = NULL, *ss = NULL;
    spn_world_def def = spn_world_def_default();
    double time = 0;
    size_t np = 0, ns = 0;
    particle_columns pc;
    spring_columns sc;
    spn_status st = check_keys(r, root, "", keys);
    if (st == SPN_OK) st = get_object(r, root, "metadata", false, &meta);
    if (st == SPN_OK) st = get_object(r, root, "world", false, &settings);
    if (st == SPN_OK) st = get_object(r, root, "thread_kinds", false, &kinds);
    if (st == SPN_OK) st = get_object(r, root, "particles", true, &ps);
    if (st == SPN_OK) st = get_object(r, root, "springs", true, &ss);
    if (st == SPN_OK) st = read_settings(r, settings, &def, &time);
    if (st == SPN_OK) st = read_count(r, ps, "particles", &np);
    if (st == SPN_OK) st = read_count(r, ss, "springs", &ns);
    r->particles = np, r->springs = ns; /* a binary file's columns' offsets */
    if (st == SPN_OK) st = open_particles(r, ps, np, &pc);
    if (st == SPN_OK) st = open_springs(r, ss, ns, &sc);
    const uint64_t want = r->payload ? spn__web_binary_size(np, ns) : 0;
    if (st == SPN_OK && r->payload && (uint64_t)payload_size != want) /* before any column is read */
        st = bad(r, "the columns take %zu bytes, expected %llu for %zu particles and %zu springs%s", payload_size,
                 (unsigned long long)want, np, ns, payload_size < want ? " (a truncated file?)" : "");
    if (st == SPN_OK) st = spn_check_counts(r->name, np, ns); /* before the world grows */
    if (st != SPN_OK) return st;

    spn_world *w = spn_world_create(&def);
    if (!w) return spn_error(SPN_ERR_NOMEM, "%s: out of memory", r->name);
    spn_world_set_time(w, time);
    st = read_particles(r, &pc, np, w);
    if (st == SPN_OK) st = read_springs(r, &sc, ns, w);
    if (st == SPN_OK && meta) {
        char *text = cJSON_PrintUnformatted(meta);
        st = text ? spn_world_set_metadata(w, text) : spn_error(SPN_ERR_NOMEM, "%s: out of memory", r->name);
        cJSON_free(text);
    }
    if (st != SPN_OK) {
        spn_world_destroy(w);
        return st;
    }
    *out = w;
    return SPN_OK;
}

/* The header comes first: a file of another format or version is named as
 * such rather than by the first field it happens to lack. */
static spn_status check_header(const reader *r, const cJSON *root)
{
    if (!cJSON_IsObject(root)) return bad(r, "expected a JSON object at the top, got %s", type_name(root));
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(root, "format");
    if (!format) return bad(r, "missing field 'format' (expected \"" SPN__WEB_FORMAT_NAME "\")");
    if (!cJSON_IsString(format)) return bad(r, "format: expected a string, got %s", type_name(format));
    if (strcmp(format->valuestring, SPN__WEB_FORMAT_NAME) != 0)
        return bad(r, "format: unknown format '%.100s' (expected \"" SPN__WEB_FORMAT_NAME "\")", format->valuestring);
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "version");
    if (!version) return bad(r, "missing field 'version'");
    double v = 0;
    spn_status st = whole_number(r, version, "version", 1e9, &v);
    if (st != SPN_OK) return st;
    if (v != SPN_WEB_FORMAT_VERSION)
        return bad(r, "version: unsupported version %.0f (this build reads version %d)", v, SPN_WEB_FORMAT_VERSION);
    const cJSON *units = cJSON_GetObjectItemCaseSensitive(root, "units");
    if (units && !(cJSON_IsString(units) && strcmp(units->valuestring, "SI") == 0))
        return bad(r, "units: only \"SI\" is supported");
    return SPN_OK;
}

/* Line and column (from 1) of byte `offset`. */
static void locate(const char *text, size_t offset, size_t *line, size_t *col)
{
    *line = 1;
    *col = 1;
    for (size_t i = 0; i < offset; i++) {
        if (text[i] == '\n') {
            (*line)++;
            *col = 1;
        } else (*col)++;
    }
}

static bool blank(const char *text, size_t size)
{
    for (size_t i = 0; i < size; i++)
        if (!strchr(" \t\r\n", text[i])) return false;
    return true;
}

/* Does the text at a syntax error spell NaN or Infinity (which some JSON
 * writers emit)? Then the message can say why it is refused. */
static bool non_number(const char *p, size_t n)
{
    static const char *const words[] = {"NaN", "nan", "Infinity", "-Infinity", "inf", "-inf"};
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        size_t len = strlen(words[i]);
        if (n >= len && strncmp(p, words[i], len) == 0) return true;
    }
    return false;
}

spn_status spn__web_parse_text(const char *text, size_t size, const char *name, const char *part, cJSON **root)
{
    const reader r = {name, NULL, 0, 0, NULL};
    const char *sep = part ? ": " : "";
    part = part ? part : "";
    *root = NULL;
    if (!text || blank(text, size)) return *part ? bad(&r, "%s: empty", part) : bad(&r, "empty file");
    const char *nul = memchr(text, '\0', size);
    if (nul) return bad(&r, "%s%snot JSON: NUL byte at offset %zu", part, sep, (size_t)(nul - text));
    const char *end = NULL;
    *root = cJSON_ParseWithLengthOpts(text, size, &end, false);
    size_t line, col, offset = end ? (size_t)(end - text) : 0;
    if (!*root) {
        locate(text, offset, &line, &col);
        return bad(&r, "%s%snot JSON: syntax error at line %zu, column %zu%s", part, sep, line, col,
                   non_number(text + offset, size - offset) ? " (NaN and infinities are not allowed)" : "");
    }
    if (!blank(end, size - offset)) {
        cJSON_Delete(*root);
        *root = NULL;
        locate(text, offset, &line, &col);
        return bad(&r, "%s%snot JSON: text after the end of the document at line %zu, column %zu", part, sep, line,
                   col);
    }
    return SPN_OK;
}

spn_status spn__web_parse_json(const char *text, size_t size, const char *name, bool lift, spn_world **out)
{
    *out = NULL;
    spn__lifted lifted;
    memset(&lifted, 0, sizeof lifted);
    if (lift && text) {
        spn_status st = spn__web_lift(text, size, &lifted);
        if (st != SPN_OK) return spn__error_prefix(st, name);
    }
    cJSON *root = NULL;
    spn_status st = SPN_ERR_FORMAT;
    if (lifted.count) { /* after a syntax error the text itself is parsed, for its positions */
        st = spn__web_parse_text(lifted.skeleton, lifted.skeleton_size, name, NULL, &root);
        if (st != SPN_OK) spn__lifted_free(&lifted);
    }
    if (!root) st = spn__web_parse_text(text, size, name, NULL, &root);
    if (st == SPN_OK) st = spn__web_read_root(name, root, NULL, 0, lifted.count ? &lifted : NULL, out);
    cJSON_Delete(root);
    spn__lifted_free(&lifted);
    return st;
}

spn_status spn_web_parse(const char *text, size_t size, const char *name, spn_world **out)
{
    name = name ? name : "web file";
    if (!out) return spn_error(SPN_ERR_INVALID, "spn_web_parse: out is NULL");
    *out = NULL;
    if (text && spn__web_is_binary(text, size))
        return spn__web_parse_binary((const unsigned char *)text, size, name, out);
    return spn__web_parse_json(text, size, name, true, out);
}

spn_status spn__web_read_root(const char *name, const cJSON *root, const unsigned char *payload, size_t payload_size,
                              const spn__lifted *lifted, spn_world **out)
{
    reader r = {name, payload, 0, 0, lifted};
    spn_status st = check_header(&r, root);
    return st == SPN_OK ? read_document(&r, root, payload_size, out) : st;
}

spn_status spn_web_load(const char *path, spn_world **out)
{
    if (!out) return spn_error(SPN_ERR_INVALID, "spn_web_load: out is NULL");
    *out = NULL;
    if (!path || !*path) return spn_error(SPN_ERR_INVALID, "web file: the path is empty");
    FILE *fp = fopen(path, "rb");
    if (!fp) return spn_error(SPN_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
#if defined(__unix__)
    /* A regular file is read where the system keeps it: no copy, and no
     * fresh pages for one (a million-particle web is hundreds of MB). */
    struct stat sb;
    if (fstat(fileno(fp), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0 &&
        (uint64_t)sb.st_size < SPN__WEB_MAX_BYTES) {
        void *map = mmap(NULL, (size_t)sb.st_size, PROT_READ, MAP_PRIVATE, fileno(fp), 0);
        if (map != MAP_FAILED) {
            fclose(fp);
            spn_status st = spn_web_parse(map, (size_t)sb.st_size, path, out);
            munmap(map, (size_t)sb.st_size);
            return st;
        }
    }
#endif
    /* A regular file is read into one buffer of its size (no copies as it
     * grows: a million-particle web is hundreds of MB); a pipe grows one. */
    size_t cap = 1 << 16, size = 0;
    if (fseek(fp, 0, SEEK_END) == 0) {
        const long end = ftell(fp);
        if (end > 0) cap = (size_t)end < SPN__WEB_MAX_BYTES ? (size_t)end + 1 : SPN__WEB_MAX_BYTES;
    }
    rewind(fp);
    char *buf = malloc(cap);
    spn_status st = buf ? SPN_OK : spn_error(SPN_ERR_NOMEM, "%s: out of memory", path);
    while (st == SPN_OK) {
        size += fread(buf + size, 1, cap - size, fp);
        if (ferror(fp)) st = spn_error(SPN_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
        else if (size < cap) break;
        else if (cap >= SPN__WEB_MAX_BYTES)
            st = spn_error(SPN_ERR_NOMEM, "%s: file larger than %zu bytes", path, SPN__WEB_MAX_BYTES);
        else {
            const size_t next = cap < SPN__WEB_MAX_BYTES / 2 ? cap * 2 : SPN__WEB_MAX_BYTES;
            char *bigger = realloc(buf, next);
            if (!bigger) st = spn_error(SPN_ERR_NOMEM, "%s: out of memory", path);
            else {
                buf = bigger;
                cap = next;
            }
        }
    }
    fclose(fp);
    if (st == SPN_OK) st = spn_web_parse(buf, size, path, out);
    free(buf);
    return st;
}

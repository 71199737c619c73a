/* spinneret info FILE [--json]: what a web file holds and the state it is in.
 *
 * The measures are gathered into one JSON object by a list of sections (the
 * table `sections` below); the text output is printed from that same object,
 * so a new measure is added in one place and shows up in both outputs. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const CMD = "info";

static void usage(FILE *out)
{
    fprintf(out, "usage: spinneret info FILE [--json]\n"
                 "Describe a web file: counts, fixed particles, broken springs, mass, bounding box,\n"
                 "energies, the largest residual force, springs per thread kind, and the world's\n"
                 "settings with its stable step (the longest stable explicit step of its springs).\n"
                 "All values are SI (m, kg, s, N, J).\n\n"
                 "  --json    print the measures as one JSON object on stdout\n"
                 "  --help    this text\n");
}

static cJSON *vec3_json(spn_vec3 v)
{
    const double c[3] = {v.x, v.y, v.z};
    return cJSON_CreateDoubleArray(c, 3);
}

/* ---- measures ------------------------------------------------------------ */

static void counts_and_mass(cJSON *info, const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w), fixed = 0, broken = 0;
    double total = 0, free_mass = 0;
    for (uint32_t i = 0; i < np; i++) {
        bool is_fixed = spn_world_is_fixed(w, i);
        fixed += is_fixed;
        total += spn_world_mass(w, i);
        if (!is_fixed) free_mass += spn_world_mass(w, i);
    }
    for (uint32_t s = 0; s < ns; s++) broken += spn_world_spring(w, s).broken;
    cJSON_AddNumberToObject(info, "particles", np);
    cJSON_AddNumberToObject(info, "springs", ns);
    cJSON_AddNumberToObject(info, "fixed_particles", fixed);
    cJSON_AddNumberToObject(info, "broken_springs", broken);
    cJSON_AddNumberToObject(info, "total_mass", total);
    cJSON_AddNumberToObject(info, "free_mass", free_mass);
}

static void bounding_box(cJSON *info, const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w);
    if (np == 0) {
        cJSON_AddNullToObject(info, "bounding_box");
        return;
    }
    const spn_vec3 *x = spn_world_positions(w);
    spn_vec3 lo = x[0], hi = x[0];
    for (uint32_t i = 1; i < np; i++) {
        lo = spn_v3(fmin(lo.x, x[i].x), fmin(lo.y, x[i].y), fmin(lo.z, x[i].z));
        hi = spn_v3(fmax(hi.x, x[i].x), fmax(hi.y, x[i].y), fmax(hi.z, x[i].z));
    }
    cJSON *box = cJSON_AddObjectToObject(info, "bounding_box");
    cJSON_AddItemToObject(box, "min", vec3_json(lo));
    cJSON_AddItemToObject(box, "max", vec3_json(hi));
    cJSON_AddItemToObject(box, "size", vec3_json(spn_v3_sub(hi, lo)));
}

static void energies(cJSON *info, spn_world *w)
{
    spn_energy e = spn_world_energy(w);
    cJSON *obj = cJSON_AddObjectToObject(info, "energy");
    cJSON_AddNumberToObject(obj, "kinetic", e.kinetic);
    cJSON_AddNumberToObject(obj, "elastic", e.elastic);
    cJSON_AddNumberToObject(obj, "gravitational", e.gravitational);
    cJSON_AddNumberToObject(obj, "total", e.kinetic + e.elastic + e.gravitational);

    uint32_t which = 0, free_particles = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) free_particles += !spn_world_is_fixed(w, i);
    double force = spn_world_max_residual(w, &which);
    cJSON *res = cJSON_AddObjectToObject(info, "max_residual");
    cJSON_AddNumberToObject(res, "force", force);
    if (free_particles) cJSON_AddNumberToObject(res, "particle", which);
    else cJSON_AddNullToObject(res, "particle");
}

/* Springs counted per thread kind (spring tag), in tag order; tags without a
 * name appear as "tag-N". */
static void springs_by_kind(cJSON *info, const spn_world *w)
{
    enum { MAX_TAGS = 64 };
    uint32_t count[MAX_TAGS] = {0}, other = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        uint32_t tag = spn_world_spring(w, s).tag;
        if (tag < MAX_TAGS) count[tag]++;
        else other++;
    }
    cJSON *obj = cJSON_AddObjectToObject(info, "springs_by_kind");
    for (uint32_t tag = 0; tag < MAX_TAGS; tag++) {
        if (!count[tag]) continue;
        char name[32];
        const char *known = spn_thread_kind_name(tag);
        if (known) snprintf(name, sizeof name, "%s", known);
        else snprintf(name, sizeof name, "tag-%u", (unsigned)tag);
        cJSON_AddNumberToObject(obj, name, count[tag]);
    }
    if (other) cJSON_AddNumberToObject(obj, "tag-64-or-more", other);
}

static void settings(cJSON *info, const spn_world *w)
{
    const spn_world_def *d = spn_world_get_def(w);
    cJSON *obj = cJSON_AddObjectToObject(info, "world");
    cJSON_AddStringToObject(obj, "integrator", spn_integrator_name(d->integrator));
    cJSON_AddItemToObject(obj, "gravity", vec3_json(d->gravity));
    cJSON_AddNumberToObject(obj, "drag", d->drag);
    cJSON_AddNumberToObject(obj, "time", spn_world_time(w));
    /* the longest stable symplectic Euler step of the springs (and drag), no
     * margin: what an explicit solver's substeps are chosen from; null when
     * nothing bounds it */
    const double stable = spn_world_stable_step(w, 0);
    if (isfinite(stable)) cJSON_AddNumberToObject(obj, "stable_step", stable);
    else cJSON_AddNullToObject(obj, "stable_step");
    cJSON *meta = cJSON_Parse(spn_world_metadata(w));
    if (meta) cJSON_AddItemToObject(info, "metadata", meta);
}

/* The measures of any spring world. */
static void generic_measures(cJSON *info, spn_world *w)
{
    counts_and_mass(info, w);
    bounding_box(info, w);
    energies(info, w);
    springs_by_kind(info, w);
    settings(info, w);
}

/* WEB MEASURES: the orb-web part adds its measures of the web itself here
 * (radii count, spiral turns, capture-spiral length, mesh size, ...), computed
 * by src/web, as one object: cJSON_AddObjectToObject(info, "web"). Both the
 * text and the --json output pick it up. */
static void web_measures(cJSON *info, spn_world *w)
{
    spn_web_measures m;
    if (spn_web_measure(w, &m) != SPN_OK) return;
    if (!m.springs_per_kind[SPN_THREAD_RADIUS] && !m.springs_per_kind[SPN_THREAD_CAPTURE]) return;
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    if (spn_web_measures_write(&m, true, &sink) == SPN_OK && buf.data) {
        cJSON *web = cJSON_Parse(buf.data);
        if (web) cJSON_AddItemToObject(info, "web", web);
    }
    spn_buffer_free(&buf);
}

typedef void (*measure_fn)(cJSON *info, spn_world *w);
static const measure_fn sections[] = {generic_measures, web_measures};

/* ---- text output ------------------------------------------------------------ */

static const char *unit_of(const char *key)
{
    static const char *const units[][2] = {{"total_mass", "kg"}, {"free_mass", "kg"}, {"kinetic", "J"},
                                           {"elastic", "J"},     {"gravitational", "J"}, {"total", "J"},
                                           {"force", "N"},       {"min", "m"},          {"max", "m"},
                                           {"size", "m"},        {"drag", "1/s"},       {"gravity", "m/s^2"},
                                           {"time", "s"},        {"stable_step", "s"}};
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (strcmp(units[i][0], key) == 0) return units[i][1];
    return NULL;
}

static void print_number(double v)
{
    if (!isfinite(v)) printf("%g", v);
    else if (v == floor(v) && fabs(v) < 1e15) printf("%.0f", v);
    else printf("%.6g", v);
}

static void print_value(const cJSON *j)
{
    if (cJSON_IsNumber(j)) print_number(j->valuedouble);
    else if (cJSON_IsString(j)) printf("%s", j->valuestring);
    else if (cJSON_IsNull(j)) printf("none");
    else if (cJSON_IsArray(j) && j->child && cJSON_IsNumber(j->child)) {
        printf("(");
        for (const cJSON *c = j->child; c; c = c->next) {
            print_number(c->valuedouble);
            if (c->next) printf(", ");
        }
        printf(")");
    } else {
        char *text = cJSON_PrintUnformatted(j);
        printf("%s", text ? text : "?");
        cJSON_free(text);
    }
}

/* One "key: value [unit]" line per entry; objects one level deep indent
 * their entries, deeper ones print as JSON on one line. */
static void print_text(const cJSON *obj, int depth)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        printf("%*s%s:", 2 * depth, "", c->string);
        if (cJSON_IsObject(c) && depth == 0 && c->child) {
            printf("\n");
            print_text(c, depth + 1);
            continue;
        }
        printf(" ");
        print_value(c);
        const char *unit = unit_of(c->string);
        if (unit && !cJSON_IsNull(c)) printf(" %s", unit);
        printf("\n");
    }
}

/* ---- the command ------------------------------------------------------------- */

int cmd_info(int argc, char **argv)
{
    static const struct option options[] = {{"json", no_argument, NULL, 'j'}, {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    bool json = false;
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, ":h", options, NULL)) != -1;) {
        if (c == 'j') json = true;
        else if (c == 'h') {
            usage(stdout);
            return 0;
        } else return cli_usage(CMD, "unknown option '%s'", argv[optind - 1]);
    }
    if (optind >= argc) return cli_usage(CMD, "missing FILE");
    if (optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    const char *path = argv[optind];

    spn_world *w = NULL;
    spn_status st = spn_web_load(path, &w);
    if (st != SPN_OK) return cli_fail(CMD, "%s", spn_last_error());
    cJSON *info = cJSON_CreateObject();
    cJSON_AddStringToObject(info, "file", path);
    for (size_t i = 0; i < sizeof sections / sizeof sections[0]; i++) sections[i](info, w);
    spn_world_destroy(w);
    if (json) {
        char *text = cJSON_Print(info);
        if (text) printf("%s\n", text);
        cJSON_free(text);
    } else print_text(info, 0);
    cJSON_Delete(info);
    return fflush(stdout) == 0 ? 0 : cli_fail(CMD, "cannot write the output");
}

/* Shared between the web builders (src/web): the weaver, which lays threads
 * into a spring world with their material, stage and construction order, and
 * the layout, a list of points and polylines that the geometric builders fill
 * before the weaver divides every line into springs. */
#ifndef SPN_WEB_INTERNAL_H
#define SPN_WEB_INTERNAL_H

#include "spinneret/web.h"

/* Lays particles and springs. Masses accumulate from the segments' linear
 * density and are written when the weaver finishes. The first error sticks:
 * later calls do nothing, and finish reports it. */
typedef struct spn__weaver {
    spn_world *w;
    spn_web_materials mat;
    double *mass;
    size_t mass_cap;
    uint32_t order;
    spn_status st;
} spn__weaver;

spn_status spn__weaver_init(spn__weaver *wv, const spn_world_def *def, const spn_web_materials *mat);
uint32_t spn__particle(spn__weaver *wv, spn_vec3 p, bool fixed, uint32_t tag);
/* A spring of the kind's material at rest length `rest`; returns its id. */
uint32_t spn__spring(spn__weaver *wv, uint32_t a, uint32_t b, uint32_t kind, uint32_t stage, double rest);
/* A straight chain from particle a to b in n segments, each of rest `rest`;
 * the n + 1 ids (a first) in *ids (malloc'd) when ids is not NULL. */
spn_status spn__chain(spn__weaver *wv, uint32_t a, uint32_t b, int n, double rest, uint32_t kind,
                      uint32_t stage, uint32_t ptag, uint32_t **ids);
/* Write the masses, store `metadata` (a JSON object) and hand the world over. */
spn_status spn__weaver_finish(spn__weaver *wv, const char *metadata, spn_world **out);
void spn__weaver_abort(spn__weaver *wv);

typedef struct spn__line {
    uint32_t *idx;
    size_t n;
    uint32_t kind, stage;
} spn__line;

typedef struct spn__layout {
    spn_vec3 *pt;
    uint32_t *ptag;
    bool *pfixed;
    size_t np, pcap;
    spn__line *lines;
    size_t nl, lcap;
    bool failed;
} spn__layout;

uint32_t spn__lay_point(spn__layout *l, spn_vec3 p, uint32_t tag, bool fixed);
void spn__lay_line(spn__layout *l, const uint32_t *idx, size_t n, uint32_t kind, uint32_t stage);
void spn__layout_free(spn__layout *l);
/* Pre-strain per thread kind from a woven builder's strains. */
void spn__web_prestrains(const spn_web_strains *s, double pre[SPN_WEB_KINDS]);
/* Each of the strains in [0, 4]; the message names the field. */
spn_status spn__web_check_strains(const spn_web_strains *s);
/* The woven web's shape with every thread but frame, moorings and bridge
 * pulling at its laid tension (prestrain[kind]), those threads then laid on
 * it at the tension each pulls with there (form_find.c); the web is left as
 * laid where the solve falls short or the web is too big (*found false).
 * Errors: out of memory. */
spn_status spn__web_form_find(spn_world *w, const double prestrain[SPN_WEB_KINDS], bool *found);
/* For tests: the most particles a web may have to be form-found and the
 * Newton steps its solve may take (FORM_FIND_MAX_PARTICLES and
 * FORM_FIND_STEPS until set); each returns the old value. */
uint32_t spn__form_find_set_max_particles(uint32_t particles);
int spn__form_find_set_steps(int steps);
/* Strands of the anchor material a woven web's mooring threads are laid of. */
#define SPN__MOORING_STRANDS 4.0
/* Divide every line into springs no longer than `segment`, laid
 * prestrain[kind] beyond rest, in the order the lines were added, the
 * mooring threads of SPN__MOORING_STRANDS strands. Springs of kind
 * SPN_THREAD_AUX_SPIRAL are removed at the end unless keep_aux. */
spn_status spn__layout_weave(const spn__layout *l, spn__weaver *wv, double segment,
                             const double prestrain[SPN_WEB_KINDS], bool keep_aux);

/* Anchors for the sites the presets use: n points on an ellipse-ish outline of
 * `size`, jittered by the rng. */
void spn__site_anchors(spn_rng *rng, int n, double width, double height, spn_vec3 *out);

/* Metadata JSON: {"builder": ..., "seed": ..., "parameters": {...}}. */
typedef struct spn__meta {
    spn_buffer buf;
    spn_sink sink;
    int fields;
} spn__meta;
void spn__meta_begin(spn__meta *m, const char *builder, uint64_t seed, const spn_vec3 *anchors, int count);
void spn__meta_num(spn__meta *m, const char *key, double v);
void spn__meta_str(spn__meta *m, const char *key, const char *v);
/* Every thread kind's material, as "materials": {kind: {ea, ...}}. */
void spn__meta_materials(spn__meta *m, const spn_web_materials *mat);
/* Particles renumbered octant by octant around the web's centroid, in the
 * weaver's order within each (weave.c). */
spn_status spn__web_number_by_place(spn_world *w);
/* The woven builders' (geometric, species) end: the world out of the
 * weaver (spn__weaver_finish) and numbered by place
 * (spn__web_number_by_place), then, if form_find, its shape found
 * (spn__web_form_find), then the metadata set, with the strains and the
 * outcome added ("prestrain", "capture_prestrain", "frame_prestrain",
 * "anchor_prestrain", "form_find": asked for, "form_found": done). *out
 * NULL on an error. m stays the caller's. */
spn_status spn__woven_finish(spn__weaver *wv, spn__meta *m, const spn_web_strains *s, bool form_find, spn_world **out);
const char *spn__meta_end(spn__meta *m);
void spn__meta_free(spn__meta *m);

/* Geometry helpers. */
double spn__cross2(spn_vec3 a, spn_vec3 b, spn_vec3 c); /* z of (b-a) x (c-a) */
bool spn__segments_cross(spn_vec3 a, spn_vec3 b, spn_vec3 c, spn_vec3 d); /* proper crossing, 2D */
spn_vec3 spn__lerp(spn_vec3 a, spn_vec3 b, double t);

#endif

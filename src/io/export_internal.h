/* Shared by the exporters: the web as emitted by spn_draw_world, collected
 * into flat arrays (strands with their points and particle ids, dew beads). */
#ifndef SPN_EXPORT_INTERNAL_H
#define SPN_EXPORT_INTERNAL_H

#include "spinneret/export.h"

typedef struct spn__xstrand {
    uint32_t kind;
    size_t first;        /* into points / particles */
    uint32_t count;
    bool closed;
    double width;        /* px on a 1200 px canvas */
    double rgb[3], alpha;
} spn__xstrand;

typedef struct spn__xscene {
    spn__xstrand *strands;
    size_t strand_count, strand_cap;
    spn_vec3 *points;
    uint32_t *particles;
    size_t point_count, point_cap;
    spn_bead *beads;
    size_t bead_count, bead_cap;
    spn_vec3 lo, hi;     /* bounds of the strand points */
    bool any;
} spn__xscene;

spn_status spn__xscene_collect(const spn_world *w, const spn_render_def *def, spn__xscene *out);
void spn__xscene_free(spn__xscene *s);
/* The name a kind gets in files: its thread kind name, or "tag_N". */
void spn__kind_label(uint32_t tag, char *buf, size_t size);
spn_status spn__export_check(const spn_export_def *def);

#endif

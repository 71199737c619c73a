/* State shared by the files of the physical construction (Mehla 2005, 5.2). */
#ifndef SPN_PHYSICAL_INTERNAL_H
#define SPN_PHYSICAL_INTERNAL_H

#include "web_internal.h"

/* A spoke as the spiral sees it: particle ids from its frame end inward to
 * the hub ring, and the direction of its frame end from the hub. */
typedef struct spn__spoke {
    uint32_t *ids;
    int n;
    double angle;
} spn__spoke;

typedef struct spn__physical {
    const spn_physical_def *def;
    spn__weaver wv;
    spn_rng rng;
    spn_vec3 centre, hub;
    uint32_t *side[SPN_WEB_MAX_ANCHORS]; /* inner-frame masses of each side, corner to corner */
    int side_n[SPN_WEB_MAX_ANCHORS];
    spn__spoke *spokes;
    int nspokes, spoke_cap;
} spn__physical;

typedef uint32_t *(*spn__spoke_fn)(spn__physical *b, uint32_t a, uint32_t c, uint32_t kind, int *count);

/* Primary spokes, hub, secondary spokes (fig. 5.10); fills b->spokes sorted by angle. */
void spn__physical_spokes(spn__physical *b, spn__spoke_fn lay);
/* Initial and processed spirals (figs. 5.15, 5.16). */
void spn__physical_spiral(spn__physical *b);
void spn__physical_free(spn__physical *b);

#endif

/* The frame of the geometric construction (Japanese thesis 2011, eqs.
 * 3.1-3.16), shared by the geometric builder and the species presets. */
#ifndef SPN_GEOMETRIC_INTERNAL_H
#define SPN_GEOMETRIC_INTERNAL_H

#include "web_internal.h"

#define SPN__GEO_MAX_ON_LINE 12

typedef struct spn__geo_params {
    double t, s, r_min, r_max, m;
    int u, v;
} spn__geo_params;

/* Per anchor i: the anchor P, attachment point P' (3.2); the arch from Q'_i
 * through its radius ends A'_{i,u} to R'_i; the frame side from R'_i through
 * its radius ends alpha'_{i,v} to Q'_{i+1}. arch[i][0] = Q'_i, arch[i][na-1] =
 * R'_i = side[i][0], side[i][ns-1] = Q'_{i+1}. */
typedef struct spn__geo_frame {
    int n;
    spn_vec3 g;
    spn_vec3 p[SPN_WEB_MAX_ANCHORS], pp[SPN_WEB_MAX_ANCHORS];
    spn_vec3 arch[SPN_WEB_MAX_ANCHORS][SPN__GEO_MAX_ON_LINE + 2];
    spn_vec3 side[SPN_WEB_MAX_ANCHORS][SPN__GEO_MAX_ON_LINE + 2];
    int na[SPN_WEB_MAX_ANCHORS], ns[SPN_WEB_MAX_ANCHORS];
} spn__geo_frame;

/* Compute the frame (eqs. 3.1-3.16); `g` overrides the centroid when not NULL. */
void spn__geo_frame_make(const spn_vec3 *anchors, int n, const spn__geo_params *gp, spn_rng *rng, spn__geo_frame *f);

#endif

/* Anchor checks shared by the builders. A web needs at least three anchors,
 * all finite and distinct, not all on one line, given in order around the web
 * so that the frame polygon through them does not cross itself (a crossing
 * frame would make radii and spiral cross too). Messages name the anchor. */
#include "web_internal.h"

#include <math.h>

spn_status spn_web_check_anchors(const spn_vec3 *anchors, int count)
{
    if (!anchors || count < 3)
        return spn_error(SPN_ERR_INVALID, "anchors: need at least 3, got %d", anchors ? count : 0);
    if (count > SPN_WEB_MAX_ANCHORS)
        return spn_error(SPN_ERR_INVALID, "anchors: at most %d, got %d", SPN_WEB_MAX_ANCHORS, count);
    double extent = 0;
    for (int i = 0; i < count; i++) {
        if (!spn_v3_finite(anchors[i])) return spn_error(SPN_ERR_INVALID, "anchor %d is not a finite point", i + 1);
        extent = fmax(extent, spn_v3_len(spn_v3_sub(anchors[i], anchors[0])));
    }
    if (!(extent > 0)) return spn_error(SPN_ERR_INVALID, "anchors: all at the same point");
    for (int i = 0; i < count; i++)
        for (int j = i + 1; j < count; j++)
            if (spn_v3_len(spn_v3_sub(anchors[i], anchors[j])) < 1e-6 * extent)
                return spn_error(SPN_ERR_INVALID, "anchors %d and %d are the same point", i + 1, j + 1);
    for (int i = 0; i < count; i++)
        for (int j = i + 2; j < count; j++) {
            if (i == 0 && j == count - 1) continue; /* neighbours around the loop */
            if (spn__segments_cross(anchors[i], anchors[(i + 1) % count], anchors[j], anchors[(j + 1) % count]))
                return spn_error(SPN_ERR_INVALID,
                                 "anchors: frame side %d-%d crosses side %d-%d; give the anchors in order around the web",
                                 i + 1, i + 2, j + 1, (j + 1) % count + 1);
        }
    double area = 0;
    for (int i = 0; i < count; i++) {
        spn_vec3 a = anchors[i], b = anchors[(i + 1) % count];
        area += a.x * b.y - b.x * a.y;
    }
    bool collinear = true;
    for (int i = 2; i < count && collinear; i++)
        if (fabs(spn__cross2(anchors[0], anchors[1], anchors[i])) > 1e-6 * extent * extent) collinear = false;
    if (collinear || fabs(area) / 2 < 1e-4 * extent * extent)
        return spn_error(SPN_ERR_INVALID, "anchors: all on one line (the web needs an area in the x-y plane)");
    return SPN_OK;
}

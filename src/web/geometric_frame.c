/* The frame of the geometric construction, after the Japanese graduation
 * thesis "automatic generation of regular orb webs" (2011), sec. 3.2-3.4:
 *   G = mean of the anchors P_i                                   (3.1)
 *   P'_i = (1-t) P_i + t G, t in [0.1, 0.2]: attachment points    (3.2)
 *   Q_i = (1-s) P'_i + s P'_{i-1},  R_i = (1-s) P'_i + s P'_{i+1}  (3.3-3.6)
 *   U radii on the arch Q_i R_i and V on the side R_i Q_{i+1}, each at the
 *   U- or V-division point B (beta) moved to (1-r) left + r right neighbour,
 *   r in [0.3, 0.7] drawn per point                              (3.7, 3.8)
 *   contraction: each radius end moves toward G by m - gamma (arches) or
 *   m - delta (sides), the offsets largest at the ends of a side so that the
 *   frame curves in toward G                                     (3.9-3.15)
 * U and V follow each arch's and side's length ("by its length"): the longest
 * gets U (V), shorter ones proportionally fewer, V at least 4 (thesis range).
 * Interpretation (the thesis' equations are ambiguous here): the arch ends Q,
 * R stay on the contracted frame, at the same fraction of the frame segment
 * P' -> alpha'_1 as before contraction; gamma is 0.05 for the arch radii
 * beside the middle one and 0 otherwise. */
#include "geometric_internal.h"

#include <math.h>
#include <string.h>

static int count_for(double len, double longest, int most, int least)
{
    int c = (int)lround(most * len / longest);
    return c < least ? least : c > most ? most : c;
}

/* Division points of a->b into c+1 parts, each moved by (3.7)/(3.8). */
static void jittered(spn_vec3 a, spn_vec3 b, int c, const spn__geo_params *gp, spn_rng *rng, spn_vec3 *out)
{
    spn_vec3 beta[SPN__GEO_MAX_ON_LINE + 2];
    for (int k = 0; k <= c + 1; k++) beta[k] = spn__lerp(a, b, (double)k / (c + 1));
    for (int k = 1; k <= c; k++) {
        double r = spn_rng_range(rng, gp->r_min, gp->r_max);
        if (gp->r_max <= gp->r_min) r = gp->r_min;
        out[k - 1] = spn__lerp(beta[k - 1], beta[k + 1], r);
    }
}

/* gamma (3.12) for arch radius u of c; delta (3.14, 3.15) for side radius v of V. */
static double gamma_of(double m, int u, int count)
{
    if (m == 0) return 0;
    int c = count % 2 ? (count + 1) / 2 : count / 2;
    return (u == c - 1 || u == c + 1) ? 0.05 : 0;
}

static double delta_of(double m, int v, int count)
{
    int d = count % 2 ? (count + 1) / 2 : count / 2;
    int off = v - d;
    if (off == 0) return 0;
    if (count % 2 == 0 && off == 1) return 0;
    if (count % 2 == 0 && off > 0) off -= 1; /* even V: the table is shifted by one above d */
    int a = off < 0 ? -off : off;
    double table = a == 1 ? 0.01 : a == 2 ? 0.02 : 0.04;
    return m < 0.03 ? fmax(table, 0.01) : table;
}

static spn_vec3 contract(spn_vec3 p, spn_vec3 g, double mu) { return spn__lerp(p, g, mu > 0 ? mu : 0); }

void spn__geo_frame_make(const spn_vec3 *anchors, int n, const spn__geo_params *gp, spn_rng *rng, spn__geo_frame *f)
{
    memset(f, 0, sizeof *f);
    f->n = n;
    for (int i = 0; i < n; i++) f->g = spn_v3_add(f->g, spn_v3_scale(anchors[i], 1.0 / n));
    for (int i = 0; i < n; i++) {
        f->p[i] = anchors[i];
        f->pp[i] = spn__lerp(anchors[i], f->g, gp->t);
    }
    spn_vec3 q[SPN_WEB_MAX_ANCHORS], r[SPN_WEB_MAX_ANCHORS];
    double arch_max = 0, side_max = 0;
    for (int i = 0; i < n; i++) {
        q[i] = spn__lerp(f->pp[i], f->pp[(i + n - 1) % n], gp->s);
        r[i] = spn__lerp(f->pp[i], f->pp[(i + 1) % n], gp->s);
        arch_max = fmax(arch_max, spn_v3_len(spn_v3_sub(r[i], q[i])));
    }
    for (int i = 0; i < n; i++) side_max = fmax(side_max, spn_v3_len(spn_v3_sub(q[(i + 1) % n], r[i])));
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        int cu = count_for(spn_v3_len(spn_v3_sub(r[i], q[i])), arch_max, gp->u, 1);
        int cv = count_for(spn_v3_len(spn_v3_sub(q[j], r[i])), side_max, gp->v, gp->v < 4 ? gp->v : 4);
        spn_vec3 a[SPN__GEO_MAX_ON_LINE], al[SPN__GEO_MAX_ON_LINE];
        jittered(q[i], r[i], cu, gp, rng, a);
        jittered(r[i], q[j], cv, gp, rng, al);
        for (int u = 0; u < cu; u++) a[u] = contract(a[u], f->g, gp->m - gamma_of(gp->m, u + 1, cu));
        for (int v = 0; v < cv; v++) al[v] = contract(al[v], f->g, gp->m - delta_of(gp->m, v + 1, cv));
        f->na[i] = cu + 2;
        f->ns[i] = cv + 2;
        memcpy(&f->arch[i][1], a, (size_t)cu * sizeof *a);
        memcpy(&f->side[i][1], al, (size_t)cv * sizeof *al);
    }
    /* Arch ends stay on the contracted frame: R_i on P'_i -> alpha'_{i,1} and
     * Q_{i+1} on alpha'_{i,V} -> P'_{i+1}, at the fraction they had before. */
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double seg = spn_v3_len(spn_v3_sub(f->pp[j], f->pp[i]));
        double fr = gp->s * seg, side_len = seg * (1 - 2 * gp->s);
        double first = fr + side_len / (f->ns[i] - 1);   /* alpha_{i,1} before jitter, roughly */
        double last = fr + side_len * (f->ns[i] - 2) / (f->ns[i] - 1);
        f->side[i][0] = spn__lerp(f->pp[i], f->side[i][1], fr / first);
        f->side[i][f->ns[i] - 1] = spn__lerp(f->pp[j], f->side[i][f->ns[i] - 2], fr / (seg - last));
    }
    for (int i = 0; i < n; i++) {
        f->arch[i][0] = f->side[(i + n - 1) % n][f->ns[(i + n - 1) % n] - 1];
        f->arch[i][f->na[i] - 1] = f->side[i][0];
    }
}

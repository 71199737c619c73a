/* Mehla's physical construction (Modeling and Animation of Orb Webs, 2005,
 * sec. 5.2; pseudo-code of figs. 5.5 and 5.10; the spiral is in
 * physical_spiral.c). Stages, in the order a spider lays them:
 *   1. centre C of the anchors' bounding box; inner-frame points I_i moved
 *      from each anchor toward C by MOVE_OUTER (fig. 5.5 steps 1-5);
 *   2. outer frame: a strand from each (fixed) anchor to its inner point;
 *      inner frame: strands between consecutive inner points (steps 6-10);
 *   3. the inward radial force on the inner frame (fig. 5.8): a string under a
 *      uniform transverse load takes a parabola, so each side is laid on the
 *      parabola of sag frame_bow * length toward C;
 *   4. primary spokes from the middle mass of each inner-frame side to the
 *      farthest frame mass (fig. 5.10 steps 1-3); the hub where they cross
 *      (steps 4-7), here a ring of hub strands round their crossing; secondary
 *      spokes from every inner-frame mass to the closest hub mass (9-12);
 *   5. the initial and processed spirals (figs. 5.15, 5.16).
 * Every strand is a chain of masses `placement` apart joined by springs of rest
 * length `rest`: laid over-extended (placement / rest - 1, 75-250% in the
 * thesis) so that it settles taut (sec. 5.1), or, with `provot`, laid at rest
 * and kept taut by the world's Provot limit. 1 thesis unit = 1 mm.
 * Invariants: anchors are the only fixed particles; every spring's stage is
 * one of spn_web_stage and its order is its place in the build. */
#include "physical_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_physical_def spn_physical_def_default(void)
{
    spn_physical_def d;
    memset(&d, 0, sizeof d);
    d.materials = spn_web_materials_preset(SPN_MATERIAL_THESIS);
    d.move_outer = 0.06;
    d.outer_placement = 0.005;
    d.outer_rest = 0.002;
    d.frame_placement = 0.020;
    d.frame_rest = 0.015;
    d.spoke_placement = 0.007;
    d.spoke_rest = 0.003;
    d.spiral_extension = 0.75;
    d.frame_bow = 0.04;
    d.hub_radius = 0.02;
    d.free_zone = 0.02;
    d.spiral_density = 5;
    d.provot = false;
    d.provot_max_strain = 0.1;
    d.seed = 1;
    d.world = spn_world_def_default();
    d.world.drag = 1.0; /* the thesis' air friction 1e-8 N s/m on 1e-8 kg particles */
    return d;
}

static spn_status check_def(const spn_physical_def *d)
{
    spn_status st = spn_web_check_anchors(d->anchors, d->anchor_count);
    if (st != SPN_OK) return st;
    struct {
        const char *name;
        double placement, rest;
    } strands[] = {{"outer", d->outer_placement, d->outer_rest},
                   {"frame", d->frame_placement, d->frame_rest},
                   {"spoke", d->spoke_placement, d->spoke_rest}};
    for (int i = 0; i < 3; i++) {
        if (!(strands[i].placement > 0) || !isfinite(strands[i].placement))
            return spn_error(SPN_ERR_INVALID, "%s_placement must be positive", strands[i].name);
        if (!(strands[i].rest > 0) || strands[i].rest > strands[i].placement)
            return spn_error(SPN_ERR_INVALID, "%s_rest must be in (0, %s_placement]", strands[i].name, strands[i].name);
    }
    if (!(d->move_outer > 0)) return spn_error(SPN_ERR_INVALID, "move_outer must be positive");
    if (!(d->spiral_extension >= 0 && d->spiral_extension <= 4))
        return spn_error(SPN_ERR_INVALID, "spiral_extension must be in [0, 4]");
    if (!(d->frame_bow >= 0 && d->frame_bow <= 0.25)) return spn_error(SPN_ERR_INVALID, "frame_bow must be in [0, 0.25]");
    if (!(d->hub_radius > 0) || !(d->free_zone >= 0))
        return spn_error(SPN_ERR_INVALID, "hub_radius must be positive and free_zone not negative");
    if (d->spiral_density < 1) return spn_error(SPN_ERR_INVALID, "spiral_density must be at least 1");
    if (d->provot && !(d->provot_max_strain > 0 && d->provot_max_strain < 1))
        return spn_error(SPN_ERR_INVALID, "provot_max_strain must be in (0, 1)");
    return SPN_OK;
}

/* Rest length for a piece laid at `len` in a strand of the given kind. */
static double rest_for(const spn__physical *b, double len, double placement, double rest)
{
    return b->def->provot ? len : len * rest / placement;
}

static int pieces(double len, double placement)
{
    int n = (int)lround(len / placement);
    return n < 1 ? 1 : n;
}

/* Stages 1-3: inner points, outer frame, bowed inner frame. */
static void lay_frame(spn__physical *b)
{
    const spn_physical_def *d = b->def;
    int n = d->anchor_count;
    spn_vec3 lo = d->anchors[0], hi = d->anchors[0];
    double z = 0;
    for (int i = 0; i < n; i++) {
        spn_vec3 a = d->anchors[i];
        lo = spn_v3(fmin(lo.x, a.x), fmin(lo.y, a.y), 0);
        hi = spn_v3(fmax(hi.x, a.x), fmax(hi.y, a.y), 0);
        z += a.z / n;
    }
    b->centre = spn_v3((lo.x + hi.x) / 2, (lo.y + hi.y) / 2, z);
    uint32_t *inner = malloc((size_t)n * sizeof *inner);
    if (!inner) {
        b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
        return;
    }
    for (int i = 0; i < n && b->wv.st == SPN_OK; i++) {
        spn_vec3 a = d->anchors[i], to_c = spn_v3_sub(b->centre, a);
        if (spn_v3_len(to_c) <= 2 * d->move_outer) {
            b->wv.st = spn_error(SPN_ERR_INVALID, "move_outer %g m is too long for anchor %d (%.3g m from the centre)",
                                 d->move_outer, i + 1, spn_v3_len(to_c));
            break;
        }
        uint32_t pa = spn__particle(&b->wv, a, true, SPN_PARTICLE_ANCHOR);
        inner[i] = spn__particle(&b->wv, spn_v3_add(a, spn_v3_scale(spn_v3_norm(to_c), d->move_outer)), false,
                                 SPN_PARTICLE_FRAME);
        int k = pieces(d->move_outer, d->outer_placement);
        double len = d->move_outer / k;
        spn__chain(&b->wv, pa, inner[i], k, rest_for(b, len, d->outer_placement, d->outer_rest), SPN_THREAD_ANCHOR,
                   SPN_STAGE_FRAME, SPN_PARTICLE_FRAME, NULL);
    }
    for (int i = 0; i < n && b->wv.st == SPN_OK; i++) {
        spn_vec3 p = spn_world_position(b->wv.w, inner[i]), q = spn_world_position(b->wv.w, inner[(i + 1) % n]);
        double len = spn_v3_len(spn_v3_sub(q, p));
        spn_vec3 mid = spn__lerp(p, q, 0.5), in = spn_v3_norm(spn_v3_sub(b->centre, mid));
        spn_vec3 dir = spn_v3_norm(spn_v3_sub(q, p));
        in = spn_v3_norm(spn_v3_sub(in, spn_v3_scale(dir, spn_v3_dot(in, dir)))); /* perpendicular to the side */
        int k = pieces(len, d->frame_placement);
        uint32_t *ids = malloc(((size_t)k + 1) * sizeof *ids);
        if (!ids) {
            b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
            break;
        }
        ids[0] = inner[i];
        for (int j = 1; j <= k && b->wv.st == SPN_OK; j++) {
            double u = (double)j / k;
            ids[j] = j == k ? inner[(i + 1) % n]
                            : spn__particle(&b->wv, spn_v3_add(spn__lerp(p, q, u), spn_v3_scale(in, 4 * u * (1 - u) * d->frame_bow * len)),
                                            false, SPN_PARTICLE_FRAME);
            double seg = spn_v3_len(spn_v3_sub(spn_world_position(b->wv.w, ids[j]), spn_world_position(b->wv.w, ids[j - 1])));
            spn__spring(&b->wv, ids[j - 1], ids[j], SPN_THREAD_FRAME, SPN_STAGE_FRAME,
                        rest_for(b, seg, d->frame_placement, d->frame_rest));
        }
        b->side[i] = ids;
        b->side_n[i] = k + 1;
    }
    free(inner);
}

/* One spoke strand from particle a to b; its ids from a to b. */
static uint32_t *lay_spoke(spn__physical *b, uint32_t a, uint32_t c, uint32_t kind, int *count)
{
    const spn_physical_def *d = b->def;
    double len = spn_v3_len(spn_v3_sub(spn_world_position(b->wv.w, c), spn_world_position(b->wv.w, a)));
    int k = pieces(len, d->spoke_placement);
    uint32_t *ids = NULL;
    spn__chain(&b->wv, a, c, k, rest_for(b, len / k, d->spoke_placement, d->spoke_rest), kind, SPN_STAGE_RADII,
               SPN_PARTICLE_RADIUS, &ids);
    *count = k + 1;
    return ids;
}

spn_status spn_web_build_physical(const spn_physical_def *def, spn_world **out)
{
    *out = NULL;
    spn_status st = check_def(def);
    if (st != SPN_OK) return st;
    spn__physical b;
    memset(&b, 0, sizeof b);
    b.def = def;
    spn_world_def wd = def->world;
    if (def->provot) wd.provot_max_strain = def->provot_max_strain;
    wd.seed = def->seed;
    spn_rng_seed(&b.rng, def->seed);
    if (spn__weaver_init(&b.wv, &wd, &def->materials) != SPN_OK) return b.wv.st;
    lay_frame(&b);
    if (b.wv.st == SPN_OK) spn__physical_spokes(&b, lay_spoke);
    if (b.wv.st == SPN_OK) spn__physical_spiral(&b);
    spn__meta m;
    spn__meta_begin(&m, "physical", def->seed, def->anchors, def->anchor_count);
    spn__meta_materials(&m, &b.wv.mat);
    spn__meta_num(&m, "move_outer", def->move_outer);
    spn__meta_num(&m, "outer_placement", def->outer_placement);
    spn__meta_num(&m, "outer_rest", def->outer_rest);
    spn__meta_num(&m, "frame_placement", def->frame_placement);
    spn__meta_num(&m, "frame_rest", def->frame_rest);
    spn__meta_num(&m, "spoke_placement", def->spoke_placement);
    spn__meta_num(&m, "spoke_rest", def->spoke_rest);
    spn__meta_num(&m, "spiral_extension", def->spiral_extension);
    spn__meta_num(&m, "frame_bow", def->frame_bow);
    spn__meta_num(&m, "hub_radius", def->hub_radius);
    spn__meta_num(&m, "free_zone", def->free_zone);
    spn__meta_num(&m, "spiral_density", def->spiral_density);
    spn__meta_num(&m, "provot", def->provot ? def->provot_max_strain : 0);
    st = spn__weaver_finish(&b.wv, spn__meta_end(&m), out);
    spn__meta_free(&m);
    spn__physical_free(&b);
    return st;
}

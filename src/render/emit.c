/* Emitting a world through the drawing callbacks (STYLE item 9): the one place
 * that decides what is drawn — strands with their width and colour, dew
 * beads, the legend — so cairo, the viewer and the exporters all show the
 * same web. Colour by tension or strain maps each spring's value linearly
 * onto the scale between the smallest and largest value in the world
 * (tension from 0), and the legend names five values along it. */
#include "render_internal.h"
#include "spinneret/web.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct value_range {
    double lo, hi;
} value_range;

static double spring_value(const spn_world *w, uint32_t s, spn_colour_by by)
{
    spn_spring_info info = spn_world_spring(w, s);
    if (by == SPN_COLOUR_TENSION) return info.tension;
    return info.rest > 0 ? (info.length - info.rest) / info.rest : 0;
}

static value_range find_range(const spn_world *w, spn_colour_by by)
{
    value_range r = {by == SPN_COLOUR_TENSION ? 0 : INFINITY, -INFINITY};
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) {
        if (spn_world_spring(w, s).broken) continue;
        double v = spring_value(w, s, by);
        if (!isfinite(v)) continue;
        r.lo = fmin(r.lo, v);
        r.hi = fmax(r.hi, v);
    }
    if (!(r.hi > r.lo)) {
        if (!isfinite(r.lo)) r.lo = 0;
        r.hi = r.lo + (r.lo != 0 ? fabs(r.lo) * 1e-3 : 1e-9);
    }
    return r;
}

static void strand_colour(const spn_render_def *def, uint32_t kind, double rgb[3])
{
    if (def->colour_by == SPN_COLOUR_KIND) {
        spn__kind_colour(kind, rgb);
        return;
    }
    double f = spn_thread_kind_shade(kind);
    for (int j = 0; j < 3; j++) rgb[j] = def->shade_rgb[j] * f;
}

/* Specular glint of a thin cylinder (Kajiya & Kay 1989, the hair model): a
 * thread of tangent t reflects the light into the eye in proportion to
 * sin(t, h)^n, h halfway between light and eye, so threads lying across h
 * light up. On a ring of spiral that gives the two bright arcs of a web
 * seen against the sun. */
static double glint(spn_vec3 a, spn_vec3 b, spn_vec3 light, const spn_camera *cam)
{
    spn_vec3 t = spn_v3_norm(spn_v3_sub(b, a));
    spn_vec3 view = spn_v3(0, 0, 1);
    if (cam->kind == SPN_CAMERA_PERSPECTIVE) view = spn_v3_norm(spn_v3_sub(cam->eye, spn_v3_scale(spn_v3_add(a, b), 0.5)));
    spn_vec3 h = spn_v3_norm(spn_v3_add(light, view));
    if (spn_v3_len(h) == 0) h = view;
    double c = spn_v3_dot(t, h), s2 = fmax(0, 1 - c * c);
    return pow(s2, 0.5 * 24);
}

static spn_status emit_strands(const spn_world *w, const spn_render_def *def, const spn__strands *s,
                               const spn_draw_fns *fns, void *user)
{
    bool scaled = def->colour_by == SPN_COLOUR_TENSION || def->colour_by == SPN_COLOUR_STRAIN;
    value_range r = scaled ? find_range(w, def->colour_by) : (value_range){0, 1};
    double *seg_rgb = scaled ? malloc(((size_t)s->point_count + 1) * 3 * sizeof *seg_rgb) : NULL;
    double *seg_glint = def->sheen > 0 ? malloc(((size_t)s->point_count + 1) * sizeof *seg_glint) : NULL;
    spn_vec3 light = spn_v3_norm(def->light);
    if ((scaled && !seg_rgb) || (def->sheen > 0 && !seg_glint)) {
        free(seg_rgb);
        return spn_error(SPN_ERR_NOMEM, "render: out of memory");
    }
    spn_status st = SPN_OK;
    for (uint32_t i = 0; i < s->chain_count && st == SPN_OK; i++) {
        const spn__chain *c = &s->chains[i];
        spn_strand out = {c->kind, c->count, s->points + c->first, s->particles + c->first, s->springs + c->first,
                          c->closed, spn_thread_kind_width(c->kind) * def->width_scale, {0, 0, 0}, NULL, def->alpha,
                          NULL};
        strand_colour(def, c->kind, out.rgb);
        /* With sheen, silk away from the glints fades, as in backlight. */
        out.alpha *= 1 - 0.5 * def->sheen;
        uint32_t segs = c->closed ? c->count : c->count - 1;
        for (uint32_t k = 0; scaled && k < segs; k++) {
            double v = spring_value(w, out.springs[k], def->colour_by);
            spn__scale_colour((v - r.lo) / (r.hi - r.lo), seg_rgb + 3 * k);
        }
        for (uint32_t k = 0; seg_glint && k < segs; k++)
            seg_glint[k] = def->sheen * glint(out.points[k], out.points[(k + 1) % c->count], light, &def->camera);
        out.segment_rgb = seg_rgb;
        out.segment_glint = seg_glint;
        st = fns->strand(user, &out);
    }
    free(seg_rgb);
    free(seg_glint);
    return st;
}

static spn_status emit_scale_legend(const spn_world *w, const spn_render_def *def, const spn_draw_fns *fns,
                                    void *user)
{
    bool tension = def->colour_by == SPN_COLOUR_TENSION;
    value_range r = find_range(w, def->colour_by);
    char text[64];
    spn_label title = {tension ? "tension [mN]" : "strain [%]", {1, 1, 1}, 0, 6};
    spn_status st = fns->label(user, &title);
    for (int i = 0; i < 5 && st == SPN_OK; i++) {
        double t = 1 - i / 4.0, v = r.lo + t * (r.hi - r.lo);
        snprintf(text, sizeof text, "%.3g", v * (tension ? 1e3 : 100));
        spn_label row = {text, {0, 0, 0}, i + 1, 6};
        spn__scale_colour(t, row.rgb);
        st = fns->label(user, &row);
    }
    return st;
}

static spn_status emit_kind_legend(const spn__strands *s, const spn_draw_fns *fns, void *user)
{
    /* Kinds appear in chain order (sorted by rank then tag): list each once. */
    uint32_t kinds[64];
    int n = 0;
    for (uint32_t i = 0; i < s->chain_count && n < 64; i++)
        if (n == 0 || kinds[n - 1] != s->chains[i].kind) kinds[n++] = s->chains[i].kind;
    spn_label title = {"thread kind", {1, 1, 1}, 0, n + 1};
    spn_status st = fns->label(user, &title);
    char text[32];
    for (int i = 0; i < n && st == SPN_OK; i++) {
        const char *name = spn_thread_kind_name(kinds[i]);
        if (!name) snprintf(text, sizeof text, "tag %u", kinds[i]);
        spn_label row = {name ? name : text, {0, 0, 0}, i + 1, n + 1};
        spn__kind_colour(kinds[i], row.rgb);
        st = fns->label(user, &row);
    }
    return st;
}

spn_status spn_draw_world(const spn_world *w, const spn_render_def *def, const spn_draw_fns *fns, void *user)
{
    spn_status st = spn_render_def_check(def);
    if (st != SPN_OK) return st;
    spn__strands s;
    st = spn__strands_build(w, &s);
    if (st != SPN_OK) return st;
    if (fns->strand) st = emit_strands(w, def, &s, fns, user);
    if (st == SPN_OK && fns->bead && def->dew.enabled) {
        spn__bead_list beads = {0};
        st = spn__dew_place(&s, &def->dew, &beads);
        for (size_t i = 0; i < beads.count && st == SPN_OK; i++) st = fns->bead(user, &beads.beads[i]);
        spn__bead_list_free(&beads);
    }
    if (st == SPN_OK && fns->label && def->legend && def->colour_by != SPN_COLOUR_SHADE)
        st = def->colour_by == SPN_COLOUR_KIND ? emit_kind_legend(&s, fns, user) : emit_scale_legend(w, def, fns, user);
    spn__strands_free(&s);
    return st;
}

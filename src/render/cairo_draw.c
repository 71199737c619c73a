/* The cairo backend of the drawing callbacks: background (a colour, or a PNG
 * scaled to cover the canvas and cropped, as the texture-mapped backdrop of
 * Mehla 2005, sec. 5.3.7 / fig. 5.39), strands as single anti-aliased strokes
 * with round joins (one path per strand, so alpha never doubles at a joint,
 * sec. 5.3.8), dew drops as small lit water lenses, and the legend.
 * Invariants: nothing here reads the physics; it draws what spn_draw_world
 * emits, in that order, so the picture is a function of the world and def. */
#include "render_internal.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>

typedef struct canvas {
    cairo_t *cr;
    const spn_render_def *def;
    spn__view view;
    cairo_surface_t *bg;       /* background image, or NULL */
    double bg_scale, bg_ox, bg_oy;
    double bg_luma;            /* mean brightness of the background, 0..1 */
} canvas;

static spn_status load_background(canvas *c)
{
    const spn_render_def *d = c->def;
    c->bg_luma = 0.2126 * d->background_rgb[0] + 0.7152 * d->background_rgb[1] + 0.0722 * d->background_rgb[2];
    if (!d->background_png) return SPN_OK;
    spn_status st = spn__backdrop_get(d->background_png, &c->bg, &c->bg_luma);
    if (st != SPN_OK) return st;
    int bw = cairo_image_surface_get_width(c->bg), bh = cairo_image_surface_get_height(c->bg);
    c->bg_scale = fmax(c->view.width / bw, c->view.height / bh);
    c->bg_ox = 0.5 * (c->view.width - bw * c->bg_scale);
    c->bg_oy = 0.5 * (c->view.height - bh * c->bg_scale);
    return SPN_OK;
}

static void paint_background(canvas *c)
{
    cairo_t *cr = c->cr;
    const double *rgb = c->def->background_rgb;
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_paint(cr);
    if (!c->bg) return;
    cairo_save(cr);
    cairo_translate(cr, c->bg_ox, c->bg_oy);
    cairo_scale(cr, c->bg_scale, c->bg_scale);
    cairo_set_source_surface(cr, c->bg, 0, 0);
    cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_GOOD);
    cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
    cairo_paint(cr);
    cairo_restore(cr);
}

/* Bezier control points of the centripetal Catmull-Rom segment p1 -> p2
 * (Yuksel, Schaefer & Keyser 2011: no cusps or overshoot on uneven spacing). */
static void catmull_rom(const double *p0, const double *p1, const double *p2, const double *p3, double c[4])
{
    double d1 = pow(hypot(p1[0] - p0[0], p1[1] - p0[1]), 0.5), d2 = pow(hypot(p2[0] - p1[0], p2[1] - p1[1]), 0.5);
    double d3 = pow(hypot(p3[0] - p2[0], p3[1] - p2[1]), 0.5);
    for (int k = 0; k < 2; k++) {
        c[k] = d1 > 1e-9 ? (d1 * d1 * p2[k] - d2 * d2 * p0[k] + (2 * d1 * d1 + 3 * d1 * d2 + d2 * d2) * p1[k]) /
                               (3 * d1 * (d1 + d2))
                         : p1[k];
        c[2 + k] = d3 > 1e-9 ? (d3 * d3 * p1[k] - d2 * d2 * p3[k] + (2 * d3 * d3 + 3 * d3 * d2 + d2 * d2) * p2[k]) /
                                   (3 * d3 * (d3 + d2))
                             : p2[k];
    }
}

/* The strand as one curve through its projected points; false (nothing
 * drawn) when a point is behind the camera. */
static bool smooth_path(canvas *c, const spn_strand *s)
{
    uint32_t n = s->count;
    double(*p)[2] = malloc((size_t)n * sizeof *p);
    bool ok = p != NULL;
    for (uint32_t i = 0; i < n && ok; i++) ok = spn__view_project(&c->view, s->points[i], &p[i][0], &p[i][1], NULL);
    if (ok) {
        cairo_new_path(c->cr);
        cairo_move_to(c->cr, p[0][0], p[0][1]);
        uint32_t segs = s->closed ? n : n - 1;
        for (uint32_t i = 0; i < segs; i++) {
            /* Ends of an open strand repeat their point: the curve meets them straight. */
            uint32_t i0 = s->closed ? (i + n - 1) % n : (i > 0 ? i - 1 : 0), i2 = (i + 1) % n;
            uint32_t i3 = s->closed ? (i + 2) % n : (i + 2 < n ? i + 2 : n - 1);
            double ctl[4];
            catmull_rom(p[i0], p[i], p[i2], p[i3], ctl);
            cairo_curve_to(c->cr, ctl[0], ctl[1], ctl[2], ctl[3], p[i2][0], p[i2][1]);
        }
        if (s->closed) cairo_close_path(c->cr);
    }
    free(p);
    return ok;
}

/* Build the strand's path; a point behind the camera breaks it. */
static void strand_path(canvas *c, const spn_strand *s)
{
    if (c->def->smooth && s->count > 2 && smooth_path(c, s)) return;
    cairo_new_path(c->cr);
    bool pen = false;
    uint32_t n = s->closed ? s->count + 1 : s->count;
    for (uint32_t i = 0; i < n; i++) {
        double x, y;
        if (!spn__view_project(&c->view, s->points[i % s->count], &x, &y, NULL)) {
            pen = false;
            continue;
        }
        if (pen) cairo_line_to(c->cr, x, y);
        else cairo_move_to(c->cr, x, y);
        pen = true;
    }
    if (s->closed && pen) cairo_close_path(c->cr);
}

static void stroke_rgb(canvas *c, const double rgb[3], double alpha, double width)
{
    cairo_set_source_rgba(c->cr, rgb[0], rgb[1], rgb[2], alpha);
    cairo_set_line_width(c->cr, width);
    cairo_stroke_preserve(c->cr);
}

/* Colour by value: each segment its own stroke (joints round-capped). */
static void draw_segments(canvas *c, const spn_strand *s, double width)
{
    uint32_t segs = s->closed ? s->count : s->count - 1;
    for (uint32_t k = 0; k < segs; k++) {
        double x0, y0, x1, y1;
        if (!spn__view_project(&c->view, s->points[k], &x0, &y0, NULL) ||
            !spn__view_project(&c->view, s->points[(k + 1) % s->count], &x1, &y1, NULL))
            continue;
        cairo_new_path(c->cr);
        cairo_move_to(c->cr, x0, y0);
        cairo_line_to(c->cr, x1, y1);
        stroke_rgb(c, s->segment_rgb + 3 * k, s->alpha, width);
    }
    cairo_new_path(c->cr);
}

/* Glints over the strand: each lit segment again, brighter and wider, with a
 * bloom; butt caps, so overlaps at joints stay under the base stroke's width. */
static void draw_glints(canvas *c, const spn_strand *s, double width)
{
    uint32_t segs = s->closed ? s->count : s->count - 1;
    double u = c->view.px_per_ref, hot[3];
    for (int j = 0; j < 3; j++) hot[j] = 0.2 * s->rgb[j] + 0.8;
    cairo_set_line_cap(c->cr, CAIRO_LINE_CAP_BUTT);
    for (uint32_t k = 0; k < segs; k++) {
        double g = s->segment_glint[k], x0, y0, x1, y1;
        if (g < 0.02 || !spn__view_project(&c->view, s->points[k], &x0, &y0, NULL) ||
            !spn__view_project(&c->view, s->points[(k + 1) % s->count], &x1, &y1, NULL))
            continue;
        cairo_new_path(c->cr);
        cairo_move_to(c->cr, x0, y0);
        cairo_line_to(c->cr, x1, y1);
        double a = fmin(1, s->alpha * 2 * g);
        stroke_rgb(c, hot, a * 0.10, width + 8 * u);
        stroke_rgb(c, hot, a * 0.25, width + 2.5 * u);
        stroke_rgb(c, hot, a, width * 1.2);
    }
    cairo_new_path(c->cr);
    cairo_set_line_cap(c->cr, CAIRO_LINE_CAP_ROUND);
}

static spn_status draw_strand(void *user, const spn_strand *s)
{
    canvas *c = user;
    double width = s->width * c->view.px_per_ref;
    cairo_set_line_cap(c->cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_join(c->cr, CAIRO_LINE_JOIN_ROUND);
    if (s->segment_rgb) {
        draw_segments(c, s, width);
        return SPN_OK;
    }
    strand_path(c, s);
    if (c->def->glow > 0) {
        /* A soft halo: light scattered by the silk, widest and faintest first. */
        stroke_rgb(c, s->rgb, s->alpha * c->def->glow * 0.05, width + 6 * c->view.px_per_ref);
        stroke_rgb(c, s->rgb, s->alpha * c->def->glow * 0.10, width + 2.5 * c->view.px_per_ref);
    }
    stroke_rgb(c, s->rgb, s->alpha, width);
    cairo_new_path(c->cr);
    if (s->segment_glint) draw_glints(c, s, width);
    return SPN_OK;
}

static spn_status draw_bead(void *user, const spn_bead *b)
{
    canvas *c = user;
    double x, y, depth;
    if (!spn__view_project(&c->view, b->centre, &x, &y, &depth)) return SPN_OK;
    double r = c->view.kind == SPN_CAMERA_PERSPECTIVE ? b->radius * c->view.focal / depth : b->radius * c->view.scale;
    if (r < 0.25 || x + r < 0 || y + r < 0 || x - r > c->view.width || y - r > c->view.height) return SPN_OK;
    double map[3] = {c->bg_scale, c->bg_ox, c->bg_oy};
    spn__cairo_water_drop(c->cr, x, y, r, c->bg_luma, c->bg, map);
    return SPN_OK;
}

static spn_status draw_label(void *user, const spn_label *l)
{
    canvas *c = user;
    cairo_t *cr = c->cr;
    double u = c->view.px_per_ref, row_h = 24 * u, x0 = 18 * u, y0 = 18 * u, pad = 10 * u;
    cairo_save(cr);
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           l->row == 0 ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 15 * u);
    if (l->row == 0) {
        cairo_rectangle(cr, x0, y0, 190 * u, l->rows * row_h + 2 * pad);
        cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
        cairo_fill(cr);
    }
    double ty = y0 + pad + l->row * row_h + 17 * u;
    if (l->row > 0) {
        cairo_rectangle(cr, x0 + pad, ty - 13 * u, 26 * u, 14 * u);
        cairo_set_source_rgb(cr, l->rgb[0], l->rgb[1], l->rgb[2]);
        cairo_fill(cr);
    }
    cairo_move_to(cr, x0 + pad + (l->row > 0 ? 36 * u : 0), ty);
    cairo_set_source_rgb(cr, 0.92, 0.92, 0.92);
    cairo_show_text(cr, l->text);
    cairo_restore(cr);
    return SPN_OK;
}

spn_status spn__cairo_draw(const spn_world *w, const spn_render_def *def, cairo_t *cr)
{
    canvas c = {cr, def, {0}, NULL, 1, 0, 0, 0};
    spn_status st = spn__view_setup(w, def, &c.view);
    if (st == SPN_OK) st = load_background(&c);
    if (st != SPN_OK) return st;
    paint_background(&c);
    spn_draw_fns fns = {draw_strand, draw_bead, draw_label};
    st = spn_draw_world(w, def, &fns, &c);
    if (c.bg) cairo_surface_destroy(c.bg);
    if (st == SPN_OK && cairo_status(cr) != CAIRO_STATUS_SUCCESS)
        st = spn_error(SPN_ERR_IO, "render: cairo: %s", cairo_status_to_string(cairo_status(cr)));
    return st;
}

/* A dew drop drawn as a small water lens (the future work of Mehla 2005,
 * ch. 7). A water sphere on a thread shows, in order of what the eye reads:
 *  - the scene behind it, upside down and shrunk (a ball lens inverts what it
 *    sees; here a region three radii wide is mapped onto the drop),
 *  - a Fresnel rim: grazing rays reflect, so the edge is brighter than the
 *    body on a dark backdrop and darker on a bright one,
 *  - a caustic: light from the upper left focuses on the lower right inside,
 *  - a small sharp specular highlight of the light, upper left.
 * Light comes from the upper left for every drop, so the web reads as lit by
 * one sun. Drops under 1.5 px are drawn as a lit point only. */
#include "render_internal.h"

#include <cairo.h>
#include <math.h>

static void radial(cairo_t *cr, double cx, double cy, double r0, double r1, const double stops[][5], int n)
{
    cairo_pattern_t *p = cairo_pattern_create_radial(cx, cy, r0, cx, cy, r1);
    for (int i = 0; i < n; i++)
        cairo_pattern_add_color_stop_rgba(p, stops[i][0], stops[i][1], stops[i][2], stops[i][3], stops[i][4]);
    cairo_set_source(cr, p);
    cairo_pattern_destroy(p);
}

/* The background seen through the drop: inverted about its centre, three
 * radii of scene squeezed into one. */
static void lens(cairo_t *cr, double x, double y, cairo_surface_t *bg, const double m[3])
{
    const double k = 3.0;
    cairo_pattern_t *p = cairo_pattern_create_for_surface(bg);
    cairo_matrix_t mat;
    /* device p -> canvas q = (1 + k) c - k p -> image (q - offset) / scale */
    cairo_matrix_init(&mat, -k / m[0], 0, 0, -k / m[0], ((1 + k) * x - m[1]) / m[0], ((1 + k) * y - m[2]) / m[0]);
    cairo_pattern_set_matrix(p, &mat);
    cairo_pattern_set_extend(p, CAIRO_EXTEND_PAD);
    cairo_pattern_set_filter(p, CAIRO_FILTER_GOOD);
    cairo_set_source(cr, p);
    cairo_paint_with_alpha(cr, 0.9);
    cairo_pattern_destroy(p);
}

static void tiny_drop(cairo_t *cr, double x, double y, double r)
{
    const double s[][5] = {{0, 1, 1, 1, 0.9}, {0.5, 0.85, 0.9, 1, 0.5}, {1, 0.8, 0.85, 0.95, 0}};
    radial(cr, x, y, 0, fmax(r, 0.6) * 1.3, s, 3);
    cairo_arc(cr, x, y, fmax(r, 0.6) * 1.3, 0, 2 * SPN_PI);
    cairo_fill(cr);
}

void spn__cairo_water_drop(cairo_t *cr, double x, double y, double r, double bg_luma, cairo_surface_t *bg,
                           const double bg_map[3])
{
    if (r < 1.5) {
        tiny_drop(cr, x, y, r);
        return;
    }
    bool dark = bg_luma < 0.5;
    cairo_save(cr);
    cairo_new_path(cr);
    cairo_arc(cr, x, y, r, 0, 2 * SPN_PI);
    cairo_clip(cr);
    if (bg) lens(cr, x, y, bg, bg_map);
    /* Body: a faint cool tint, then the rim. */
    double e = dark ? 0.85 : 0.08;
    const double rim[][5] = {{0, 0.75, 0.85, 0.95, dark ? 0.10 : 0.04},
                             {0.72, e, e + 0.04, e + 0.08, dark ? 0.12 : 0.08},
                             {0.93, e, e + 0.04, e + 0.08, dark ? 0.55 : 0.5},
                             {1, e, e + 0.04, e + 0.08, dark ? 0.35 : 0.65}};
    radial(cr, x, y, 0, r, rim, 4);
    cairo_paint(cr);
    /* Caustic: the light focused on the far (lower right) side. */
    const double caustic[][5] = {{0, 1, 1, 0.95, 0.75}, {0.45, 1, 1, 0.95, 0.25}, {1, 1, 1, 0.95, 0}};
    radial(cr, x + 0.38 * r, y + 0.42 * r, 0, 0.55 * r, caustic, 3);
    cairo_paint(cr);
    /* Specular highlight of the light, upper left. */
    const double spec[][5] = {{0, 1, 1, 1, 1}, {0.35, 1, 1, 1, 0.95}, {1, 1, 1, 1, 0}};
    radial(cr, x - 0.36 * r, y - 0.38 * r, 0, 0.3 * r, spec, 3);
    cairo_paint(cr);
    cairo_restore(cr);
}

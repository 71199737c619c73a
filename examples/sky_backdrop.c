/* A procedural backdrop for webs: a dawn sky, out-of-focus foliage and light
 * (bokeh), and two sharp branches for a web to hang between — the kind of
 * photograph Mehla mapped behind his webs (thesis sec. 5.3.7, fig. 5.39),
 * painted with cairo from a seeded spn_rng so the same seed gives the same
 * picture.
 *
 *   example_sky_backdrop [OUT.png [WxH [SEED]]]   (default sky_backdrop.png 1600x1200 7)
 *
 * The demo (demo/30-render.sh) renders webs over it with --background. */
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <spinneret/spinneret.h>

static void sky(cairo_t *cr, double w, double h)
{
    cairo_pattern_t *g = cairo_pattern_create_linear(0, 0, 0, h);
    cairo_pattern_add_color_stop_rgb(g, 0.0, 0.10, 0.14, 0.24);
    cairo_pattern_add_color_stop_rgb(g, 0.45, 0.30, 0.36, 0.46);
    cairo_pattern_add_color_stop_rgb(g, 0.80, 0.62, 0.56, 0.50);
    cairo_pattern_add_color_stop_rgb(g, 1.0, 0.78, 0.64, 0.48);
    cairo_set_source(cr, g);
    cairo_paint(cr);
    cairo_pattern_destroy(g);
    /* The low sun, off to the right, behind haze. */
    cairo_pattern_t *sun = cairo_pattern_create_radial(0.78 * w, 0.82 * h, 0, 0.78 * w, 0.82 * h, 0.7 * h);
    cairo_pattern_add_color_stop_rgba(sun, 0, 1.0, 0.88, 0.66, 0.75);
    cairo_pattern_add_color_stop_rgba(sun, 0.25, 0.95, 0.75, 0.55, 0.30);
    cairo_pattern_add_color_stop_rgba(sun, 1, 0.9, 0.7, 0.5, 0);
    cairo_set_source(cr, sun);
    cairo_paint(cr);
    cairo_pattern_destroy(sun);
}

/* A soft disc: out-of-focus leaves (dark) or light (bright). */
static void blob(cairo_t *cr, double x, double y, double r, double red, double green, double blue, double a)
{
    cairo_pattern_t *p = cairo_pattern_create_radial(x, y, 0, x, y, r);
    cairo_pattern_add_color_stop_rgba(p, 0, red, green, blue, a);
    cairo_pattern_add_color_stop_rgba(p, 0.6, red, green, blue, a * 0.7);
    cairo_pattern_add_color_stop_rgba(p, 1, red, green, blue, 0);
    cairo_set_source(cr, p);
    cairo_arc(cr, x, y, r, 0, 2 * SPN_PI);
    cairo_fill(cr);
    cairo_pattern_destroy(p);
}

static void foliage(cairo_t *cr, double w, double h, spn_rng *rng)
{
    /* Distant trees: dark blobs thickening towards the bottom and the sides. */
    for (int i = 0; i < 260; i++) {
        double x = spn_rng_uniform(rng) * w, t = spn_rng_uniform(rng);
        double y = h * (0.55 + 0.5 * sqrt(t)) - 0.25 * h * pow(fabs(x / w - 0.5) * 2, 2);
        double r = h * spn_rng_range(rng, 0.04, 0.12);
        blob(cr, x, y, r, 0.10, 0.13 + 0.05 * spn_rng_uniform(rng), 0.10, spn_rng_range(rng, 0.25, 0.55));
    }
    /* Bokeh: sunlight through the leaves, round and soft. */
    for (int i = 0; i < 70; i++) {
        double x = spn_rng_uniform(rng) * w, y = h * spn_rng_range(rng, 0.45, 1.0);
        double r = h * spn_rng_range(rng, 0.008, 0.035);
        blob(cr, x, y, r, 1.0, 0.86, 0.62, spn_rng_range(rng, 0.10, 0.35));
    }
}

static void leaf(cairo_t *cr, double x, double y, double angle, double size, spn_rng *rng)
{
    cairo_save(cr);
    cairo_translate(cr, x, y);
    cairo_rotate(cr, angle);
    cairo_scale(cr, size, size * 0.42);
    cairo_arc(cr, 0.5, 0, 0.5, 0, 2 * SPN_PI);
    cairo_restore(cr);
    double g = spn_rng_range(rng, 0.08, 0.13);
    cairo_set_source_rgba(cr, 0.05, g, 0.05, 0.95);
    cairo_fill(cr);
}

/* A tapering, slightly bent branch that forks until its twigs carry leaves. */
static void branch(cairo_t *cr, double x, double y, double angle, double len, double width, int depth, spn_rng *rng)
{
    double bend = spn_rng_range(rng, -0.25, 0.25);
    double mx = x + 0.5 * len * cos(angle + bend), my = y + 0.5 * len * sin(angle + bend);
    double ex = x + len * cos(angle), ey = y + len * sin(angle);
    cairo_move_to(cr, x, y);
    cairo_curve_to(cr, mx, my, mx, my, ex, ey);
    cairo_set_line_width(cr, width);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_source_rgb(cr, 0.07, 0.055, 0.045);
    cairo_stroke(cr);
    if (depth == 0 || width < 1.2) {
        for (int i = 0; i < 3; i++)
            leaf(cr, ex, ey, angle + spn_rng_range(rng, -1.2, 1.2), len * spn_rng_range(rng, 0.5, 0.9), rng);
        return;
    }
    int forks = 2 + (spn_rng_uniform(rng) < 0.35);
    for (int i = 0; i < forks; i++) {
        double t = spn_rng_range(rng, 0.55, 1.0);
        double bx = x + t * (ex - x), by = y + t * (ey - y);
        double turn = (i - (forks - 1) * 0.5) * spn_rng_range(rng, 0.35, 0.7) + spn_rng_range(rng, -0.15, 0.15);
        branch(cr, bx, by, angle + turn, len * spn_rng_range(rng, 0.62, 0.8), width * 0.66, depth - 1, rng);
    }
}

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "sky_backdrop.png";
    int w = 1600, h = 1200;
    unsigned long long seed = 7;
    if (argc > 2 && (sscanf(argv[2], "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192)) {
        fprintf(stderr, "example_sky_backdrop: size must be WxH, 16..8192, got '%s'\n", argv[2]);
        return 2;
    }
    if (argc > 3) seed = strtoull(argv[3], NULL, 10);
    spn_rng rng;
    spn_rng_seed(&rng, seed);
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
    cairo_t *cr = cairo_create(s);
    sky(cr, w, h);
    foliage(cr, w, h, &rng);
    /* One branch from the upper left, one from the right: a frame for a web. */
    branch(cr, -0.02 * w, 0.04 * h, 0.10, 0.24 * w, 0.020 * h, 5, &rng);
    branch(cr, 1.02 * w, 0.80 * h, SPN_PI + 0.30, 0.17 * w, 0.016 * h, 5, &rng);
    cairo_destroy(cr);
    cairo_status_t st = cairo_surface_write_to_png(s, out);
    cairo_surface_destroy(s);
    if (st != CAIRO_STATUS_SUCCESS) {
        fprintf(stderr, "example_sky_backdrop: %s: %s\n", out, cairo_status_to_string(st));
        return 1;
    }
    return 0;
}

/* The comparison of Mehla 2005, ch. 6: the settled web drawn to a raster (the
 * "source image", the thesis captured it from the screen), both images
 * dilated with a 7x7 structuring element, then for each capture segment the
 * ink of both summed over its neighbourhood — the rectangle five pixels wide
 * (the segment's own pixel and two either side) along the segment — and the
 * score of fig. 6.9 taken from their ratio.
 *
 * Ink, not brightness: 1 where there is thread or message, 0 elsewhere, so
 * that the ratio reads "how much of this segment's neighbourhood the message
 * covers" (docs/inscription.md explains the choice). Dilation of ink is the
 * grey-scale max filter, which "enlarges the boundaries of the strands and of
 * the dark region in the target", as the thesis describes it. */
#include "inscribe_internal.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_status spn__raster_web(const spn_world *w, const spn_target *t, float *ink)
{
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, t->width, t->height);
    cairo_t *cr = cairo_create(surf);
    if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) {
        cairo_destroy(cr);
        cairo_surface_destroy(surf);
        return spn_error(SPN_ERR_NOMEM, "inscribe: cannot make a %dx%d raster", t->width, t->height);
    }
    /* Aliased one-pixel lines, as a screen capture of line drawing: every
     * thread leaves full-ink pixels, so the dilated band is all ink. */
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    cairo_set_line_width(cr, 1.0);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken) continue;
        double ax, ay, bx, by;
        spn_target_to_pixel(t, spn_world_position(w, si.a), &ax, &ay);
        spn_target_to_pixel(t, spn_world_position(w, si.b), &bx, &by);
        cairo_move_to(cr, ax, ay);
        cairo_line_to(cr, bx, by);
    }
    cairo_stroke(cr);
    cairo_surface_flush(surf);
    const unsigned char *px = cairo_image_surface_get_data(surf);
    int stride = cairo_image_surface_get_stride(surf);
    for (int j = 0; j < t->height; j++)
        for (int i = 0; i < t->width; i++)
            ink[(size_t)j * (size_t)t->width + (size_t)i] = px[(size_t)j * (size_t)stride + (size_t)i] / 255.0f;
    cairo_destroy(cr);
    cairo_surface_destroy(surf);
    return SPN_OK;
}

/* Running max over a window of 2r+1 along one axis (separable square element). */
static void max_pass(const float *in, float *out, int n, int stride, int count, int step, int r)
{
    for (int line = 0; line < count; line++) {
        const float *a = in + (size_t)line * (size_t)step;
        float *b = out + (size_t)line * (size_t)step;
        for (int i = 0; i < n; i++) {
            int lo = i - r < 0 ? 0 : i - r, hi = i + r >= n ? n - 1 : i + r;
            float m = 0;
            for (int k = lo; k <= hi; k++) m = fmaxf(m, a[(size_t)k * (size_t)stride]);
            b[(size_t)i * (size_t)stride] = m;
        }
    }
}

spn_status spn__dilate(float *ink, int width, int height, int r)
{
    float *tmp = malloc((size_t)width * (size_t)height * sizeof *tmp);
    if (!tmp) return spn_error(SPN_ERR_NOMEM, "out of memory");
    max_pass(ink, tmp, width, 1, height, width, r);  /* rows */
    max_pass(tmp, ink, height, width, width, 1, r);  /* columns */
    free(tmp);
    return SPN_OK;
}

double spn__band_sum(const spn_target *t, const float *ink, spn_vec3 a, spn_vec3 b, double *count)
{
    double ax, ay, bx, by;
    spn_target_to_pixel(t, a, &ax, &ay);
    spn_target_to_pixel(t, b, &bx, &by);
    double dx = bx - ax, dy = by - ay, len = hypot(dx, dy);
    double h = SPN__BAND_HALF;
    int i0 = (int)floor(fmin(ax, bx) - h), i1 = (int)ceil(fmax(ax, bx) + h);
    int j0 = (int)floor(fmin(ay, by) - h), j1 = (int)ceil(fmax(ay, by) + h);
    i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0;
    i1 = i1 > t->width ? t->width : i1, j1 = j1 > t->height ? t->height : j1;
    double ux = len > 0 ? dx / len : 1, uy = len > 0 ? dy / len : 0, sum = 0, n = 0;
    for (int j = j0; j < j1; j++)
        for (int i = i0; i < i1; i++) {
            double px = i + 0.5 - ax, py = j + 0.5 - ay;
            double along = px * ux + py * uy, across = fabs(py * ux - px * uy);
            if (along < 0 || along > len || across > h) continue;
            sum += ink[(size_t)j * (size_t)t->width + (size_t)i];
            n += 1;
        }
    if (count) *count = n;
    return sum;
}

int spn__score(double source_sum, double target_sum)
{
    /* The ratio of fig. 6.9 read on ink: the message's ink over the web's in
     * the segment's band. The dilated band is full of web ink, so this is the
     * fraction of the neighbourhood the dilated message covers. */
    double ratio = source_sum > 0 ? target_sum / source_sum : 0;
    int score = (int)floor(10 * ratio + 1e-9);
    return score < 1 ? 1 : score > 10 ? 10 : score;
}

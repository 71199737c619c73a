/* The overlaid images of Mehla 2005, figs. 6.3 and 6.10: the web (the source
 * image) dark on white, with the dilated target over it in translucent red,
 * so one sees which capture segments the message covers. Same frame and
 * size as the target. Written atomically. */
#include "inscribe_internal.h"

#include <cairo.h>
#include <stdlib.h>
#include <string.h>

static void draw_threads(cairo_t *cr, const spn_world *w, const spn_target *t, bool inscription)
{
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken || (si.tag == SPN_THREAD_INSCRIPTION) != inscription) continue;
        double ax, ay, bx, by;
        spn_target_to_pixel(t, spn_world_position(w, si.a), &ax, &ay);
        spn_target_to_pixel(t, spn_world_position(w, si.b), &bx, &by);
        cairo_move_to(cr, ax, ay);
        cairo_line_to(cr, bx, by);
    }
    cairo_stroke(cr);
}

static spn_status paint_target(cairo_t *cr, const spn_target *t)
{
    float *dil = spn__raster_alloc(t);
    if (!dil) return spn_error(SPN_ERR_NOMEM, "out of memory");
    memcpy(dil, t->ink, (size_t)t->width * (size_t)t->height * sizeof *dil);
    spn_status st = spn__dilate(dil, t->width, t->height, SPN__DILATE_RADIUS);
    cairo_surface_t *mask = cairo_image_surface_create(CAIRO_FORMAT_A8, t->width, t->height);
    if (st == SPN_OK && cairo_surface_status(mask) == CAIRO_STATUS_SUCCESS) {
        cairo_surface_flush(mask);
        unsigned char *px = cairo_image_surface_get_data(mask);
        int stride = cairo_image_surface_get_stride(mask);
        for (int j = 0; j < t->height; j++)
            for (int i = 0; i < t->width; i++)
                px[(size_t)j * (size_t)stride + (size_t)i] =
                    (unsigned char)(255.0f * dil[(size_t)j * (size_t)t->width + (size_t)i] + 0.5f);
        cairo_surface_mark_dirty(mask);
        cairo_set_source_rgba(cr, 0.85, 0.1, 0.1, 0.45);
        cairo_mask_surface(cr, mask, 0, 0);
    }
    cairo_surface_destroy(mask);
    free(dil);
    return st;
}

spn_status spn_inscribe_overlay(const spn_world *w, const spn_target *t, const char *path)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, false);
    if (st != SPN_OK) return st;
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, t->width, t->height);
    cairo_t *cr = cairo_create(surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_width(cr, 1.0);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    draw_threads(cr, w, t, false);
    cairo_set_line_width(cr, 1.4);
    cairo_set_source_rgb(cr, 0.05, 0.2, 0.7);
    draw_threads(cr, w, t, true);
    st = paint_target(cr, t);
    cairo_destroy(cr);
    if (st == SPN_OK && cairo_surface_write_to_png(surf, f.tmp_path) != CAIRO_STATUS_SUCCESS)
        st = spn_error(SPN_ERR_IO, "%s: cannot write the PNG", path);
    cairo_surface_destroy(surf);
    if (st == SPN_OK) return spn_atomic_commit(&f);
    spn_atomic_abort(&f);
    return st;
}

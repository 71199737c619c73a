/* The target image of Mehla 2005, ch. 6: the message as ink on a raster that
 * shares its frame with the raster of the web (the "source image"), so a
 * capture segment and the message are compared pixel for pixel.
 *
 * The frame is the web's x-y bounding box plus a margin, square pixels. Text
 * and images are fitted into the capture area: the largest circle about the
 * capture threads' centre that stays inside them in every direction (so a
 * message is never set where there is no spiral to take out).
 * Invariant: ink values are in [0, 1]. */
#include "inscribe_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FRAME_MARGIN 0.04
#define AREA_SECTORS 72

spn_status spn_target_create(const spn_world *w, int size, spn_target **out)
{
    *out = NULL;
    if (size < 16 || size > 8192) return spn_error(SPN_ERR_INVALID, "target size %d: need 16..8192 pixels", size);
    uint32_t np = spn_world_particle_count(w);
    if (np == 0) return spn_error(SPN_ERR_INVALID, "inscribe: the web has no particles");
    const spn_vec3 *x = spn_world_positions(w);
    double lo[2] = {x[0].x, x[0].y}, hi[2] = {x[0].x, x[0].y};
    for (uint32_t i = 1; i < np; i++) {
        lo[0] = fmin(lo[0], x[i].x), hi[0] = fmax(hi[0], x[i].x);
        lo[1] = fmin(lo[1], x[i].y), hi[1] = fmax(hi[1], x[i].y);
    }
    double side = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(side > 0) || !isfinite(side)) return spn_error(SPN_ERR_INVALID, "inscribe: the web has no extent in x-y");
    side *= 1 + 2 * FRAME_MARGIN;
    spn_target *t = calloc(1, sizeof *t);
    if (!t) return spn_error(SPN_ERR_NOMEM, "out of memory");
    t->scale = size / side;
    t->width = (int)ceil((hi[0] - lo[0]) * (1 + 2 * FRAME_MARGIN) * t->scale);
    t->height = (int)ceil((hi[1] - lo[1]) * (1 + 2 * FRAME_MARGIN) * t->scale);
    t->width = t->width < 16 ? 16 : t->width > size ? size : t->width;
    t->height = t->height < 16 ? 16 : t->height > size ? size : t->height;
    t->x0 = 0.5 * (lo[0] + hi[0]) - 0.5 * t->width / t->scale;
    t->y0 = 0.5 * (lo[1] + hi[1]) + 0.5 * t->height / t->scale;
    t->ink = calloc((size_t)t->width * (size_t)t->height, sizeof *t->ink);
    if (!t->ink) {
        free(t);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    *out = t;
    return SPN_OK;
}

void spn_target_destroy(spn_target *t)
{
    if (!t) return;
    free(t->ink);
    free(t);
}

const float *spn_target_ink(const spn_target *t, int *width, int *height)
{
    if (width) *width = t->width;
    if (height) *height = t->height;
    return t->ink;
}

void spn_target_to_pixel(const spn_target *t, spn_vec3 p, double *px, double *py)
{
    *px = (p.x - t->x0) * t->scale;
    *py = (t->y0 - p.y) * t->scale;
}

double spn_target_scale(const spn_target *t) { return t->scale; }

double spn_target_ink_at(const spn_target *t, spn_vec3 p)
{
    double px, py;
    spn_target_to_pixel(t, p, &px, &py);
    if (!(px >= 0 && py >= 0 && px < t->width && py < t->height)) return 0;
    return t->ink[(size_t)py * (size_t)t->width + (size_t)px];
}

double spn_target_coverage(const spn_target *t)
{
    size_t n = (size_t)t->width * (size_t)t->height, on = 0;
    for (size_t i = 0; i < n; i++) on += t->ink[i] >= 0.5f;
    return (double)on / (double)n;
}

float *spn__raster_alloc(const spn_target *t)
{
    return calloc((size_t)t->width * (size_t)t->height, sizeof(float));
}

void spn_target_paint(spn_target *t, spn_ink_fn fn, void *user)
{
    for (int j = 0; j < t->height; j++)
        for (int i = 0; i < t->width; i++) {
            double v = fn(user, t->x0 + (i + 0.5) / t->scale, t->y0 - (j + 0.5) / t->scale);
            float *p = &t->ink[(size_t)j * (size_t)t->width + (size_t)i];
            v = v > 1 ? 1 : v;
            if (v > *p) *p = (float)v;
        }
}

spn_status spn_capture_area_of(const spn_world *w, spn_capture_area *out)
{
    memset(out, 0, sizeof *out);
    uint32_t ns = spn_world_spring_count(w), n = 0;
    spn_vec3 c = spn_v3(0, 0, 0);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || si.broken) continue;
        c = spn_v3_add(c, spn_v3_add(spn_world_position(w, si.a), spn_world_position(w, si.b)));
        n++;
    }
    if (n == 0) return spn_error(SPN_ERR_INVALID, "inscribe: the web has no capture-spiral threads (tag capture)");
    c = spn_v3_scale(c, 0.5 / n);
    double far[AREA_SECTORS], near[AREA_SECTORS];
    for (int k = 0; k < AREA_SECTORS; k++) far[k] = 0, near[k] = INFINITY;
    /* Points along every capture thread, binned by direction: each sector's
     * farthest point bounds the spiral there. */
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || si.broken) continue;
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        double reach = fmax(hypot(a.x - c.x, a.y - c.y), 1e-12);
        int samples = 2 + (int)(hypot(b.x - a.x, b.y - a.y) / (2 * SPN_PI * reach / AREA_SECTORS) * 3);
        samples = samples > 1000 ? 1000 : samples;
        for (int e = 0; e <= samples; e++) {
            spn_vec3 d = spn_v3_sub(spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), (double)e / samples)), c);
            double r = hypot(d.x, d.y), ang = atan2(d.y, d.x) + SPN_PI;
            int k = (int)(ang / (2 * SPN_PI) * AREA_SECTORS) % AREA_SECTORS;
            far[k] = fmax(far[k], r);
            near[k] = fmin(near[k], r);
        }
    }
    double radius = INFINITY, inner = 0;
    for (int k = 0; k < AREA_SECTORS; k++) {
        if (far[k] > 0) radius = fmin(radius, far[k]);
        if (isfinite(near[k])) inner = fmax(inner, near[k]);
    }
    out->centre = c;
    out->radius = radius;
    out->inner = inner < radius ? inner : 0;
    out->segments = n;
    return SPN_OK;
}

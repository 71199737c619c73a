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

/* Capture radius and free-zone radius about `c`: each of AREA_SECTORS
 * directions is bounded by the farthest capture point in it. */
static double area_about(const spn_vec3 *pt, size_t n, spn_vec3 c, double *inner)
{
    double far[AREA_SECTORS], near[AREA_SECTORS];
    for (int k = 0; k < AREA_SECTORS; k++) far[k] = 0, near[k] = INFINITY;
    for (size_t i = 0; i < n; i++) {
        double dx = pt[i].x - c.x, dy = pt[i].y - c.y, r = hypot(dx, dy);
        int k = (int)((atan2(dy, dx) + SPN_PI) / (2 * SPN_PI) * AREA_SECTORS) % AREA_SECTORS;
        far[k] = fmax(far[k], r);
        near[k] = fmin(near[k], r);
    }
    double radius = INFINITY, in = 0;
    for (int k = 0; k < AREA_SECTORS; k++) {
        radius = fmin(radius, far[k]); /* an empty direction has no spiral: radius 0 */
        if (isfinite(near[k])) in = fmax(in, near[k]);
    }
    *inner = in < radius ? in : 0;
    return radius;
}

/* Points every `step` metres along every capture thread (NULL on no memory). */
static spn_vec3 *capture_points(const spn_world *w, double step, size_t *count)
{
    uint32_t ns = spn_world_spring_count(w);
    size_t n = 0, cap = 1024;
    spn_vec3 *pt = malloc(cap * sizeof *pt);
    for (uint32_t s = 0; s < ns && pt; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || si.broken) continue;
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        int m = 1 + (int)fmin(1000, hypot(b.x - a.x, b.y - a.y) / step);
        for (int e = 0; e <= m && pt; e++) {
            if (n == cap) {
                spn_vec3 *grown = realloc(pt, 2 * cap * sizeof *pt);
                if (!grown) free(pt);
                pt = grown, cap *= 2;
                if (!pt) break;
            }
            pt[n++] = spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), (double)e / m));
        }
    }
    *count = n;
    return pt;
}

spn_status spn_capture_area_of(const spn_world *w, spn_capture_area *out)
{
    memset(out, 0, sizeof *out);
    uint32_t ns = spn_world_spring_count(w), n = 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || si.broken) continue;
        for (int e = 0; e < 2; e++) {
            spn_vec3 p = spn_world_position(w, e ? si.b : si.a);
            lo[0] = fmin(lo[0], p.x), hi[0] = fmax(hi[0], p.x), lo[1] = fmin(lo[1], p.y), hi[1] = fmax(hi[1], p.y);
        }
        n++;
    }
    if (n == 0) return spn_error(SPN_ERR_INVALID, "inscribe: the web has no capture-spiral threads (tag capture)");
    double size = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    size_t np;
    spn_vec3 *pt = capture_points(w, size / 500, &np);
    if (!pt) return spn_error(SPN_ERR_NOMEM, "out of memory");
    /* The centre with the largest circle inside the spiral: a coarse grid over
     * the middle of the capture box, then a finer one about the best point. */
    spn_vec3 best = spn_v3(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0);
    double inner, best_r = area_about(pt, np, best, &inner), half = 0.25 * size;
    for (int pass = 0; pass < 3; pass++, half /= 4) {
        spn_vec3 around = best;
        for (int j = -4; j <= 4; j++)
            for (int i = -4; i <= 4; i++) {
                spn_vec3 c = spn_v3(around.x + half * i / 4, around.y + half * j / 4, 0);
                double in, r = area_about(pt, np, c, &in);
                if (r > best_r) best_r = r, best = c;
            }
    }
    out->centre = best;
    out->radius = area_about(pt, np, best, &inner);
    out->inner = inner;
    out->segments = n;
    free(pt);
    if (!(out->radius > 0)) return spn_error(SPN_ERR_INVALID, "inscribe: the capture spiral encloses no area");
    return SPN_OK;
}

/* Largest s such that the box of half-size (aw s, ah s) centred at c lies in
 * the spiral: in each direction the box's edge must stay inside the farthest
 * capture point of that direction (checked at both edges of every sector). */
static double box_scale_about(const spn_vec3 *pt, size_t n, spn_vec3 c, double aw, double ah)
{
    double far[AREA_SECTORS];
    for (int k = 0; k < AREA_SECTORS; k++) far[k] = 0;
    for (size_t i = 0; i < n; i++) {
        double dx = pt[i].x - c.x, dy = pt[i].y - c.y;
        int k = (int)((atan2(dy, dx) + SPN_PI) / (2 * SPN_PI) * AREA_SECTORS) % AREA_SECTORS;
        far[k] = fmax(far[k], hypot(dx, dy));
    }
    double s = INFINITY;
    for (int k = 0; k < AREA_SECTORS; k++)
        for (int e = 0; e < 2; e++) {
            double ang = (k + e) * 2 * SPN_PI / AREA_SECTORS - SPN_PI;
            double cx = fabs(cos(ang)), cy = fabs(sin(ang));
            double edge = fmin(cx > 1e-12 ? aw / cx : INFINITY, cy > 1e-12 ? ah / cy : INFINITY);
            s = fmin(s, far[k] / edge);
        }
    return s;
}

spn_status spn__fit_box(const spn_world *w, double aw, double ah, spn_vec3 *centre, double *scale)
{
    spn_capture_area area;
    spn_status st = spn_capture_area_of(w, &area);
    if (st != SPN_OK) return st;
    size_t np;
    spn_vec3 *pt = capture_points(w, area.radius / 250, &np);
    if (!pt) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_vec3 best = area.centre;
    double best_s = box_scale_about(pt, np, best, aw, ah), half = 0.5 * area.radius;
    for (int pass = 0; pass < 3; pass++, half /= 4) {
        spn_vec3 around = best;
        for (int j = -4; j <= 4; j++)
            for (int i = -4; i <= 4; i++) {
                spn_vec3 c = spn_v3(around.x + half * i / 4, around.y + half * j / 4, 0);
                double sc = box_scale_about(pt, np, c, aw, ah);
                if (sc > best_s) best_s = sc, best = c;
            }
    }
    free(pt);
    *centre = best;
    *scale = best_s;
    return SPN_OK;
}

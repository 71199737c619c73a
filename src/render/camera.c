/* The camera: world points to canvas pixels.
 *
 * Front: orthographic, looking along -z with y up, scaled uniformly so the
 * web's bounding box (or the camera's fixed bounds, for animations) fills the
 * canvas less a margin on every side, and centred. Perspective: a pinhole at
 * `eye` looking at `target`, vertical field of view `fov_degrees`, square
 * pixels. Pixel (0, 0) is the top-left corner of the canvas.
 * Invariant: a finite world gives finite pixel coordinates; a degenerate box
 * (one point, a vertical line) still gets a finite scale. */
#include "render_internal.h"

#include <math.h>

static void grow(spn_vec3 p, bool *any, spn_vec3 *lo, spn_vec3 *hi)
{
    if (!*any) *lo = *hi = p;
    *any = true;
    lo->x = fmin(lo->x, p.x), lo->y = fmin(lo->y, p.y), lo->z = fmin(lo->z, p.z);
    hi->x = fmax(hi->x, p.x), hi->y = fmax(hi->y, p.y), hi->z = fmax(hi->z, p.z);
}

bool spn__world_bounds(const spn_world *w, spn_vec3 *lo, spn_vec3 *hi)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    const spn_vec3 *x = spn_world_positions(w);
    bool any = false;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info info = spn_world_spring(w, s);
        if (info.broken) continue;
        grow(x[info.a], &any, lo, hi);
        grow(x[info.b], &any, lo, hi);
    }
    for (uint32_t p = 0; p < np && ns == 0; p++) grow(x[p], &any, lo, hi);
    return any;
}

static spn_status setup_front(const spn_world *w, const spn_render_def *def, spn__view *v)
{
    spn_vec3 lo = spn_v3(-1, -1, 0), hi = spn_v3(1, 1, 0);
    if (def->camera.fixed_bounds) {
        lo = def->camera.bounds_min;
        hi = def->camera.bounds_max;
    } else {
        spn__world_bounds(w, &lo, &hi);
    }
    double bw = hi.x - lo.x, bh = hi.y - lo.y;
    double extent = fmax(fmax(bw, bh), 1e-9);
    if (bw < 1e-6 * extent) bw = 1e-6 * extent;
    if (bh < 1e-6 * extent) bh = 1e-6 * extent;
    double m = def->camera.margin;
    double uw = v->width * (1 - 2 * m), uh = v->height * (1 - 2 * m);
    v->scale = fmin(uw / bw, uh / bh);
    if (!isfinite(v->scale) || !(v->scale > 0))
        return spn_error(SPN_ERR_INVALID, "camera: cannot frame the web (bounds %g x %g m)", bw, bh);
    v->ox = 0.5 * v->width - v->scale * 0.5 * (lo.x + hi.x);
    v->oy = 0.5 * v->height + v->scale * 0.5 * (lo.y + hi.y);
    return SPN_OK;
}

static spn_status setup_perspective(const spn_render_def *def, spn__view *v)
{
    const spn_camera *c = &def->camera;
    v->eye = c->eye;
    v->forward = spn_v3_norm(spn_v3_sub(c->target, c->eye));
    spn_vec3 up = spn_v3_len(c->up) > 0 ? c->up : spn_v3(0, 1, 0);
    v->right = spn_v3_norm(spn_v3_cross(v->forward, up));
    if (spn_v3_len(v->forward) == 0 || spn_v3_len(v->right) == 0)
        return spn_error(SPN_ERR_INVALID, "camera: eye and target must differ and not look along 'up'");
    v->up = spn_v3_cross(v->right, v->forward);
    v->focal = 0.5 * v->height / tan(0.5 * c->fov_degrees * SPN_PI / 180);
    return SPN_OK;
}

spn_status spn__view_setup(const spn_world *w, const spn_render_def *def, spn__view *view)
{
    spn__view v = {0};
    v.kind = def->camera.kind;
    v.width = def->width;
    v.height = def->height;
    v.px_per_ref = fmin(def->width, def->height) / 1200.0;
    spn_status st = v.kind == SPN_CAMERA_PERSPECTIVE ? setup_perspective(def, &v) : setup_front(w, def, &v);
    if (st == SPN_OK) *view = v;
    return st;
}

bool spn__view_project(const spn__view *v, spn_vec3 p, double *x, double *y, double *depth)
{
    if (v->kind != SPN_CAMERA_PERSPECTIVE) {
        *x = v->ox + v->scale * p.x;
        *y = v->oy - v->scale * p.y;
        if (depth) *depth = 1;
        return true;
    }
    spn_vec3 d = spn_v3_sub(p, v->eye);
    double z = spn_v3_dot(d, v->forward);
    if (depth) *depth = z;
    if (!(z > 1e-9)) return false;
    *x = 0.5 * v->width + v->focal * spn_v3_dot(d, v->right) / z;
    *y = 0.5 * v->height - v->focal * spn_v3_dot(d, v->up) / z;
    return true;
}

spn_camera spn_camera_orbit(const spn_world *w, double yaw_degrees, double pitch_degrees, double fov_degrees)
{
    spn_camera c = spn_render_def_default().camera;
    spn_vec3 lo = spn_v3(-1, -1, 0), hi = spn_v3(1, 1, 0);
    spn__world_bounds(w, &lo, &hi);
    double radius = fmax(0.5 * spn_v3_len(spn_v3_sub(hi, lo)), 1e-9);
    double fov = fov_degrees > 0 && fov_degrees < 180 ? fov_degrees : 40;
    double dist = 1.05 * radius / sin(0.5 * fov * SPN_PI / 180);
    double yaw = yaw_degrees * SPN_PI / 180, pitch = pitch_degrees * SPN_PI / 180;
    c.kind = SPN_CAMERA_PERSPECTIVE;
    c.fov_degrees = fov;
    c.target = spn_v3_scale(spn_v3_add(lo, hi), 0.5);
    c.eye = spn_v3_add(c.target, spn_v3(dist * cos(pitch) * sin(yaw), dist * sin(pitch), dist * cos(pitch) * cos(yaw)));
    return c;
}

/* POV-Ray 3.7 scene export: a complete scene that `povray +W800 +H800 F.pov`
 * renders without edits. Juhasz & Bercovici's POV film maker writes one POV
 * scene per frame for the renderer to turn into a film; spn_export_pov_frame
 * does the same for Spinneret's animations.
 *
 * POV-Ray is left-handed with y up; our world is right-handed with y up and
 * the front camera on +z, so points are written as (x, y, -z): the picture
 * is the same as the cairo front view. Threads are cylinder chains with a
 * sphere at each joint, merged per kind under one silk texture (merge, so a
 * translucent thread does not show its inner joints); dew drops are water
 * spheres (ior 1.33, Fresnel reflection). Thread radii follow the line widths
 * the renderer would draw at render.width x render.height, so the scene looks
 * like the PNG. Threads and drops cast no shadow on the backdrop, which is
 * scenery far behind the web, as in Mehla's backgrounds (sec. 5.3.7). */
#include "export_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct pov_view {
    spn_vec3 centre;       /* what the camera looks at (world) */
    double view_h;         /* visible height at the web [m] */
    double px;             /* size of one pixel at the web [m] */
    double depth;          /* extent of the web along z [m] */
} pov_view;

static spn_status sink_char(spn_sink *s, char c) { return s->write(s->ctx, &c, 1); }

static spn_vec3 pov(spn_vec3 p) { return spn_v3(p.x, p.y, 0.0 - p.z); } /* 0.0 - z: never "-0" */

static spn_status vec(spn_sink *s, spn_vec3 p)
{
    p = pov(p);
    return spn_sink_printf(s, "<%.9g, %.9g, %.9g>", p.x, p.y, p.z);
}

static void frame_view(const spn__xscene *x, const spn_render_def *d, pov_view *v)
{
    spn_vec3 lo = x->any ? x->lo : spn_v3(-1, -1, 0), hi = x->any ? x->hi : spn_v3(1, 1, 0);
    if (d->camera.fixed_bounds) lo = d->camera.bounds_min, hi = d->camera.bounds_max;
    double bw = fmax(hi.x - lo.x, 1e-9), bh = fmax(hi.y - lo.y, 1e-9);
    double m = d->camera.margin, scale = fmin(d->width * (1 - 2 * m) / bw, d->height * (1 - 2 * m) / bh);
    v->centre = spn_v3_scale(spn_v3_add(lo, hi), 0.5);
    v->view_h = d->height / scale;
    v->px = 1 / scale;
    v->depth = hi.z - lo.z;
    if (d->camera.kind == SPN_CAMERA_PERSPECTIVE) {
        double dist = spn_v3_len(spn_v3_sub(d->camera.target, d->camera.eye));
        v->centre = d->camera.target;
        v->view_h = 2 * dist * tan(0.5 * d->camera.fov_degrees * SPN_PI / 180);
        v->px = v->view_h / d->height;
    }
}

static spn_status camera_and_lights(spn_sink *s, const spn_render_def *d, const pov_view *v)
{
    spn_status st;
    double reach = 2 * v->view_h + v->depth;
    spn_vec3 c = v->centre;
    if (d->camera.kind == SPN_CAMERA_PERSPECTIVE) {
        const spn_camera *cam = &d->camera;
        st = spn_sink_printf(s, "camera {\n  perspective\n  location ");
        if (st == SPN_OK) st = vec(s, cam->eye);
        if (st == SPN_OK) st = spn_sink_printf(s, "\n  sky ");
        if (st == SPN_OK) st = vec(s, spn_v3_len(cam->up) > 0 ? cam->up : spn_v3(0, 1, 0));
        if (st == SPN_OK)
            st = spn_sink_printf(s,
                                 "\n  right x * image_width / image_height\n"
                                 "  angle degrees(2 * atan(tan(radians(%.9g / 2)) * image_width / image_height))\n"
                                 "  look_at ",
                                 cam->fov_degrees);
        if (st == SPN_OK) st = vec(s, cam->target);
    } else {
        st = spn_sink_printf(s, "camera {\n  orthographic\n  location ");
        if (st == SPN_OK) st = vec(s, spn_v3(c.x, c.y, c.z + reach));
        if (st == SPN_OK)
            st = spn_sink_printf(s, "\n  up y * %.9g\n  right x * %.9g * image_width / image_height\n  look_at ",
                                 v->view_h, v->view_h);
        if (st == SPN_OK) st = vec(s, c);
    }
    if (st == SPN_OK) st = spn_sink_printf(s, "\n}\n\n// A low sun from the upper left, a soft fill from the right.\nlight_source { ");
    if (st == SPN_OK) st = vec(s, spn_v3(c.x - 3 * reach, c.y + 4 * reach, c.z + 5 * reach));
    if (st == SPN_OK) st = spn_sink_printf(s, " color rgb 1.3 parallel point_at ");
    if (st == SPN_OK) st = vec(s, c);
    if (st == SPN_OK) st = spn_sink_printf(s, " }\nlight_source { ");
    if (st == SPN_OK) st = vec(s, spn_v3(c.x + 4 * reach, c.y + reach, c.z + 3 * reach));
    if (st == SPN_OK) st = spn_sink_printf(s, " color rgb 0.35 shadowless }\n\n");
    return st;
}

/* PNG size from its IHDR chunk, for cover scaling of the backdrop. */
static spn_status png_size(const char *path, double *w, double *h)
{
    unsigned char head[24];
    FILE *fp = fopen(path, "rb");
    size_t n = fp ? fread(head, 1, sizeof head, fp) : 0;
    if (fp) fclose(fp);
    if (!fp) return spn_error(SPN_ERR_IO, "%s: cannot read background", path);
    if (n < 24 || memcmp(head, "\x89PNG", 4) != 0 || memcmp(head + 12, "IHDR", 4) != 0)
        return spn_error(SPN_ERR_FORMAT, "%s: cannot read background: not a PNG file", path);
    *w = (double)((uint32_t)head[16] << 24 | (uint32_t)head[17] << 16 | (uint32_t)head[18] << 8 | head[19]);
    *h = (double)((uint32_t)head[20] << 24 | (uint32_t)head[21] << 16 | (uint32_t)head[22] << 8 | head[23]);
    if (!(*w > 0 && *h > 0)) return spn_error(SPN_ERR_FORMAT, "%s: cannot read background: empty image", path);
    return SPN_OK;
}

static spn_status pov_string(spn_sink *s, const char *text)
{
    spn_status st = sink_char(s, '"');
    for (const char *p = text; *p && st == SPN_OK; p++) {
        if (*p == '"' || *p == '\\') st = sink_char(s, '\\');
        if (st == SPN_OK) st = sink_char(s, *p);
    }
    return st == SPN_OK ? sink_char(s, '"') : st;
}

/* Camera basis in the world: right, up, forward (into the scene). */
static void basis(const spn_render_def *d, spn_vec3 *r, spn_vec3 *u, spn_vec3 *f)
{
    *r = spn_v3(1, 0, 0), *u = spn_v3(0, 1, 0), *f = spn_v3(0, 0, -1);
    if (d->camera.kind != SPN_CAMERA_PERSPECTIVE) return;
    spn_vec3 up = spn_v3_len(d->camera.up) > 0 ? d->camera.up : spn_v3(0, 1, 0);
    *f = spn_v3_norm(spn_v3_sub(d->camera.target, d->camera.eye));
    *r = spn_v3_norm(spn_v3_cross(*f, up));
    *u = spn_v3_cross(*r, *f);
}

/* The background image on a square behind the web, facing the camera, scaled
 * to cover the view (POV works out the image aspect at render time) and lit
 * by itself (emission 1), like the backdrop of sec. 5.3.7. */
static spn_status backdrop(spn_sink *s, const spn_render_def *d, const pov_view *v)
{
    double iw = 1, ih = 1;
    spn_status st = png_size(d->background_png, &iw, &ih);
    if (st != SPN_OK) return st;
    spn_vec3 r, u, f;
    basis(d, &r, &u, &f);
    double behind = v->depth + v->view_h, view_h = v->view_h;
    spn_vec3 at = spn_v3_add(v->centre, spn_v3_scale(f, behind));
    if (d->camera.kind == SPN_CAMERA_PERSPECTIVE) {
        double dist = spn_v3_len(spn_v3_sub(d->camera.target, d->camera.eye)) + behind;
        view_h = 2 * dist * tan(0.5 * d->camera.fov_degrees * SPN_PI / 180);
    }
    /* What refracting drops and glinting silk see: a sky like the backdrop's
     * (the camera itself only sees the backdrop). */
    st = spn_sink_printf(s, "sky_sphere { pigment { gradient y color_map { [0 srgb <0.75, 0.65, 0.5>] "
                            "[0.5 srgb <0.45, 0.52, 0.6>] [1 srgb <0.12, 0.16, 0.26>] } scale 2 translate -y } }\n");
    if (st == SPN_OK)
        st = spn_sink_printf(s,
                         "// Backdrop: the image covers the view and is cropped, never stretched.\n"
                         "#declare Back_View_H = %.9g;\n#declare Back_View_W = Back_View_H * image_width / image_height;\n"
                         "#declare Back_Aspect = %.9g;\n"
                         "#declare Back_H = max(Back_View_H, Back_View_W / Back_Aspect);\n"
                         "#declare Back_W = Back_H * Back_Aspect;\n"
                         "polygon {\n  5, <0, 0>, <1, 0>, <1, 1>, <0, 1>, <0, 0>\n"
                         "  texture {\n    pigment { image_map { png ",
                         view_h * 1.02, iw / ih);
    if (st == SPN_OK) st = pov_string(s, d->background_png);
    if (st == SPN_OK)
        st = spn_sink_printf(s, " once interpolate 2 } }\n    finish { ambient 0 diffuse 0 emission 1 }\n  }\n"
                                "  translate <-0.5, -0.5, 0>\n  scale <Back_W, Back_H, 1>\n  matrix <");
    spn_vec3 pr = pov(r), pu = pov(u), pf = pov(f), pa = pov(at);
    if (st == SPN_OK)
        st = spn_sink_printf(s, "%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g>\n}\n\n", pr.x,
                             pr.y, pr.z, pu.x, pu.y, pu.z, pf.x, pf.y, pf.z, pa.x, pa.y, pa.z);
    return st;
}

static double thread_radius(const spn_export_def *def, const spn__xstrand *t, const pov_view *v)
{
    if (def->pov_thread_radius > 0) return def->pov_thread_radius;
    double px_per_ref = fmin(def->render.width, def->render.height) / 1200.0;
    return 0.5 * t->width * px_per_ref * v->px;
}

/* The cylinders and joint spheres of one strand into `out`; counts objects. */
static spn_status strand_objects(spn_sink *out, const spn__xscene *x, const spn__xstrand *t, double r, int *objects)
{
    spn_status st = SPN_OK;
    uint32_t segs = t->closed ? t->count : t->count - 1;
    const spn_vec3 *p = x->points + t->first;
    for (uint32_t i = 0; i < segs && st == SPN_OK; i++) {
        spn_vec3 a = p[i], b = p[(i + 1) % t->count];
        if (spn_v3_len(spn_v3_sub(a, b)) < 1e-6 * r) continue; /* POV refuses degenerate cylinders */
        st = spn_sink_printf(out, "  cylinder { ");
        if (st == SPN_OK) st = vec(out, a);
        if (st == SPN_OK) st = spn_sink_printf(out, ", ");
        if (st == SPN_OK) st = vec(out, b);
        if (st == SPN_OK) st = spn_sink_printf(out, ", %.9g }\n", r);
        (*objects)++;
        bool joint = t->closed || i + 1 < segs;
        if (!joint || st != SPN_OK) continue;
        st = spn_sink_printf(out, "  sphere { ");
        if (st == SPN_OK) st = vec(out, b);
        if (st == SPN_OK) st = spn_sink_printf(out, ", %.9g }\n", r);
        (*objects)++;
    }
    return st;
}

/* One group of objects under one texture or material; a lone object is
 * wrapped in `object`, since POV warns about one-object CSG. */
static spn_status group(spn_sink *s, const spn_buffer *body, int objects, bool merge, const char *look)
{
    if (objects == 0) return SPN_OK;
    spn_status st = spn_sink_printf(s, "%s {\n", objects == 1 ? "object" : merge ? "merge" : "union");
    if (st == SPN_OK) st = s->write(s->ctx, body->data, body->size);
    if (st == SPN_OK) st = spn_sink_printf(s, "  %s\n  no_shadow\n}\n\n", look);
    return st;
}

static spn_status silk_texture(spn_sink *s, const char *name, const spn__xstrand *t)
{
    return spn_sink_printf(s,
                           "#declare Silk_%s = texture {\n  pigment { srgbt <%.4f, %.4f, %.4f, %.4f> }\n"
                           "  finish { ambient 0 emission 0.35 diffuse 0.65 specular 0.6 roughness 0.01 }\n}\n",
                           name, t->rgb[0], t->rgb[1], t->rgb[2], 1 - t->alpha);
}

/* Every kind's strands under one texture: strands of a kind are contiguous. */
static spn_status threads(spn_sink *s, const spn_export_def *def, const spn__xscene *x, const pov_view *v)
{
    spn_status st = SPN_OK;
    for (size_t i = 0; i < x->strand_count && st == SPN_OK;) {
        size_t j = i;
        char name[48], look[80];
        spn__kind_label(x->strands[i].kind, name, sizeof name);
        snprintf(look, sizeof look, "texture { Silk_%s }", name);
        spn_buffer body = {0};
        spn_sink bs = spn_sink_buffer(&body);
        int objects = 0;
        for (; j < x->strand_count && x->strands[j].kind == x->strands[i].kind && st == SPN_OK; j++)
            st = strand_objects(&bs, x, &x->strands[j], thread_radius(def, &x->strands[j], v), &objects);
        if (st == SPN_OK) st = spn_sink_printf(s, "// %s: %zu strands\n", name, j - i);
        if (st == SPN_OK) st = silk_texture(s, name, &x->strands[i]);
        if (st == SPN_OK) st = group(s, &body, objects, x->strands[i].alpha < 1, look);
        spn_buffer_free(&body);
        i = j;
    }
    return st;
}

static spn_status dew(spn_sink *s, const spn__xscene *x)
{
    if (x->bead_count == 0) return SPN_OK;
    spn_status st = spn_sink_printf(s,
                                    "// Dew: %zu water drops.\n#declare Dew_Water = material {\n"
                                    "  texture {\n    pigment { rgbf <0.98, 0.99, 1, 0.97> }\n"
                                    "    finish { ambient 0 diffuse 0.02 specular 0.9 roughness 0.0015\n"
                                    "             reflection { 0.02, 1 fresnel on } conserve_energy }\n  }\n"
                                    "  interior { ior 1.33 }\n}\n",
                                    x->bead_count);
    spn_buffer body = {0};
    spn_sink bs = spn_sink_buffer(&body);
    for (size_t i = 0; i < x->bead_count && st == SPN_OK; i++) {
        st = spn_sink_printf(&bs, "  sphere { ");
        if (st == SPN_OK) st = vec(&bs, x->beads[i].centre);
        if (st == SPN_OK) st = spn_sink_printf(&bs, ", %.9g }\n", x->beads[i].radius);
    }
    if (st == SPN_OK) st = group(s, &body, (int)x->bead_count, false, "material { Dew_Water }");
    spn_buffer_free(&body);
    return st;
}

static spn_status header(spn_sink *s, const spn_world *w, const spn_render_def *d)
{
    return spn_sink_printf(s,
                           "// Spinneret web: %u particles, %u springs. POV-Ray 3.7 scene.\n"
                           "// Render: povray +W%d +H%d +A0.1 +FN THIS.pov\n"
                           "#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 16 }\n"
                           "background { srgb <%.4f, %.4f, %.4f> }\n\n",
                           spn_world_particle_count(w), spn_world_spring_count(w), d->width, d->height,
                           d->background_rgb[0], d->background_rgb[1], d->background_rgb[2]);
}

spn_status spn_export_pov(const spn_world *w, const spn_export_def *def, spn_sink *sink)
{
    spn_status st = spn__export_check(def);
    spn__xscene x;
    if (st == SPN_OK) st = spn__xscene_collect(w, &def->render, &x);
    if (st != SPN_OK) return st;
    pov_view v;
    frame_view(&x, &def->render, &v);
    st = header(sink, w, &def->render);
    if (st == SPN_OK) st = camera_and_lights(sink, &def->render, &v);
    if (st == SPN_OK && def->render.background_png) st = backdrop(sink, &def->render, &v);
    if (st == SPN_OK) st = threads(sink, def, &x, &v);
    if (st == SPN_OK) st = dew(sink, &x);
    spn__xscene_free(&x);
    return st;
}

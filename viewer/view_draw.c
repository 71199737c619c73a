/* Drawing the live world with OpenGL 1.x vertex arrays (they run everywhere,
 * Mesa's software rasteriser included, which is what the tests use under
 * Xvfb). The camera orbits the web's centre; picking uses the same matrices,
 * computed here in double precision. Text (the readout and the key overlay)
 * is laid out by cairo into a texture. */
#include "view_internal.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void mat_identity(double *m)
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1;
}

static void mat_mul(const double *a, const double *b, double *out)
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0;
            for (int k = 0; k < 4; k++) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(out, r, sizeof r);
}

static spn_vec3 camera_eye(const view_state *v)
{
    spn_vec3 dir = spn_v3(cos(v->pitch) * sin(v->yaw), sin(v->pitch), cos(v->pitch) * cos(v->yaw));
    return spn_v3_add(v->centre, spn_v3_scale(dir, v->distance));
}

static void camera_matrices(const view_state *v, double *proj, double *view)
{
    double aspect = v->fb_h > 0 ? (double)v->fb_w / v->fb_h : 1;
    double f = 1.0 / tan(v->fov * SPN_PI / 360.0), n = v->distance * 0.01, fa = v->distance * 100;
    mat_identity(proj);
    proj[0] = f / aspect;
    proj[5] = f;
    proj[10] = (fa + n) / (n - fa);
    proj[11] = -1;
    proj[14] = 2 * fa * n / (n - fa);
    proj[15] = 0;
    spn_vec3 eye = camera_eye(v);
    spn_vec3 fw = spn_v3_norm(spn_v3_sub(v->centre, eye));
    spn_vec3 side = spn_v3_norm(spn_v3_cross(fw, spn_v3(0, 1, 0)));
    if (spn_v3_len(side) == 0) side = spn_v3(1, 0, 0);
    spn_vec3 up = spn_v3_cross(side, fw);
    mat_identity(view);
    view[0] = side.x, view[4] = side.y, view[8] = side.z;
    view[1] = up.x, view[5] = up.y, view[9] = up.z;
    view[2] = -fw.x, view[6] = -fw.y, view[10] = -fw.z;
    view[12] = -spn_v3_dot(side, eye);
    view[13] = -spn_v3_dot(up, eye);
    view[14] = spn_v3_dot(fw, eye);
}

void view_frame_camera(view_state *v)
{
    uint32_t n = v->world ? spn_world_particle_count(v->world) : 0;
    spn_vec3 lo = spn_v3(-0.3, -0.3, 0), hi = spn_v3(0.3, 0.3, 0); /* build mode: a canvas of 0.6 m */
    if (n > 0) {
        const spn_vec3 *x = spn_world_positions(v->world);
        lo = hi = x[0];
        for (uint32_t i = 1; i < n; i++) {
            lo = spn_v3(fmin(lo.x, x[i].x), fmin(lo.y, x[i].y), fmin(lo.z, x[i].z));
            hi = spn_v3(fmax(hi.x, x[i].x), fmax(hi.y, x[i].y), fmax(hi.z, x[i].z));
        }
    }
    v->centre = spn_v3_scale(spn_v3_add(lo, hi), 0.5);
    double radius = 0.5 * spn_v3_len(spn_v3_sub(hi, lo));
    if (!(radius > 0)) radius = 0.1;
    v->distance = radius / tan(v->fov * SPN_PI / 360.0) * 1.15;
}

bool view_project(const view_state *v, spn_vec3 p, double *sx, double *sy)
{
    const double *m = v->mvp;
    double cx = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
    double cy = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
    double cw = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    if (cw <= 0) return false;
    int ww, wh;
    glfwGetWindowSize(v->win, &ww, &wh);
    *sx = (cx / cw * 0.5 + 0.5) * ww;
    *sy = (0.5 - cy / cw * 0.5) * wh;
    return true;
}

spn_vec3 view_unproject(const view_state *v, double x, double y, spn_vec3 on)
{
    /* Walk along the camera plane: the screen offset from `on`'s projection,
     * scaled by the size of one pixel at `on`'s depth. */
    double sx, sy;
    if (!view_project(v, on, &sx, &sy)) return on;
    spn_vec3 eye = camera_eye(v);
    spn_vec3 fw = spn_v3_norm(spn_v3_sub(v->centre, eye));
    spn_vec3 side = spn_v3_norm(spn_v3_cross(fw, spn_v3(0, 1, 0)));
    spn_vec3 up = spn_v3_cross(side, fw);
    int ww, wh;
    glfwGetWindowSize(v->win, &ww, &wh);
    double depth = spn_v3_dot(spn_v3_sub(on, eye), fw);
    double px = 2 * depth * tan(v->fov * SPN_PI / 360.0) / (wh > 0 ? wh : 1);
    return spn_v3_add(on, spn_v3_add(spn_v3_scale(side, (x - sx) * px), spn_v3_scale(up, -(y - sy) * px)));
}

/* Grey shade per thread kind: structural threads brighter than the spiral. */
static void kind_colour(uint32_t tag, float *c)
{
    float g = 0.75f;
    switch (tag) {
    case SPN_THREAD_ANCHOR: case SPN_THREAD_FRAME: case SPN_THREAD_BRIDGE: g = 0.95f; break;
    case SPN_THREAD_RADIUS: g = 0.88f; break;
    case SPN_THREAD_CAPTURE: case SPN_THREAD_AUX_SPIRAL: g = 0.72f; break;
    case SPN_THREAD_INSCRIPTION: case SPN_THREAD_STABILIMENTUM: g = 1.0f; break;
    default: break;
    }
    c[0] = c[1] = c[2] = g;
    c[3] = 0.9f;
}

/* Blue (little elastic energy) to red (the most), on a log scale. */
static void energy_colour(double e, double emax, float *c)
{
    double t = (e > 0 && emax > 0) ? 1 + log10(e / emax) / 6 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    c[0] = (float)t;
    c[1] = (float)(0.2 + 0.6 * (1 - fabs(2 * t - 1)));
    c[2] = (float)(1 - t);
    c[3] = 1;
}

static void draw_edges(view_state *v)
{
    uint32_t ns = spn_world_spring_count(v->world);
    if (ns == 0) return;
    const spn_vec3 *x = spn_world_positions(v->world);
    double *pos = malloc((size_t)ns * 6 * sizeof *pos);
    float *col = malloc((size_t)ns * 8 * sizeof *col);
    if (!pos || !col) goto done;
    double emax = 0;
    if (v->show_energy)
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(v->world, s);
            emax = fmax(emax, 0.5 * si.tension * si.tension / (si.k > 0 ? si.k : 1));
        }
    uint32_t n = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(v->world, s);
        if (si.broken) continue;
        float c[4];
        if (v->show_energy) energy_colour(0.5 * si.tension * si.tension / (si.k > 0 ? si.k : 1), emax, c);
        else kind_colour(si.tag, c);
        memcpy(pos + 6 * n, &x[si.a], 3 * sizeof *pos);
        memcpy(pos + 6 * n + 3, &x[si.b], 3 * sizeof *pos);
        memcpy(col + 8 * n, c, sizeof c);
        memcpy(col + 8 * n + 4, c, sizeof c);
        n++;
    }
    glLineWidth(v->show_energy ? 2.0f : 1.2f);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_DOUBLE, 0, pos);
    glColorPointer(4, GL_FLOAT, 0, col);
    glDrawArrays(GL_LINES, 0, (GLsizei)(2 * n));
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
done:
    free(pos);
    free(col);
}

static void draw_vertices(view_state *v)
{
    uint32_t np = spn_world_particle_count(v->world);
    glPointSize(4);
    glBegin(GL_POINTS);
    for (uint32_t i = 0; i < np; i++) {
        if (spn_world_is_fixed(v->world, i)) glColor3f(1.0f, 0.55f, 0.2f);
        else glColor3f(0.4f, 0.8f, 1.0f);
        spn_vec3 p = spn_world_position(v->world, i);
        glVertex3d(p.x, p.y, p.z);
    }
    glEnd();
}

static void draw_faces(view_state *v)
{
    if (!v->tris) return;
    const spn_vec3 *x = spn_world_positions(v->world);
    glEnable(GL_DEPTH_TEST);
    glBegin(GL_TRIANGLES);
    for (uint32_t t = 0; t < v->ntris; t++) {
        spn_vec3 a = x[v->tris[3 * t]], b = x[v->tris[3 * t + 1]], c = x[v->tris[3 * t + 2]];
        spn_vec3 n = spn_v3_norm(spn_v3_cross(spn_v3_sub(b, a), spn_v3_sub(c, a)));
        float shade = (float)(0.35 + 0.55 * fabs(spn_v3_dot(n, spn_v3_norm(spn_v3(0.3, 0.8, 0.5)))));
        glColor4f(0.55f * shade, 0.7f * shade, 0.9f * shade, 1.0f);
        glVertex3d(a.x, a.y, a.z);
        glVertex3d(b.x, b.y, b.z);
        glVertex3d(c.x, c.y, c.z);
    }
    glEnd();
    glDisable(GL_DEPTH_TEST);
}

/* Beads along the capture spiral: a droplet at a hashed spot of each segment. */
static void draw_dew(view_state *v)
{
    uint32_t ns = spn_world_spring_count(v->world);
    const spn_vec3 *x = spn_world_positions(v->world);
    glEnable(GL_POINT_SMOOTH);
    glPointSize(5);
    glBegin(GL_POINTS);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(v->world, s);
        if (si.broken || (si.tag != SPN_THREAD_CAPTURE && si.tag != SPN_THREAD_INSCRIPTION)) continue;
        double t = 0.2 + 0.6 * (double)((s * 2654435761u) >> 16 & 1023u) / 1023.0;
        spn_vec3 p = spn_v3_add(x[si.a], spn_v3_scale(spn_v3_sub(x[si.b], x[si.a]), t));
        glColor4f(0.75f, 0.9f, 1.0f, 0.95f);
        glVertex3d(p.x, p.y, p.z);
    }
    glEnd();
    glDisable(GL_POINT_SMOOTH);
}

static void screen_quad(double x0, double y0, double x1, double y1, double u1, double v1)
{
    glBegin(GL_QUADS);
    glTexCoord2d(0, 0), glVertex2d(x0, y0);
    glTexCoord2d(u1, 0), glVertex2d(x1, y0);
    glTexCoord2d(u1, v1), glVertex2d(x1, y1);
    glTexCoord2d(0, v1), glVertex2d(x0, y1);
    glEnd();
}

static void screen_space(const view_state *v)
{
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0, v->fb_w, v->fb_h, 0, -1, 1);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
}

static void upload_surface(unsigned *tex, cairo_surface_t *s)
{
    if (!*tex) glGenTextures(1, tex);
    glBindTexture(GL_TEXTURE_2D, *tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, cairo_image_surface_get_stride(s) / 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, cairo_image_surface_get_width(s), cairo_image_surface_get_height(s), 0,
                 GL_BGRA, GL_UNSIGNED_BYTE, cairo_image_surface_get_data(s));
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

spn_status view_load_background(view_state *v, const char *path)
{
    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return spn_error(SPN_ERR_IO, "%s: cannot read PNG background", path);
    }
    cairo_surface_t *argb = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, cairo_image_surface_get_width(s),
                                                       cairo_image_surface_get_height(s));
    cairo_t *cr = cairo_create(argb);
    cairo_set_source_surface(cr, s, 0, 0);
    cairo_paint(cr);
    cairo_destroy(cr);
    cairo_surface_flush(argb);
    v->bg_w = cairo_image_surface_get_width(s);
    v->bg_h = cairo_image_surface_get_height(s);
    upload_surface(&v->bg_texture, argb);
    cairo_surface_destroy(argb);
    cairo_surface_destroy(s);
    return SPN_OK;
}

static void draw_background(view_state *v)
{
    screen_space(v);
    if (v->bg_texture) {
        /* Scale to cover the window and crop, keeping the image's aspect. */
        double s = fmax((double)v->fb_w / v->bg_w, (double)v->fb_h / v->bg_h);
        double w = v->bg_w * s, h = v->bg_h * s, x0 = (v->fb_w - w) / 2, y0 = (v->fb_h - h) / 2;
        glEnable(GL_TEXTURE_2D);
        glBindTexture(GL_TEXTURE_2D, v->bg_texture);
        glColor4f(1, 1, 1, 1);
        screen_quad(x0, y0, x0 + w, y0 + h, 1, 1);
        glDisable(GL_TEXTURE_2D);
        return;
    }
    glBegin(GL_QUADS); /* a dusk gradient, so threads read as they would outdoors */
    glColor3f(0.10f, 0.14f, 0.22f), glVertex2d(0, 0), glVertex2d(v->fb_w, 0);
    glColor3f(0.03f, 0.04f, 0.06f), glVertex2d(v->fb_w, v->fb_h), glVertex2d(0, v->fb_h);
    glEnd();
}

static const char *const help_lines[] = {
    "F1 vertices   F2 edges   F3 energy   F4 faces   F5 background",
    "r reverse gravity   g gravity on/off   s stop (freeze motion)",
    "space pause   . single step   w wind   [ ] wind strength   d dew",
    "p screenshot   n new seed (build mode)   h this help   Esc quit",
    "drag a particle to pull it; drag empty space to orbit; scroll to zoom",
    "build mode: click anchors, Enter builds the web, Backspace removes one",
};

static void draw_text(view_state *v)
{
    int w = v->fb_w, h = v->show_help ? 150 : 26;
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h);
    cairo_t *cr = cairo_create(s);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.55);
    cairo_paint(cr);
    cairo_select_font_face(cr, "DejaVu Sans Mono", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 13);
    cairo_set_source_rgba(cr, 0.9, 0.95, 1, 1);
    char line[256];
    uint32_t np = v->world ? spn_world_particle_count(v->world) : 0, ns = v->world ? spn_world_spring_count(v->world) : 0;
    snprintf(line, sizeof line, "%5.1f fps  sim %6.2f ms/frame  %u particles  %u springs  t=%.2fs%s%s%s", v->fps,
             v->sim_ms, np, ns, v->world ? spn_world_time(v->world) : 0.0, v->paused ? "  [paused]" : "",
             v->wind_on ? "  [wind]" : "", v->opt.build_mode && !v->world ? "  [build: click anchors, Enter]" : "");
    cairo_move_to(cr, 8, 18);
    cairo_show_text(cr, line);
    if (v->show_help)
        for (size_t i = 0; i < sizeof help_lines / sizeof help_lines[0]; i++) {
            cairo_move_to(cr, 8, 40 + 19 * (double)i);
            cairo_show_text(cr, help_lines[i]);
        }
    cairo_destroy(cr);
    cairo_surface_flush(s);
    upload_surface(&v->text_texture, s);
    cairo_surface_destroy(s);
    screen_space(v);
    glEnable(GL_TEXTURE_2D);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); /* cairo's pixels are premultiplied */
    glColor4f(1, 1, 1, 1);
    screen_quad(0, 0, w, h, 1, 1);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDisable(GL_TEXTURE_2D);
}

static void draw_anchors(view_state *v)
{
    glPointSize(9);
    glBegin(GL_POINTS);
    glColor3f(1.0f, 0.6f, 0.2f);
    for (int i = 0; i < v->nanchors; i++) glVertex3d(v->anchors[i].x, v->anchors[i].y, v->anchors[i].z);
    glEnd();
    if (v->nanchors > 1) {
        glBegin(GL_LINE_LOOP);
        glColor4f(1.0f, 0.6f, 0.2f, 0.4f);
        for (int i = 0; i < v->nanchors; i++) glVertex3d(v->anchors[i].x, v->anchors[i].y, v->anchors[i].z);
        glEnd();
    }
}

void view_update_camera(view_state *v)
{
    double proj[16], view[16];
    glfwGetFramebufferSize(v->win, &v->fb_w, &v->fb_h);
    camera_matrices(v, proj, view);
    mat_mul(proj, view, v->mvp);
}

void view_draw(view_state *v)
{
    glfwGetFramebufferSize(v->win, &v->fb_w, &v->fb_h);
    glViewport(0, 0, v->fb_w, v->fb_h);
    glClearColor(0.02f, 0.03f, 0.05f, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_LINE_SMOOTH);
    if (v->show_background) draw_background(v);

    double proj[16], view[16];
    camera_matrices(v, proj, view);
    mat_mul(proj, view, v->mvp);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(view);
    if (v->world) {
        if (v->show_faces) draw_faces(v);
        if (v->show_edges || v->show_energy) draw_edges(v);
        if (v->show_dew) draw_dew(v);
        if (v->show_vertices) draw_vertices(v);
    }
    if (v->opt.build_mode && !v->world) draw_anchors(v);
    draw_text(v);
}

spn_status view_screenshot(view_state *v, const char *path)
{
    int w = v->fb_w, h = v->fb_h;
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
    unsigned char *rgba = malloc((size_t)w * h * 4);
    if (!rgba || cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        free(rgba);
        cairo_surface_destroy(s);
        return spn_error(SPN_ERR_NOMEM, "out of memory for a %dx%d screenshot", w, h);
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    unsigned char *dst = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < h; y++) /* GL rows run bottom-up */
        for (int x = 0; x < w; x++) {
            const unsigned char *p = rgba + ((size_t)(h - 1 - y) * w + x) * 4;
            uint32_t px = 0xff000000u | (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2];
            memcpy(dst + (size_t)y * stride + 4 * (size_t)x, &px, 4);
        }
    free(rgba);
    cairo_surface_mark_dirty(s);
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, false);
    if (st == SPN_OK) {
        if (cairo_surface_write_to_png(s, f.tmp_path) != CAIRO_STATUS_SUCCESS) {
            spn_atomic_abort(&f);
            st = spn_error(SPN_ERR_IO, "%s: cannot write the screenshot", path);
        } else {
            st = spn_atomic_commit(&f);
        }
    }
    cairo_surface_destroy(s);
    return st;
}

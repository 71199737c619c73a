/* Output of `spinneret shoot`: the recorded frames as JSON, or rendered
 * through the render API (spn_render_rgba, spn_frames_*) from one perspective
 * camera that frames the whole shot.
 * Each frame is two renders composited by the brighter pixel (both on the
 * same dark background): the strand, drawn with the shot's fading alpha, and
 * the scenery (a ground grid and the character as an orange wireframe
 * octahedron), always opaque. */
#include "cmd_shoot.h"
#include "frame_pipe.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static spn_status write_vec(spn_sink *k, spn_vec3 v)
{
    return spn_sink_printf(k, "[%.9g,%.9g,%.9g]", v.x, v.y, v.z);
}

static spn_status write_frame(spn_sink *k, const recording *r, uint32_t f)
{
    spn_status st = spn_sink_printf(k, "%s\n{\"t\":%.9g,\"phase\":\"%s\",\"alpha\":%.6g,\"shake\":%.6g,\"character\":",
                                    f ? "," : "", r->t[f], spn_shot_phase_name(r->phase[f]), r->alpha[f], r->shake[f]);
    if (st == SPN_OK) st = write_vec(k, r->character[f]);
    if (st == SPN_OK) st = spn_sink_printf(k, ",\"strand\":[");
    const spn_vec3 *p = r->strand + (size_t)f * r->n;
    for (uint32_t i = 0; i < r->count[f] && st == SPN_OK; i++) {
        if (i) st = spn_sink_printf(k, ",");
        if (st == SPN_OK) st = write_vec(k, p[i]);
    }
    return st == SPN_OK ? spn_sink_printf(k, "]}") : st;
}

int shoot_write_json(const char *cmd, const char *path, const spn_shot *s, const recording *r, double fps)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, true);
    if (st != SPN_OK) return cli_fail_status(cmd, st);
    spn_sink k = spn_sink_file(f.fp);
    const spn_ballistic *b = spn_shot_path(s);
    st = spn_sink_printf(&k,
                         "{\"format\":\"spinneret-shot\",\"version\":1,\"units\":\"SI\",\"fps\":%.9g,\"points\":%u,\n"
                         "\"origin\":[%.9g,%.9g,%.9g],\"target\":[%.9g,%.9g,%.9g],\"speed\":%.9g,\"min_speed\":%.9g,\n"
                         "\"elevation\":%.9g,\"contact_time\":%.9g,\n\"frames\":[",
                         fps, r->n, b->origin.x, b->origin.y, b->origin.z, b->target.x, b->target.y, b->target.z,
                         b->speed, b->min_speed, b->elevation, b->flight_time);
    for (uint32_t i = 0; i < r->frames && st == SPN_OK; i++) st = write_frame(&k, r, i);
    if (st == SPN_OK) st = spn_sink_printf(&k, "\n]}\n");
    if (st != SPN_OK) {
        spn_atomic_abort(&f);
        return cli_fail(cmd, "%s: %s", path, spn_last_error());
    }
    st = spn_atomic_commit(&f);
    if (st != SPN_OK) return cli_fail_status(cmd, st);
    fprintf(stderr, "shoot: wrote %s\n", path);
    return 0;
}

/* ---- rendering ----------------------------------------------------------- */

typedef struct view {
    spn_vec3 centre, lo, hi;
    double radius;
} view;

static void grow_box(view *v, spn_vec3 p)
{
    v->lo = spn_v3(fmin(v->lo.x, p.x), fmin(v->lo.y, p.y), fmin(v->lo.z, p.z));
    v->hi = spn_v3(fmax(v->hi.x, p.x), fmax(v->hi.y, p.y), fmax(v->hi.z, p.z));
}

static view frame_all(const recording *r)
{
    view v;
    v.lo = v.hi = r->character[0];
    for (uint32_t f = 0; f < r->frames; f++) {
        /* The character after release may fly out of the picture: framing
         * its whole flight would shrink the shot itself. */
        if (r->phase[f] < SPN_SHOT_ZIPP) grow_box(&v, r->character[f]);
        for (uint32_t i = 0; i < r->count[f]; i++) grow_box(&v, r->strand[(size_t)f * r->n + i]);
    }
    v.centre = spn_v3_scale(spn_v3_add(v.lo, v.hi), 0.5);
    v.radius = fmax(0.5 * spn_v3_len(spn_v3_sub(v.hi, v.lo)), 1e-3);
    return v;
}

static spn_status add_line(spn_world *w, spn_vec3 a, spn_vec3 b, uint32_t tag)
{
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    uint32_t ia = 0, ib = 0;
    p.position = a;
    spn_status st = spn_world_add_particle(w, &p, &ia);
    p.position = b;
    if (st == SPN_OK) st = spn_world_add_particle(w, &p, &ib);
    spn_spring_def s = spn_spring_def_default();
    s.a = ia, s.b = ib, s.tag = tag, s.rest = -1;
    return st == SPN_OK ? spn_world_add_spring(w, &s, NULL) : st;
}

/* A ground grid under the shot, a little wider than it, with about ten lines
 * across; then the marker's 6 particles (from *marker_first). */
static spn_status build_scenery(spn_world *w, const view *v, uint32_t *marker_first)
{
    spn_vec3 ext = spn_v3_sub(v->hi, v->lo);
    double e = fmax(fmax(ext.x, ext.z), 1e-3), hx = 0.5 * ext.x + 0.15 * e, hz = fmax(0.5 * ext.z, 0.3 * e) + 0.15 * e;
    double step = pow(10, floor(log10(e / 10)));
    while (2 * fmax(hx, hz) / step > 14) step *= 2;
    double y = v->lo.y - 0.05 * e, x0 = floor((v->centre.x - hx) / step) * step,
           z0 = floor((v->centre.z - hz) / step) * step, x1 = v->centre.x + hx, z1 = v->centre.z + hz;
    spn_status st = SPN_OK;
    for (double x = x0; x <= x1 + 1e-9 && st == SPN_OK; x += step)
        st = add_line(w, spn_v3(x, y, z0), spn_v3(x, y, z1), SPN_THREAD_BEND);
    for (double z = z0; z <= z1 + 1e-9 && st == SPN_OK; z += step)
        st = add_line(w, spn_v3(x0, y, z), spn_v3(x1, y, z), SPN_THREAD_BEND);
    *marker_first = spn_world_particle_count(w);
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    for (int i = 0; i < 6 && st == SPN_OK; i++) st = spn_world_add_particle(w, &p, NULL);
    /* Octahedron: 0,1 = +-x, 2,3 = +-y, 4,5 = +-z; every pair but opposites. */
    spn_spring_def s = spn_spring_def_default();
    s.tag = SPN_THREAD_ANCHOR;
    s.rest = 1;
    for (uint32_t a = 0; a < 6 && st == SPN_OK; a++)
        for (uint32_t b = a + 1; b < 6 && st == SPN_OK; b++) {
            if (b == a + 1 && a % 2 == 0) continue;
            s.a = *marker_first + a, s.b = *marker_first + b;
            st = spn_world_add_spring(w, &s, NULL);
        }
    return st;
}

static void place_marker(spn_world *w, uint32_t first, spn_vec3 c, double size)
{
    const spn_vec3 d[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (uint32_t i = 0; i < 6; i++) spn_world_set_position(w, first + i, spn_v3_add(c, spn_v3_scale(d[i], size)));
}

static spn_status build_strand(spn_world *w, uint32_t n)
{
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    spn_status st = SPN_OK;
    for (uint32_t i = 0; i < n && st == SPN_OK; i++) {
        p.position = spn_v3(i, 0, 0);
        st = spn_world_add_particle(w, &p, NULL);
    }
    spn_spring_def s = spn_spring_def_default();
    s.tag = SPN_THREAD_SHOT;
    s.rest = 1;
    for (uint32_t i = 0; i + 1 < n && st == SPN_OK; i++) {
        s.a = i, s.b = i + 1;
        st = spn_world_add_spring(w, &s, NULL);
    }
    return st;
}

static spn_render_def render_def(const video_options *o, const view *v)
{
    const int width = o->width, height = o->height;
    spn_render_def d = spn_render_def_default();
    d.width = width, d.height = height;
    d.background_rgb[0] = 0.035, d.background_rgb[1] = 0.045, d.background_rgb[2] = 0.075;
    d.shade_rgb[0] = 0.92, d.shade_rgb[1] = 0.94, d.shade_rgb[2] = 1.0;
    d.width_scale = 2;
    d.legend = false;
    d.camera.kind = SPN_CAMERA_PERSPECTIVE;
    d.camera.fov_degrees = 40;
    d.camera.up = spn_v3(0, 1, 0);
    double fov = d.camera.fov_degrees * SPN_PI / 180;
    if (width < height) fov = 2 * atan(tan(fov / 2) * width / height); /* the narrower side frames */
    double dist = 0.95 * v->radius / sin(fov / 2);
    spn_vec3 dir = spn_v3_norm(spn_v3(0.25, 0.16, 1));
    d.camera.target = o->have_look ? o->look : v->centre;
    d.camera.eye = o->have_eye ? o->eye : spn_v3_add(d.camera.target, spn_v3_scale(dir, dist));
    return d;
}

/* What one drawing thread keeps: its own strand and scenery worlds (each
 * frame moves their particles) and the strand's picture. */
typedef struct render_slot {
    spn_world *strand, *scenery;
    uint32_t marker_first;
    uint8_t *a;
} render_slot;

typedef struct renderer {
    const recording *r;
    spn_render_def d;
    double radius; /* the view's */
    render_slot slot[FRAME_PIPE_MAX_THREADS];
    int slots;
} renderer;

static void renderer_free(renderer *q)
{
    for (int i = 0; i < q->slots; i++) {
        spn_world_destroy(q->slot[i].strand);
        spn_world_destroy(q->slot[i].scenery);
        free(q->slot[i].a);
    }
}

static spn_status slot_init(render_slot *s, const recording *r, const view *v, size_t bytes)
{
    s->strand = spn_world_create(NULL);
    s->scenery = spn_world_create(NULL);
    s->a = malloc(bytes);
    if (!s->strand || !s->scenery || !s->a) return spn_error(SPN_ERR_NOMEM, "out of memory for the frames");
    spn_status st = build_strand(s->strand, r->n);
    return st == SPN_OK ? build_scenery(s->scenery, v, &s->marker_first) : st;
}

/* Frame f into b (frame_pipe_fn: slot `slot`'s worlds and buffer). */
static spn_status render_frame(void *user, int slot, int frame, const spn_world *none, uint8_t *b)
{
    (void)none;
    const renderer *q = user;
    const recording *r = q->r;
    const render_slot *s = &q->slot[slot];
    const uint32_t f = (uint32_t)frame;
    spn_render_def d = q->d;
    /* Camera shake: a small wobble of eye and target, at two unrelated rates. */
    double amp = 0.02 * q->radius * r->shake[f], t = r->t[f];
    spn_vec3 off = spn_v3(amp * sin(2 * SPN_PI * 11 * t), amp * sin(2 * SPN_PI * 17 * t + 1), 0);
    d.camera.eye = spn_v3_add(d.camera.eye, off);
    d.camera.target = spn_v3_add(d.camera.target, off);
    place_marker(s->scenery, s->marker_first, r->character[f], 0.025 * q->radius);
    spn_render_def ds = d;
    ds.colour_by = SPN_COLOUR_KIND;
    spn_status st = spn_render_rgba(s->scenery, &ds, b);
    size_t bytes = (size_t)d.width * d.height * 4;
    if (st == SPN_OK && r->count[f] > 0) {
        const spn_vec3 *p = r->strand + (size_t)f * r->n;
        for (uint32_t i = 0; i < r->n; i++) spn_world_set_position(s->strand, i, p[i]);
        d.alpha = r->alpha[f];
        st = spn_render_rgba(s->strand, &d, s->a);
        for (size_t i = 0; i < bytes && st == SPN_OK; i++)
            if (s->a[i] > b[i]) b[i] = s->a[i];
    }
    return st;
}

int shoot_write_video(const char *cmd, const char *path, const recording *r, const video_options *o)
{
    const int width = o->width, height = o->height;
    view v = frame_all(r);
    renderer q;
    memset(&q, 0, sizeof q);
    q.r = r;
    q.d = render_def(o, &v);
    q.radius = v.radius;
    const int threads = frame_pipe_threads((int)r->frames);
    spn_status st = SPN_OK;
    for (; q.slots < threads && st == SPN_OK; q.slots++)
        st = slot_init(&q.slot[q.slots], r, &v, (size_t)width * height * 4);
    spn_frames *frames = NULL;
    if (st == SPN_OK) st = spn_frames_open(path, width, height, o->fps, &frames);
    spn_progress *bar = spn_progress_begin("shoot", r->frames, o->quiet);
    int done = 0;
    cli_interruptible(r->frames);
    if (st == SPN_OK) st = frame_pipe_run(frames, (int)r->frames, render_frame, &q, bar, &done);
    spn_progress_end(bar);
    /* Interrupted or not, the complete frames; after a failure no partial video. */
    if (frames) {
        spn_status cs = spn_frames_close(frames, st == SPN_OK);
        if (st == SPN_OK) st = cs;
    }
    renderer_free(&q);
    if (st != SPN_OK) return spn_interrupt_graceful(false), cli_fail_status(cmd, st);
    if (spn_interrupted()) return cli_report_interrupt(cmd, (uint64_t)done, r->frames, "the complete frames are kept", 0);
    spn_interrupt_graceful(false);
    fprintf(stderr, "shoot: wrote %s\n", path);
    return 0;
}

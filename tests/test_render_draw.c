/* Rendering measured, never compared with golden pictures: ink lies where the
 * springs are and nowhere else (coverage against the analytic stroke area),
 * alpha 0.7 over white gives the expected blend, joints of a strand are not
 * darker than its middle, a background image shows through where no thread
 * is, strands and dew come out in the numbers the geometry predicts, and bad
 * definitions are refused with no file left behind. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cairo.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <spinneret/spinneret.h>

#define SIDE 200

/* A world of straight springs between the given points (x0, y0, x1, y1). */
static spn_world *segments_world(const double (*seg)[4], int n, uint32_t tag)
{
    spn_world *w = spn_world_create(NULL);
    for (int i = 0; i < n; i++) {
        spn_particle_def p = spn_particle_def_default();
        uint32_t a, b;
        p.fixed = true;
        p.position = spn_v3(seg[i][0], seg[i][1], 0);
        assert_int_equal(spn_world_add_particle(w, &p, &a), SPN_OK);
        p.position = spn_v3(seg[i][2], seg[i][3], 0);
        assert_int_equal(spn_world_add_particle(w, &p, &b), SPN_OK);
        spn_spring_def s = spn_spring_def_default();
        s.a = a;
        s.b = b;
        s.k = 1;
        s.rest = -1;
        s.tag = tag;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    }
    return w;
}

/* A known mapping: world [-0.5, 0.5]^2 onto SIDE x SIDE pixels, 200 px/m,
 * lines `px` pixels wide (generic kind), white threads, black background. */
static spn_render_def known_def(double px)
{
    spn_render_def d = spn_render_def_default();
    d.width = d.height = SIDE;
    d.camera.fixed_bounds = true;
    d.camera.bounds_min = spn_v3(-0.5, -0.5, 0);
    d.camera.bounds_max = spn_v3(0.5, 0.5, 0);
    d.camera.margin = 0;
    d.shade_rgb[0] = d.shade_rgb[1] = d.shade_rgb[2] = 1;
    d.width_scale = px / (spn_thread_kind_width(SPN_THREAD_GENERIC) * SIDE / 1200.0);
    return d;
}

/* Distance from pixel centre (x, y) to the segment (a, b) in pixels. */
static double seg_dist(double x, double y, const double *s)
{
    double ax = 100 + 200 * s[0], ay = 100 - 200 * s[1], bx = 100 + 200 * s[2], by = 100 - 200 * s[3];
    double dx = bx - ax, dy = by - ay, t = ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(x - ax - t * dx, y - ay - t * dy);
}

static void test_ink_where_expected(void **state)
{
    (void)state;
    const double seg[2][4] = {{-0.4, 0.2, 0.4, 0.2}, {-0.2, -0.4, -0.2, -0.1}};
    spn_world *w = segments_world(seg, 2, SPN_THREAD_GENERIC);
    const double width = 4;
    spn_render_def d = known_def(width);
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    double ink = 0, stray = 0, inside_min = 255;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            double v = px[(y * SIDE + x) * 4], dist = fmin(seg_dist(x + 0.5, y + 0.5, seg[0]), seg_dist(x + 0.5, y + 0.5, seg[1]));
            ink += v / 255;
            if (dist > width / 2 + 1) stray += v;
            if (dist < width / 2 - 1) inside_min = fmin(inside_min, v);
        }
    /* Two strokes with round caps: length * width + a disc each. */
    double expected = (160 + 60) * width + 2 * SPN_PI * width * width / 4;
    assert_true(stray == 0);
    assert_true(inside_min >= 254);
    assert_true(fabs(ink - expected) < 0.03 * expected);
    free(px);
    spn_world_destroy(w);
}

/* Widths follow the kind: anchor 2.4 / capture 1.0 / generic 1.3 (and an
 * unknown tag draws like generic), measured as ink per unit length. */
static void test_kind_widths(void **state)
{
    (void)state;
    const uint32_t tags[4] = {SPN_THREAD_ANCHOR, SPN_THREAD_CAPTURE, SPN_THREAD_GENERIC, 999};
    double ink[4];
    for (int k = 0; k < 4; k++) {
        const double seg[1][4] = {{-0.4, 0.0, 0.4, 0.0}};
        spn_world *w = segments_world(seg, 1, tags[k]);
        spn_render_def d = known_def(5);  /* generic: 5 px */
        for (int c = 0; c < 3; c++) d.shade_rgb[c] = 1;
        uint8_t *px = malloc(SIDE * SIDE * 4);
        assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
        ink[k] = 0;
        for (int y = 0; y < SIDE; y++)
            for (int x = 40; x < 160; x++) ink[k] += px[(y * SIDE + x) * 4] / 255.0; /* away from the caps */
        ink[k] /= spn_thread_kind_shade(tags[k]); /* capture is drawn a little greyer */
        free(px);
        spn_world_destroy(w);
    }
    double generic = 5 * 120;
    assert_true(fabs(ink[2] - generic) < 0.02 * generic);
    assert_true(fabs(ink[0] / ink[2] - spn_thread_kind_width(SPN_THREAD_ANCHOR) / 1.3) < 0.03);
    assert_true(fabs(ink[1] / ink[2] - spn_thread_kind_width(SPN_THREAD_CAPTURE) / 1.3) < 0.03);
    assert_true(spn_thread_kind_width(SPN_THREAD_ANCHOR) > spn_thread_kind_width(SPN_THREAD_CAPTURE));
    assert_true(fabs(ink[3] - ink[2]) < 1e-9);
}

/* A bent chain of three springs: one strand, so its joints blend like its middle. */
static void test_alpha_blend_and_joints(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    const double pts[4][2] = {{-0.4, -0.3}, {-0.1, 0.3}, {0.2, -0.3}, {0.4, 0.3}};
    for (int i = 0; i < 4; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3(pts[i][0], pts[i][1], 0);
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    for (uint32_t i = 0; i < 3; i++) {
        spn_spring_def s = spn_spring_def_default();
        s.a = i;
        s.b = i + 1;
        s.k = 1;
        s.rest = -1;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    }
    spn_render_def d = known_def(8);
    const double shade[3] = {0.2, 0.4, 0.6};
    for (int c = 0; c < 3; c++) d.shade_rgb[c] = shade[c], d.background_rgb[c] = 1;
    d.alpha = 0.7;
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    /* Middle of the first segment, and the two joints. */
    const double probe[3][2] = {{-0.25, 0.0}, {-0.1, 0.3}, {0.2, -0.3}};
    for (int k = 0; k < 3; k++) {
        int x = (int)(100 + 200 * probe[k][0]), y = (int)(100 - 200 * probe[k][1]);
        for (int c = 0; c < 3; c++) {
            double expected = 255 * (0.7 * shade[c] + 0.3);
            assert_true(fabs(px[(y * SIDE + x) * 4 + c] - expected) <= 2);
        }
    }
    free(px);
    spn_world_destroy(w);
}

/* A 4 x 2 test image of four coloured quadrants (their colours turned by
 * `turn` places), stretched over a square canvas by cover scaling: the
 * middle half of the image width shows. */
static const double quadrant_rgb[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};

static const char *write_test_background(char *path, size_t n, int turn)
{
    snprintf(path, n, "%s/render_bg_%ld.png", SPN_BUILD_DIR, (long)getpid());
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 400, 200);
    cairo_t *cr = cairo_create(s);
    for (int i = 0; i < 4; i++) {
        const double *q = quadrant_rgb[(i + turn) % 4];
        cairo_rectangle(cr, (i % 2) * 200, (i / 2) * 100, 200, 100);
        cairo_set_source_rgb(cr, q[0], q[1], q[2]);
        cairo_fill(cr);
    }
    cairo_destroy(cr);
    assert_int_equal(cairo_surface_write_to_png(s, path), CAIRO_STATUS_SUCCESS);
    cairo_surface_destroy(s);
    return path;
}

/* Canvas quadrants show image quadrants: the image is 2:1, scaled by 1 to
 * 200 px high and cropped to its middle 200 px. */
static void assert_quadrants(const uint8_t *px, int turn)
{
    const int probe[4][2] = {{50, 40}, {150, 40}, {50, 160}, {150, 160}};
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++)
            assert_int_equal(px[(probe[k][1] * SIDE + probe[k][0]) * 4 + c], 255 * quadrant_rgb[(k + turn) % 4][c]);
}

/* One line across the middle over the quadrant image turned `turn` places. */
static spn_world *line_over_background(spn_render_def *d, char *path, size_t n, int turn)
{
    const double seg[1][4] = {{-0.5, 0.0, 0.5, 0.0}};
    *d = known_def(4);
    d->background_png = write_test_background(path, n, turn);
    return segments_world(seg, 1, SPN_THREAD_GENERIC);
}

static void test_background_shows_where_no_thread(void **state)
{
    (void)state;
    char path[512];
    spn_render_def d;
    spn_world *w = line_over_background(&d, path, sizeof path, 0);
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    assert_quadrants(px, 0);
    /* The thread covers the image on its line. */
    assert_int_equal(px[(100 * SIDE + 30) * 4 + 2], 255);
    assert_int_equal(px[(100 * SIDE + 30) * 4 + 1], 255);
    /* The decoded image is kept between pictures, but a file written again
     * at once (the same size, the same path) is what the next one shows. */
    for (int turn = 1; turn < 4; turn++) {
        write_test_background(path, sizeof path, turn);
        for (int again = 0; again < 2; again++) {
            memset(px, 0, SIDE * SIDE * 4);
            assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
            assert_quadrants(px, turn);
        }
    }
    remove(path);
    d.background_png = "/nonexistent/sky.png";
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_ERR_IO);
    assert_non_null(strstr(spn_last_error(), "/nonexistent/sky.png"));
    assert_non_null(strstr(spn_last_error(), "background"));
    free(px);
    spn_world_destroy(w);
    spn_render_release_caches();
}

/* A thread that draws over a background and ends leaves nothing behind (its
 * decoded image goes with it: the sanitizer build's leak check sees to
 * that), and draws what the main thread draws. */
typedef struct drawing {
    const spn_world *w;
    const spn_render_def *d;
    uint8_t *px;
    spn_status st;
} drawing;

static void *draw_on_thread(void *arg)
{
    drawing *job = arg;
    job->st = spn_render_rgba(job->w, job->d, job->px);
    return NULL;
}

static void test_background_on_threads(void **state)
{
    (void)state;
    char path[512];
    spn_render_def d;
    spn_world *w = line_over_background(&d, path, sizeof path, 2);
    uint8_t *mine = malloc(SIDE * SIDE * 4), *theirs[2] = {malloc(SIDE * SIDE * 4), malloc(SIDE * SIDE * 4)};
    assert_int_equal(spn_render_rgba(w, &d, mine), SPN_OK);
    drawing jobs[2] = {{w, &d, theirs[0], SPN_ERR_INVALID}, {w, &d, theirs[1], SPN_ERR_INVALID}};
    pthread_t t[2];
    for (int i = 0; i < 2; i++) assert_int_equal(pthread_create(&t[i], NULL, draw_on_thread, &jobs[i]), 0);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(pthread_join(t[i], NULL), 0);
        assert_int_equal(jobs[i].st, SPN_OK);
        assert_memory_equal(theirs[i], mine, SIDE * SIDE * 4);
    }
    assert_quadrants(mine, 2);
    remove(path);
    free(mine);
    free(theirs[0]);
    free(theirs[1]);
    spn_world_destroy(w);
    spn_render_release_caches();
}

typedef struct counts {
    int strands, closed, segments, beads, labels;
    uint32_t kinds_seen[8];
    double bead_radius_sum;
    int main_beads;
    double main_radius_sum, dew_radius;
} counts;

static spn_status count_strand(void *user, const spn_strand *s)
{
    counts *c = user;
    c->strands++;
    c->closed += s->closed;
    c->segments += (int)(s->closed ? s->count : s->count - 1);
    return SPN_OK;
}

static spn_status count_bead(void *user, const spn_bead *b)
{
    counts *c = user;
    c->beads++;
    if (b->radius > 0.5 * c->dew_radius) {
        c->main_beads++;
        c->main_radius_sum += b->radius;
    }
    return SPN_OK;
}

static spn_status count_label(void *user, const spn_label *l)
{
    (void)l;
    ((counts *)user)->labels++;
    return SPN_OK;
}

/* The standard web: each radius is one strand from the hub to the rim, each
 * ring one closed strand; every spring is drawn once. */
static void test_orb_web_strands(void **state)
{
    (void)state;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 7;
    od.radials = 11;
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    spn_render_def d = spn_render_def_default();
    d.colour_by = SPN_COLOUR_KIND;
    counts c = {0};
    spn_draw_fns fns = {count_strand, count_bead, count_label};
    assert_int_equal(spn_draw_world(w, &d, &fns, &c), SPN_OK);
    assert_int_equal(c.strands, 11 + 7);
    assert_int_equal(c.closed, 7);
    assert_int_equal(c.segments, (int)spn_world_spring_count(w));
    assert_int_equal(c.labels, 1 + 3); /* title, frame, radius, capture */
    spn_world_destroy(w);
}

/* Dew along the capture rings: main drops every `spacing` on average, of
 * mean radius `radius`, the same drops for the same seed. */
static void test_dew_spacing_and_radius(void **state)
{
    (void)state;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    double capture = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info info = spn_world_spring(w, s);
        if (info.tag == SPN_THREAD_CAPTURE) capture += info.length;
    }
    spn_render_def d = spn_render_def_default();
    d.dew.enabled = true;
    d.dew.spacing = 3e-3;
    d.dew.radius = 0.5e-3;
    counts a = {0}, b = {0};
    a.dew_radius = b.dew_radius = d.dew.radius;
    spn_draw_fns fns = {NULL, count_bead, NULL};
    assert_int_equal(spn_draw_world(w, &d, &fns, &a), SPN_OK);
    assert_int_equal(spn_draw_world(w, &d, &fns, &b), SPN_OK);
    assert_int_equal(a.beads, b.beads);
    assert_true(a.main_radius_sum == b.main_radius_sum);
    double expected = capture / d.dew.spacing;
    assert_true(fabs(a.main_beads - expected) < 0.05 * expected);
    assert_true(fabs(a.main_radius_sum / a.main_beads - d.dew.radius) < 0.05 * d.dew.radius);
    d.dew.seed = 2;
    counts e = {0};
    e.dew_radius = d.dew.radius;
    assert_int_equal(spn_draw_world(w, &d, &fns, &e), SPN_OK);
    assert_true(e.main_radius_sum != a.main_radius_sum);
    spn_world_destroy(w);
}

static void test_deterministic_pixels(void **state)
{
    (void)state;
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, NULL, &w), SPN_OK);
    spn_render_def d = spn_render_def_default();
    d.width = d.height = 300;
    d.dew.enabled = true;
    d.glow = 0.5;
    uint8_t *a = malloc(300 * 300 * 4), *b = malloc(300 * 300 * 4);
    assert_int_equal(spn_render_rgba(w, &d, a), SPN_OK);
    assert_int_equal(spn_render_rgba(w, &d, b), SPN_OK);
    assert_memory_equal(a, b, 300 * 300 * 4);
    free(a);
    free(b);
    spn_world_destroy(w);
}

/* Tension colouring: a stretched spring takes the top of the scale (red), a
 * spring at rest the bottom (blue). */
static void test_colour_by_tension(void **state)
{
    (void)state;
    const double seg[2][4] = {{-0.4, 0.2, 0.4, 0.2}, {-0.4, -0.2, 0.4, -0.2}};
    spn_world *w = segments_world(seg, 2, SPN_THREAD_GENERIC);
    spn_world_set_spring_rest(w, 0, 0.5); /* 0.8 m long: tension 0.3 N */
    spn_render_def d = known_def(6);
    d.colour_by = SPN_COLOUR_TENSION;
    d.legend = false;
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    const uint8_t *hot = px + (60 * SIDE + 100) * 4, *cold = px + (140 * SIDE + 100) * 4;
    assert_true(hot[0] > 200 && hot[2] < 80);
    assert_true(cold[2] > 180 && cold[0] < 80);
    free(px);
    spn_world_destroy(w);
}

/* A pinhole at (0, 0, 1) with a 90 degree field of view: focal length half the
 * canvas, so the segment from (-0.5, 0, 0) to (0.5, 0, 0) spans the middle
 * half of the middle row. */
static void test_perspective_projection(void **state)
{
    (void)state;
    const double seg[1][4] = {{-0.5, 0.0, 0.5, 0.0}};
    spn_world *w = segments_world(seg, 1, SPN_THREAD_GENERIC);
    spn_render_def d = known_def(3);
    d.camera.kind = SPN_CAMERA_PERSPECTIVE;
    d.camera.eye = spn_v3(0, 0, 1);
    d.camera.target = spn_v3(0, 0, 0);
    d.camera.fov_degrees = 90;
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    int first = -1, last = -1;
    for (int x = 0; x < SIDE; x++)
        if (px[(100 * SIDE + x) * 4] > 128) {
            if (first < 0) first = x;
            last = x;
        }
    /* 50 .. 150 plus the round caps (1.5 px) */
    assert_true(abs(first - 49) <= 1 && abs(last - 150) <= 1);
    assert_int_equal(px[(90 * SIDE + 100) * 4], 0);
    free(px);
    spn_world_destroy(w);
}

/* --smooth: a closed hexagon of one kind becomes a Catmull-Rom curve through
 * its corners; midway between two corners it passes (-P0 + 9 P1 + 9 P2 - P3)
 * / 16 (equal spacing), outside the straight chord. */
static void test_smooth_strands(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    const double r = 0.4;
    for (int i = 0; i < 6; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3(r * cos(i * SPN_PI / 3), r * sin(i * SPN_PI / 3), 0);
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    for (uint32_t i = 0; i < 6; i++) {
        spn_spring_def sd = spn_spring_def_default();
        sd.a = i;
        sd.b = (i + 1) % 6;
        sd.k = 1;
        sd.rest = -1;
        assert_int_equal(spn_world_add_spring(w, &sd, NULL), SPN_OK);
    }
    /* Along the 30 degree bisector: the chord at r cos 30, the curve at
     * (9 + 9) r cos 30 / 16 - 2 r cos 90 / 16 (P0 and P3 at -60 and 120 degrees). */
    double chord = r * cos(SPN_PI / 6), curve = 18 * r * cos(SPN_PI / 6) / 16 - 2 * r * cos(SPN_PI / 2) / 16;
    uint8_t *px = malloc(SIDE * SIDE * 4);
    spn_render_def d = known_def(2);
    for (int smooth = 0; smooth < 2; smooth++) {
        d.smooth = smooth;
        assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
        int xc = (int)(100 + 200 * chord * cos(SPN_PI / 6)), yc = (int)(100 - 200 * chord * sin(SPN_PI / 6));
        int xs = (int)(100 + 200 * curve * cos(SPN_PI / 6)), ys = (int)(100 - 200 * curve * sin(SPN_PI / 6));
        uint8_t on_chord = px[(yc * SIDE + xc) * 4], on_curve = px[(ys * SIDE + xs) * 4];
        assert_true(smooth ? (on_curve > 100 && on_chord == 0) : (on_chord > 100 && on_curve == 0));
        /* Both pass through the corners. */
        assert_true(px[(100 * SIDE + (int)(100 + 200 * r) - 1) * 4] > 100);
    }
    free(px);
    spn_world_destroy(w);
}

/* Sheen lights the thread lying across the half vector, not the one along it:
 * light from +x behind, eye on +z: h ~ (1, 0, 0) + (0, 0, 1) minus the light's
 * z, so a vertical thread glints and a horizontal one does not. */
static void test_sheen_glints_across_half_vector(void **state)
{
    (void)state;
    const double seg[2][4] = {{-0.4, 0.3, 0.4, 0.3}, {0.0, -0.45, 0.0, 0.1}};
    spn_world *w = segments_world(seg, 2, SPN_THREAD_GENERIC);
    spn_render_def d = known_def(3);
    for (int c = 0; c < 3; c++) d.shade_rgb[c] = 0.5;
    uint8_t *plain = malloc(SIDE * SIDE * 4), *lit = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, plain), SPN_OK);
    d.sheen = 1;
    d.light = spn_v3(1, 0, -1);
    assert_int_equal(spn_render_rgba(w, &d, lit), SPN_OK);
    int horizontal = (40 * SIDE + 100) * 4, vertical = (150 * SIDE + 100) * 4;
    assert_true(lit[vertical] > plain[vertical] + 60);   /* across h: glints */
    assert_true(lit[horizontal] < plain[horizontal]);    /* along h: fades */
    free(plain);
    free(lit);
    spn_world_destroy(w);
}

static spn_status keep_bead(void *user, const spn_bead *b)
{
    *(spn_bead *)user = *b;
    return SPN_OK;
}

/* A dew drop reads as water: a near-white highlight towards the light (upper
 * left), a body much darker than it, a rim, and no ink beyond its radius. */
static void test_dew_drop_is_lit(void **state)
{
    (void)state;
    const double seg[1][4] = {{-0.5, 0.0, 0.5, 0.0}};
    spn_world *w = segments_world(seg, 1, SPN_THREAD_CAPTURE);
    spn_render_def d = known_def(0.01);
    d.dew.enabled = true;
    d.dew.spacing = 0.9;  /* the first drop within 0.9 m, the next beyond the 1 m thread */
    d.dew.radius = 0.1;   /* 20 px at 200 px/m */
    d.dew.radius_jitter = 0;
    spn_bead b = {{0, 0, 0}, 0, 0};
    spn_draw_fns fns = {NULL, keep_bead, NULL};
    assert_int_equal(spn_draw_world(w, &d, &fns, &b), SPN_OK);
    assert_true(fabs(b.radius - 0.1) < 1e-12);
    uint8_t *px = malloc(SIDE * SIDE * 4);
    assert_int_equal(spn_render_rgba(w, &d, px), SPN_OK);
    double cx = 100 + 200 * b.centre.x, cy = 100 - 200 * b.centre.y, r = 20;
#define G(x, y) px[((int)(y) * SIDE + (int)(x)) * 4 + 1]
    assert_true(G(cx - 0.36 * r, cy - 0.38 * r) > 230);       /* highlight */
    assert_true(G(cx, cy) < 120);                              /* clear body */
    assert_true(G(cx - 0.95 * r, cy) > G(cx - 0.5 * r, cy));   /* brighter rim on a dark backdrop */
    assert_true(G(cx, cy - 1.3 * r) == 0 && G(cx + 1.3 * r, cy - 0.5 * r) == 0);
#undef G
    free(px);
    spn_world_destroy(w);
}

static void test_bad_definitions(void **state)
{
    (void)state;
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, NULL, &w), SPN_OK);
    char path[512];
    snprintf(path, sizeof path, "%s/render_bad_%ld.png", SPN_BUILD_DIR, (long)getpid());
    spn_render_def d = spn_render_def_default();
    d.width = 0;
    assert_int_equal(spn_render_file(w, &d, path), SPN_ERR_INVALID);
    d = spn_render_def_default();
    d.width = d.height = 100000;
    assert_int_equal(spn_render_file(w, &d, path), SPN_ERR_INVALID);
    d = spn_render_def_default();
    d.shade_rgb[1] = NAN;
    assert_int_equal(spn_render_file(w, &d, path), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "shade_rgb[1]"));
    d = spn_render_def_default();
    d.background_png = "/nonexistent/x.png";
    assert_int_equal(spn_render_file(w, &d, path), SPN_ERR_IO);
    assert_int_equal(access(path, F_OK), -1);
    snprintf(path, sizeof path, "%s/render_bad_%ld.bmp", SPN_BUILD_DIR, (long)getpid());
    d = spn_render_def_default();
    assert_int_equal(spn_render_file(w, &d, path), SPN_ERR_INVALID);
    assert_int_equal(access(path, F_OK), -1);
    spn_world_destroy(w);
}

/* SVG and PDF come out as files of their type. */
static void test_vector_outputs(void **state)
{
    (void)state;
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, NULL, &w), SPN_OK);
    spn_render_def d = spn_render_def_default();
    const char *ext[2] = {"svg", "pdf"}, *magic[2] = {"<?xml", "%PDF"};
    for (int i = 0; i < 2; i++) {
        char path[512], head[8] = {0};
        snprintf(path, sizeof path, "%s/render_vec_%ld.%s", SPN_BUILD_DIR, (long)getpid(), ext[i]);
        assert_int_equal(spn_render_file(w, &d, path), SPN_OK);
        FILE *fp = fopen(path, "rb");
        assert_non_null(fp);
        assert_true(fread(head, 1, 5, fp) > 0);
        fclose(fp);
        assert_memory_equal(head, magic[i], strlen(magic[i]));
        remove(path);
    }
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ink_where_expected),      cmocka_unit_test(test_kind_widths),
        cmocka_unit_test(test_alpha_blend_and_joints),
        cmocka_unit_test(test_background_shows_where_no_thread), cmocka_unit_test(test_background_on_threads),
        cmocka_unit_test(test_orb_web_strands),
        cmocka_unit_test(test_dew_spacing_and_radius),  cmocka_unit_test(test_deterministic_pixels),
        cmocka_unit_test(test_colour_by_tension),       cmocka_unit_test(test_bad_definitions),
        cmocka_unit_test(test_vector_outputs),          cmocka_unit_test(test_perspective_projection),
        cmocka_unit_test(test_sheen_glints_across_half_vector), cmocka_unit_test(test_dew_drop_is_lit),
        cmocka_unit_test(test_smooth_strands),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

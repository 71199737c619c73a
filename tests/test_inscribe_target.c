/* Targets: text set in a real font and fitted in the capture area, images
 * placed the same way, the PBM/PGM reader against hand-made files, and every
 * bad input refused with a message naming what is wrong. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#define DATA SPN_TEST_DATA "/inscribe/"
#define BAD SPN_TEST_DATA "/bad/"

static spn_world *orb(void)
{
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(NULL, NULL, &w), SPN_OK);
    return w;
}

static void test_capture_area_of_standard_web(void **state)
{
    (void)state;
    spn_world *w = orb();
    spn_capture_area a;
    assert_int_equal(spn_capture_area_of(w, &a), SPN_OK);
    /* Rings at hub + (R - hub) j / 19, j = 0..18 capture; 24 radials: the
     * outermost capture ring's chords come within R18 cos(7.5 deg) of the centre. */
    double r18 = 0.0075 + (0.15 - 0.0075) * 18 / 19;
    assert_true(fabs(a.radius - r18 * cos(SPN_PI / 24)) < 0.002);
    assert_true(fabs(a.centre.x) < 1e-9 && fabs(a.centre.y) < 1e-9);
    assert_int_equal(a.segments, 18 * 24 + 24);
    spn_world_destroy(w);
}

/* Bounding box of ink >= 0.5 in world units. */
static void ink_box(const spn_target *t, double box[4])
{
    int w, h;
    const float *ink = spn_target_ink(t, &w, &h);
    double s = spn_target_scale(t), px, py;
    spn_target_to_pixel(t, spn_v3(0, 0, 0), &px, &py);
    box[0] = box[1] = INFINITY, box[2] = box[3] = -INFINITY;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++)
            if (ink[(size_t)j * w + i] >= 0.5f) {
                box[0] = fmin(box[0], (i - px) / s), box[2] = fmax(box[2], (i + 1 - px) / s);
                box[1] = fmin(box[1], (py - j - 1) / s), box[3] = fmax(box[3], (py - j) / s);
            }
}

static void test_text_fits_the_capture_area(void **state)
{
    (void)state;
    spn_world *w = orb();
    spn_capture_area a;
    spn_capture_area_of(w, &a);
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 1200, &t), SPN_OK);
    spn_text_def td = spn_text_def_default();
    td.text = "SOME\nPIG";
    assert_int_equal(spn_target_text(t, w, &td), SPN_OK);
    double b[4];
    ink_box(t, b);
    /* Inside fit x the spiral (the outer capture ring's 24-gon, corners at
     * R18), and filling most of the circle inside it; round letters overshoot
     * the capital height and baseline by a few per cent of a letter. */
    double corner = hypot(fmax(-b[0], b[2]), fmax(-b[1], b[3]));
    double r18 = 0.0075 + (0.15 - 0.0075) * 18 / 19;
    if (!(corner <= 0.92 * r18))
        fail_msg("block [%g %g] x [%g %g]: corner %g beyond %g", b[0], b[2], b[1], b[3], corner, 0.92 * r18);
    assert_true(corner >= 0.75 * a.radius);
    assert_true(b[3] - b[1] > 0.1); /* two lines: taller than wide-ish single line */
    double cov = spn_target_coverage(t);
    assert_true(cov > 0.02 && cov < 0.4);
    spn_target_destroy(t);

    /* A given capital height: the letters of "H" are that tall. */
    assert_int_equal(spn_target_create(w, 1200, &t), SPN_OK);
    td.text = "H";
    td.height = 0.05;
    assert_int_equal(spn_target_text(t, w, &td), SPN_OK);
    ink_box(t, b);
    assert_true(fabs((b[3] - b[1]) - 0.05) < 3 / spn_target_scale(t));
    spn_target_destroy(t);
    spn_world_destroy(w);
}

static void expect_error(spn_status st, spn_status want, const char *needle)
{
    assert_int_equal(st, want);
    if (!strstr(spn_last_error(), needle)) fail_msg("message '%s' lacks '%s'", spn_last_error(), needle);
}

static void test_bad_text_refused(void **state)
{
    (void)state;
    spn_world *w = orb();
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 400, &t), SPN_OK);
    spn_text_def td = spn_text_def_default();
    td.text = "PIG";
    td.font = "No Such Font Family Bold";
    expect_error(spn_target_text(t, w, &td), SPN_ERR_INVALID, "not installed");
    td = spn_text_def_default();
    td.text = " \n  ";
    expect_error(spn_target_text(t, w, &td), SPN_ERR_INVALID, "empty");
    td.text = NULL;
    expect_error(spn_target_text(t, w, &td), SPN_ERR_INVALID, "empty");
    td.text = "TERRIFIC";
    td.height = 0.2;
    expect_error(spn_target_text(t, w, &td), SPN_ERR_INVALID, "does not fit");
    td.height = 0;
    td.fit = 1.5;
    expect_error(spn_target_text(t, w, &td), SPN_ERR_INVALID, "fit");
    assert_true(spn_target_coverage(t) == 0); /* nothing drawn by the failures */
    spn_target_destroy(t);
    spn_world_destroy(w);
}

static void test_pnm_reader(void **state)
{
    (void)state;
    spn_grey_image img;
    assert_int_equal(spn_pnm_read(DATA "plus.pbm", &img), SPN_OK);
    assert_int_equal(img.width, 5);
    assert_int_equal(img.height, 5);
    assert_int_equal(img.pixels[2], 0);       /* '1' is black */
    assert_int_equal(img.pixels[0], 255);
    assert_int_equal(img.pixels[12], 0);      /* centre */
    spn_grey_image_free(&img);
    assert_int_equal(spn_pnm_read(DATA "ramp.pgm", &img), SPN_OK);
    assert_int_equal(img.pixels[0], 0);
    assert_int_equal(img.pixels[1], 128);
    assert_int_equal(img.pixels[2], 255);
    spn_grey_image_free(&img);
    expect_error(spn_pnm_read(BAD "inscribe_zero.pgm", &img), SPN_ERR_FORMAT, "inscribe_zero.pgm:3: image is 0x0");
    expect_error(spn_pnm_read(BAD "inscribe_token.pgm", &img), SPN_ERR_FORMAT, "inscribe_token.pgm:5: pixel 4");
    expect_error(spn_pnm_read(BAD "inscribe_p3.ppm", &img), SPN_ERR_FORMAT, ":1: not a PBM or PGM");
    expect_error(spn_pnm_read(BAD "inscribe_short.pgm", &img), SPN_ERR_FORMAT, "ends at pixel 2");
    expect_error(spn_pnm_read(BAD "no_such_file.pgm", &img), SPN_ERR_IO, "cannot read");
    assert_null(img.pixels);
}

static void test_image_target(void **state)
{
    (void)state;
    spn_world *w = orb();
    spn_capture_area a;
    spn_capture_area_of(w, &a);
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 600, &t), SPN_OK);
    assert_int_equal(spn_target_image(t, w, DATA "plus.pbm", 0.8), SPN_OK);
    /* A plus of five 1/5 bars: 9 of 25 cells of a square of diagonal 1.6 R
     * (R: the circle inside the 24-gon of the outer capture ring; the square's
     * corners may reach towards the 24-gon's corners, 1/cos(7.5 deg) further:
     * up to +1.7 % area). Bilinear sampling rounds the four inner corners
     * outward: 4 x (ln2 / 2 - 1/4) of an image pixel, +4.3 % here. */
    double side = 1.6 * a.radius / sqrt(2);
    double want = (9.0 + 4 * (log(2) / 2 - 0.25)) / 25 * side * side * pow(spn_target_scale(t), 2);
    int wd, ht;
    spn_target_ink(t, &wd, &ht);
    double got = spn_target_coverage(t) * wd * ht;
    double most = want / pow(cos(SPN_PI / 24), 2);
    if (!(got > 0.99 * want && got < 1.01 * most)) fail_msg("ink %g px, expected %g..%g", got, want, most);
    assert_true(spn_target_ink_at(t, a.centre) > 0.99);
    expect_error(spn_target_image(t, w, BAD "inscribe_zero.pgm", 0.8), SPN_ERR_FORMAT, "0x0");
    expect_error(spn_target_image(t, w, BAD "inscribe_text.png", 0.8), SPN_ERR_FORMAT, "not a PNG, PBM or PGM");
    expect_error(spn_target_image(t, w, BAD "missing.png", 0.8), SPN_ERR_IO, "missing.png");
    spn_target_destroy(t);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_capture_area_of_standard_web), cmocka_unit_test(test_text_fits_the_capture_area),
        cmocka_unit_test(test_bad_text_refused),             cmocka_unit_test(test_pnm_reader),
        cmocka_unit_test(test_image_target),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    spn_render_release_caches(); /* cairo's and fontconfig's font caches */
    return failed;
}

/* The program's frame threads (tools/frame_pipe.c: worlds handed over by
 * `animate`, and frame_pipe_run for turntables, construction frames and
 * shots), driven directly on two threads: frames land in order even when a
 * later frame is drawn first (even frames here take 30 ms, odd ones none),
 * and a frame that fails ends the sequence there: the frames before it are
 * written, none after it, and the failure's own message comes back. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "common/scratch.h"

#include "frame_pipe.h"

#include <cairo.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

enum { W = 16, H = 8, COUNT = 10, BAD = 4 };

static char folder[512];

static int setup(void **state)
{
    (void)state;
    return spn_test_scratch_make(folder, sizeof folder, "frame_threads");
}

static int teardown(void **state)
{
    (void)state;
    return spn_test_scratch_remove(folder);
}

/* Frame f: every pixel's red is f * 20; even frames take 30 ms, so their
 * odd successors, drawn on the other thread, are done first. Frame BAD
 * fails when `fail_at_bad`. */
static bool fail_at_bad;

static spn_status paint(int frame, uint8_t *rgba)
{
    if (frame % 2 == 0) nanosleep(&(struct timespec){0, 30 * 1000 * 1000}, NULL);
    if (fail_at_bad && frame == BAD) return spn_error(SPN_ERR_INVALID, "frame %d would not draw", frame);
    for (int i = 0; i < W * H; i++) rgba[4 * i] = (uint8_t)(20 * frame), rgba[4 * i + 1] = 7, rgba[4 * i + 2] = 9, rgba[4 * i + 3] = 255;
    return SPN_OK;
}

/* A world handed over (user non-NULL) must arrive as a copy of one
 * particle, none otherwise. (No cmocka assertion off the main thread: a
 * wrong world or slot is an error.) */
static spn_status draw(void *user, int slot, int frame, const spn_world *w, uint8_t *rgba)
{
    if (user ? !w || spn_world_particle_count(w) != 1 : w != NULL)
        return spn_error(SPN_ERR_INVALID, "frame %d: not the world handed over", frame);
    if (slot < 0 || slot >= frame_pipe_threads(COUNT)) return spn_error(SPN_ERR_INVALID, "frame %d: slot %d", frame, slot);
    return paint(frame, rgba);
}

/* The frames in `dir`: frame_00000.png .. of `expect` frames, in order. */
static void check_folder(const char *dir, int expect)
{
    char path[700];
    for (int f = 0; f < COUNT; f++) {
        snprintf(path, sizeof path, "%s/frame_%05d.png", dir, f);
        if (f >= expect) {
            assert_int_equal(access(path, F_OK), -1);
            continue;
        }
        cairo_surface_t *s = cairo_image_surface_create_from_png(path);
        assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
        const uint32_t v = *(const uint32_t *)(const void *)cairo_image_surface_get_data(s);
        assert_int_equal((int)((v >> 16) & 255), 20 * f);
        cairo_surface_destroy(s);
    }
}

static void run_pipe(const char *name, bool fail, int expect)
{
    char dir[600];
    snprintf(dir, sizeof dir, "%s/%s", folder, name);
    fail_at_bad = fail;
    spn_frames *frames;
    assert_int_equal(spn_frames_open(dir, W, H, 25, &frames), SPN_OK);
    spn_world *w = spn_world_create(NULL);
    spn_particle_def pd = spn_particle_def_default();
    assert_int_equal(spn_world_add_particle(w, &pd, NULL), SPN_OK);
    frame_pipe *pipe;
    assert_int_equal(frame_pipe_open(&pipe, frames, 2, draw, w), SPN_OK);
    spn_status st = SPN_OK;
    for (int f = 0; f < COUNT && st == SPN_OK; f++) st = frame_pipe_push(pipe, f, w);
    spn_status closed = frame_pipe_close(pipe, NULL);
    if (st == SPN_OK) st = closed;
    if (fail) {
        assert_int_equal(st, SPN_ERR_INVALID);
        assert_non_null(strstr(spn_last_error(), "frame 4 would not draw"));
    } else {
        assert_int_equal(st, SPN_OK);
    }
    assert_int_equal(spn_frames_close(frames, st == SPN_OK), SPN_OK);
    spn_world_destroy(w);
    check_folder(dir, expect);
}

static void test_pipe_order(void **state)
{
    (void)state;
    run_pipe("pipe", false, COUNT);
}

static void test_pipe_failure(void **state)
{
    (void)state;
    run_pipe("pipe_bad", true, BAD);
}

static void run_free(const char *name, bool fail, int expect)
{
    char dir[600];
    snprintf(dir, sizeof dir, "%s/%s", folder, name);
    fail_at_bad = fail;
    spn_frames *frames;
    assert_int_equal(spn_frames_open(dir, W, H, 25, &frames), SPN_OK);
    int added = -1;
    spn_status st = frame_pipe_run(frames, COUNT, draw, NULL, NULL, &added);
    assert_int_equal(st, fail ? SPN_ERR_INVALID : SPN_OK);
    if (fail) assert_non_null(strstr(spn_last_error(), "frame 4 would not draw"));
    assert_int_equal(added, expect);
    assert_int_equal(spn_frames_close(frames, true), SPN_OK);
    check_folder(dir, expect);
}

static void test_run_order(void **state)
{
    (void)state;
    run_free("run", false, COUNT);
}

static void test_run_failure(void **state)
{
    (void)state;
    run_free("run_bad", true, BAD);
}

int main(void)
{
#ifdef _OPENMP
    omp_set_num_threads(2); /* frame_pipe_run's threads, whatever the machine */
#endif
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_pipe_order), cmocka_unit_test(test_pipe_failure),
                                       cmocka_unit_test(test_run_order), cmocka_unit_test(test_run_failure)};
    return cmocka_run_group_tests(tests, setup, teardown);
}

/* Inscription (Mehla 2005, ch. 6) on the standard orb web: which segments the
 * thesis' scores take out for targets whose answer is known (half the web,
 * nothing, everything), that the emphasis modes touch only threads on the
 * dilated message, and that the result is a settled web hanging whole from
 * its anchors with no dangling thread. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "inscribe_util.h"

static spn_inscribe_def quick_def(void)
{
    spn_inscribe_def d = spn_inscribe_def_default();
    d.settle = false;
    return d;
}

static double right_half(void *user, double x, double y)
{
    (void)user, (void)y;
    return x > 0 ? 1 : 0;
}
static double everything(void *user, double x, double y) { return (void)user, (void)x, (void)y, 1; }

static spn_target *target_from(const spn_world *w, spn_ink_fn fn)
{
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 1200, &t), SPN_OK);
    if (fn) spn_target_paint(t, fn, NULL);
    return t;
}

static uint32_t count_tag(const spn_world *w, uint32_t tag, int side)
{
    uint32_t n = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        double mx = 0.5 * (spn_world_position(w, si.a).x + spn_world_position(w, si.b).x);
        if (si.tag == tag && (side == 0 || (side < 0 ? mx < 0 : mx > 0))) n++;
    }
    return n;
}

static void test_half_target_removes_that_half_only(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    spn_target *t = target_from(w, right_half);
    uint32_t ns = spn_world_spring_count(w);
    uint8_t *scores = malloc(ns);
    assert_int_equal(spn_inscribe_scores(w, t, scores), SPN_OK);
    double px_m = 1.0 / spn_target_scale(t), far_right = 0, removed = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE) {
            assert_int_equal(scores[s], 0);
            continue;
        }
        double xa = spn_world_position(w, si.a).x, xb = spn_world_position(w, si.b).x;
        if (scores[s] > 8) {
            removed++;
            assert_true(fmax(xa, xb) > 0); /* never a segment of the left half */
        }
        if (fmin(xa, xb) > 6 * px_m) far_right++, assert_int_equal(scores[s], 10);
        if (fmax(xa, xb) < -6 * px_m) assert_int_equal(scores[s], 1); /* beyond dilation and band */
    }
    assert_true(far_right > 100 && removed >= far_right);
    uint32_t left = count_tag(w, SPN_THREAD_CAPTURE, -1), right = count_tag(w, SPN_THREAD_CAPTURE, 1);
    spn_inscribe_def d = quick_def();
    spn_inscribe_report rep;
    assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
    assert_int_equal(rep.removed, (uint32_t)removed);
    assert_int_equal(count_tag(w, SPN_THREAD_CAPTURE, -1), left);
    assert_true(count_tag(w, SPN_THREAD_CAPTURE, 1) < right / 4);
    free(scores);
    spn_target_destroy(t);
    spn_world_destroy(w);
}

static void test_empty_target_removes_none(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    spn_target *t = target_from(w, NULL);
    uint32_t ns = spn_world_spring_count(w), np = spn_world_particle_count(w);
    for (int e = 0; e < 4; e++) {
        spn_inscribe_def d = quick_def();
        d.emphasis = (spn_emphasis)e;
        spn_inscribe_report rep;
        assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
        assert_int_equal(rep.removed + rep.added + rep.pruned, 0);
        assert_int_equal(rep.score_histogram[1], rep.segments);
        assert_int_equal(spn_world_spring_count(w), ns);
        assert_int_equal(spn_world_particle_count(w), np);
    }
    spn_target_destroy(t);
    spn_world_destroy(w);
}

static void test_full_target_removes_all_above_threshold(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    spn_target *t = target_from(w, everything);
    uint32_t capture = count_tag(w, SPN_THREAD_CAPTURE, 0);
    spn_inscribe_def d = quick_def();
    d.threshold = 10; /* nothing scores above 10 */
    spn_inscribe_report rep;
    assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
    assert_int_equal(rep.score_histogram[10], capture);
    assert_int_equal(rep.removed, 0);
    d.threshold = 8;
    assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
    assert_int_equal(rep.removed, capture);
    assert_int_equal(count_tag(w, SPN_THREAD_CAPTURE, 0), 0);
    assert_true(count_tag(w, SPN_THREAD_RADIUS, 0) > 0); /* the radii stay */
    spn_target_destroy(t);
    spn_world_destroy(w);
}

/* A thread, as its end positions (ordered) and tag, to compare webs before and after. */
typedef struct thread_key {
    double v[6];
    uint32_t tag;
} thread_key;

static int cmp_key(const void *pa, const void *pb)
{
    const thread_key *a = pa, *b = pb;
    for (int i = 0; i < 6; i++)
        if (a->v[i] != b->v[i]) return a->v[i] < b->v[i] ? -1 : 1;
    return (a->tag > b->tag) - (a->tag < b->tag);
}

static thread_key *keys_of(const spn_world *w, uint32_t *n)
{
    *n = spn_world_spring_count(w);
    thread_key *k = malloc((*n + 1) * sizeof *k);
    for (uint32_t s = 0; s < *n; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        if (a.x > b.x || (a.x == b.x && a.y > b.y)) { spn_vec3 c = a; a = b; b = c; }
        thread_key key = {{a.x, a.y, a.z, b.x, b.y, b.z}, si.tag};
        k[s] = key;
    }
    qsort(k, *n, sizeof *k, cmp_key);
    return k;
}

/* Does the band of a -> b reach within the 7x7 dilation of the message? */
static bool touches_dilated(const spn_target *t, const thread_key *k)
{
    int w, h;
    const float *ink = spn_target_ink(t, &w, &h);
    double ax, ay, bx, by;
    spn_target_to_pixel(t, spn_v3(k->v[0], k->v[1], 0), &ax, &ay);
    spn_target_to_pixel(t, spn_v3(k->v[3], k->v[4], 0), &bx, &by);
    int steps = 2 + (int)hypot(bx - ax, by - ay);
    for (int i = 0; i <= steps; i++) {
        double x = ax + (bx - ax) * i / steps, y = ay + (by - ay) * i / steps;
        for (int dj = -6; dj <= 6; dj++)
            for (int di = -6; di <= 6; di++) {
                int px = (int)x + di, py = (int)y + dj;
                if (px >= 0 && py >= 0 && px < w && py < h && ink[(size_t)py * w + px] > 0) return true;
            }
    }
    return false;
}

/* Threads in one sorted list and not the other must all touch the dilated message. */
static void check_changes_local(const spn_target *t, const thread_key *a, uint32_t na, const thread_key *b,
                                uint32_t nb, uint32_t *changes)
{
    uint32_t i = 0, j = 0;
    while (i < na || j < nb) {
        int c = i == na ? 1 : j == nb ? -1 : cmp_key(&a[i], &b[j]);
        if (c == 0) { i++, j++; continue; }
        const thread_key *k = c < 0 ? &a[i++] : &b[j++];
        assert_true(touches_dilated(t, k));
        (*changes)++;
    }
}

static void test_emphasis_changes_only_the_message(void **state)
{
    (void)state;
    for (int e = 0; e < 4; e++) {
        spn_world *w = inscribe_orb();
        spn_target *t = NULL;
        assert_int_equal(spn_target_create(w, 600, &t), SPN_OK);
        spn_text_def td = spn_text_def_default();
        td.text = "PIG";
        td.fit = 0.5; /* a quarter of the area: fewer fill threads, a quicker test */
        assert_int_equal(spn_target_text(t, w, &td), SPN_OK);
        uint32_t na, nb, changes = 0;
        thread_key *before = keys_of(w, &na);
        spn_inscribe_def d = quick_def();
        d.emphasis = (spn_emphasis)e;
        spn_inscribe_report rep;
        assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
        assert_true(rep.removed > 0);
        if (e != SPN_EMPHASIS_NONE) assert_true(rep.added > 0);
        thread_key *after = keys_of(w, &nb);
        check_changes_local(t, before, na, after, nb, &changes);
        assert_true(changes >= rep.removed + rep.added);
        free(before), free(after);
        spn_target_destroy(t);
        spn_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_half_target_removes_that_half_only),
        cmocka_unit_test(test_empty_target_removes_none),
        cmocka_unit_test(test_full_target_removes_all_above_threshold),
        cmocka_unit_test(test_emphasis_changes_only_the_message),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    spn_render_release_caches(); /* cairo's and fontconfig's font caches */
    return failed;
}

/* A shot allocates everything when it is created: stepping it, through every
 * phase change, allocates nothing. The library's calls to malloc, calloc and
 * realloc are counted by link-time wrapping (-Wl,--wrap=..., set for this one
 * program in tests/CMakeLists.txt). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <spinneret/spinneret.h>

void *__real_malloc(size_t size);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t size);

static long allocations;

void *__wrap_malloc(size_t size)
{
    allocations++;
    return __real_malloc(size);
}

void *__wrap_calloc(size_t n, size_t size)
{
    allocations++;
    return __real_calloc(n, size);
}

void *__wrap_realloc(void *p, size_t size)
{
    allocations++;
    return __real_realloc(p, size);
}

static void run(double dt, int shots)
{
    spn_shot *s[8];
    spn_shot_def def = spn_shot_def_default();
    long before_create = allocations;
    for (int i = 0; i < shots; i++) {
        def.seed = (uint64_t)i + 1;
        def.target.z = i;
        assert_int_equal(spn_shot_create(&def, &s[i]), SPN_OK);
    }
    /* The counter works: creation does allocate. */
    assert_true(allocations > before_create);
    long before = allocations;
    int done = 0, frames = 0;
    spn_shot_phase seen = SPN_SHOT_THWIP;
    while (done < shots) {
        done = 0;
        for (int i = 0; i < shots; i++) {
            assert_int_equal(spn_shot_step(s[i], dt), SPN_OK);
            const spn_vec3 *p;
            (void)spn_shot_strand(s[i], &p);
            (void)spn_shot_camera_shake(s[i]);
            (void)spn_shot_character(s[i]);
            if (spn_shot_phase_now(s[i]) > seen) seen = spn_shot_phase_now(s[i]);
            done += spn_shot_phase_now(s[i]) == SPN_SHOT_DONE;
        }
        frames++;
    }
    long during = allocations - before;
    print_message("dt %g: %d shots, %d frames, %ld allocations while stepping\n", dt, shots, frames, during);
    assert_int_equal(seen, SPN_SHOT_DONE);
    assert_int_equal(during, 0);
    for (int i = 0; i < shots; i++) spn_shot_destroy(s[i]);
}

static void test_stepping_allocates_nothing(void **state)
{
    (void)state;
    run(1.0 / 60, 4);
    run(1.0 / 240, 1);
    run(0.1, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_stepping_allocates_nothing)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}

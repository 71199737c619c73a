/* See frame_fan.h. One lock guards the counters: `claimed` (the next frame
 * to draw), `turn` (the next frame to add) and the first failure. A thread
 * adds its frame when `turn` reaches it, without the lock: only the thread
 * whose frame is `turn` touches the sequence, so the other can claim and
 * draw meanwhile. Each thread also encodes its frame (compresses the PNG)
 * before its turn: only the file's write waits for the frames before it.
 * Errors are per thread (spn_last_error), so the first failure's message is
 * kept here and raised again on the caller's thread. */
#include "frame_fan.h"

#include "cli.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

typedef struct fan {
    spn_frames *frames;
    frame_fan_fn fn;
    void *user;
    spn_progress *bar;
    int count;
    size_t bytes; /* one frame */
    pthread_mutex_t lock;
    pthread_cond_t turned;
    int claimed, turn;
    spn_status failed;
    char message[1024];
} fan;

typedef struct fan_slot {
    fan *f;
    int slot;
    pthread_t thread;
} fan_slot;

int frame_fan_threads(int count)
{
#ifdef _OPENMP
    int n = omp_get_max_threads();
#else
    long online = sysconf(_SC_NPROCESSORS_ONLN);
    int n = online > 0 && online < 64 ? (int)online : 1;
#endif
    if (n > 8) n = 8;
    if (n > count) n = count;
    return n > 1 ? n : 1;
}

/* Record a failure (the lock held): the first one wins. */
static void fail(fan *f, spn_status st)
{
    if (f->failed != SPN_OK) return;
    f->failed = st;
    snprintf(f->message, sizeof f->message, "%s", spn_last_error());
}

static void *draw_frames(void *arg)
{
    const fan_slot *s = arg;
    fan *f = s->f;
    uint8_t *rgba = malloc(f->bytes);
    pthread_mutex_lock(&f->lock);
    if (!rgba) fail(f, spn_error(SPN_ERR_NOMEM, "out of memory for a frame"));
    for (;;) {
        if (f->failed != SPN_OK || f->claimed >= f->count || spn_interrupted()) break;
        const int i = f->claimed++;
        pthread_mutex_unlock(&f->lock);
        uint8_t *bytes = NULL;
        size_t size = 0;
        spn_status st = f->fn(f->user, s->slot, i, rgba);
        if (st == SPN_OK) st = spn_frames_encode(f->frames, rgba, &bytes, &size);
        pthread_mutex_lock(&f->lock);
        while (f->turn != i && f->failed == SPN_OK)
            pthread_cond_wait(&f->turned, &f->lock);
        if (st == SPN_OK && f->failed == SPN_OK) {
            pthread_mutex_unlock(&f->lock);
            st = spn_frames_add_encoded(f->frames, bytes, size);
            pthread_mutex_lock(&f->lock);
            if (st == SPN_OK) {
                f->turn++;
                spn_progress_update(f->bar, (uint64_t)f->turn);
                spn_interrupt_progress((uint64_t)f->turn, (uint64_t)f->count);
            }
        }
        if (st != SPN_OK) fail(f, st);
        pthread_cond_broadcast(&f->turned);
        free(bytes);
    }
    pthread_mutex_unlock(&f->lock);
    free(rgba);
    return NULL;
}

spn_status frame_fan_run(spn_frames *frames, int count, int threads, frame_fan_fn fn, void *user, spn_progress *bar,
                         int *added)
{
    int width, height;
    spn_frames_size(frames, &width, &height);
    fan f = {.frames = frames, .fn = fn, .user = user, .bar = bar, .count = count};
    f.bytes = (size_t)width * (size_t)height * 4;
    pthread_mutex_init(&f.lock, NULL);
    pthread_cond_init(&f.turned, NULL);
    if (threads < 1) threads = 1;
    fan_slot slots[8];
    if (threads > 8) threads = 8;
    int started = 1; /* helpers: stop signals reach this thread, whose handler sets the flag all poll */
    for (; started < threads; started++) {
        slots[started] = (fan_slot){&f, started, 0};
        if (cli_start_helper(&slots[started].thread, draw_frames, &slots[started]) != 0) break;
    }
    slots[0] = (fan_slot){&f, 0, 0};
    draw_frames(&slots[0]); /* with fewer helpers than asked, the ones started share the work */
    for (int t = 1; t < started; t++)
        pthread_join(slots[t].thread, NULL);
    pthread_cond_destroy(&f.turned);
    pthread_mutex_destroy(&f.lock);
    *added = f.turn;
    return f.failed == SPN_OK ? SPN_OK : spn_error(f.failed, "%s", f.message);
}

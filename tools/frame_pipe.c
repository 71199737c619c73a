/* See frame_pipe.h. Each drawing thread is a slot: its world copy, its
 * picture and, while `busy`, the frame it draws and that frame's place in
 * the order of hand-overs (`seq`). The main thread refills an idle slot's
 * world (spn_world_copy_into: no new memory once the sizes are reached; a
 * fresh clone of a 1M-particle web took about a second, most of it on new
 * pages), or hands over no world, and marks it busy; the slot's thread
 * draws and encodes, then waits
 * until `turn` reaches its `seq` to add the frame, so frames go out in the
 * order they came in. Every slot takes its turn even after a failure (it
 * then adds nothing), so the turns never stall. Errors are per thread
 * (spn_last_error): the first failure's status and message are kept and
 * raised again on the main thread. */
#include "frame_pipe.h"

#include "cli.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

typedef struct pipe_slot {
    frame_pipe *p;
    int index;
    pthread_t thread;
    spn_world *world; /* this slot's copy */
    const spn_world *drawn; /* the frame's world: the copy, or NULL */
    uint8_t *rgba;
    int frame;
    long seq;
    bool busy;
} pipe_slot;

struct frame_pipe {
    spn_frames *frames;
    frame_pipe_fn fn;
    void *user;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    pipe_slot slot[FRAME_PIPE_MAX_THREADS];
    int nslots;
    long pushed, turn;
    int added, total;
    spn_progress *bar;
    bool quit;
    spn_status failed;
    char message[1024];
};

/* The first failure wins (the lock held). */
static void fail(frame_pipe *p, spn_status st)
{
    if (p->failed != SPN_OK) return;
    p->failed = st;
    snprintf(p->message, sizeof p->message, "%s", spn_last_error());
}

/* Draw and encode the slot's frame (none after a failure); NULL bytes then. */
static spn_status draw(pipe_slot *s, bool skip, uint8_t **bytes, size_t *size)
{
    frame_pipe *p = s->p;
    *bytes = NULL, *size = 0;
    if (skip) return SPN_OK;
    spn_status st = p->fn(p->user, s->index, s->frame, s->drawn, s->rgba);
    return st == SPN_OK ? spn_frames_encode(p->frames, s->rgba, bytes, size) : st;
}

static void *worker(void *arg)
{
    pipe_slot *s = arg;
    frame_pipe *p = s->p;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!s->busy && !p->quit) pthread_cond_wait(&p->changed, &p->lock);
        if (!s->busy) break;
        const bool skip = p->failed != SPN_OK;
        pthread_mutex_unlock(&p->lock);
        uint8_t *bytes;
        size_t size;
        spn_status st = draw(s, skip, &bytes, &size);
        pthread_mutex_lock(&p->lock);
        while (p->turn != s->seq) pthread_cond_wait(&p->changed, &p->lock);
        if (st == SPN_OK && bytes && p->failed == SPN_OK) {
            pthread_mutex_unlock(&p->lock); /* only the turn's holder touches the sequence */
            st = spn_frames_add_encoded(p->frames, bytes, size);
            pthread_mutex_lock(&p->lock);
            if (st == SPN_OK) {
                p->added++;
                spn_progress_update(p->bar, (uint64_t)p->added);
                if (p->total > 0) spn_interrupt_progress((uint64_t)p->added, (uint64_t)p->total);
            }
        }
        if (st != SPN_OK) fail(p, st);
        free(bytes);
        p->turn++;
        s->busy = false; /* the world stays until the next hand-over refills it */
        pthread_cond_broadcast(&p->changed);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

int frame_pipe_threads(int count)
{
#ifdef _OPENMP
    int n = omp_get_max_threads();
#else
    long online = sysconf(_SC_NPROCESSORS_ONLN);
    int n = online > 0 && online < 64 ? (int)online : 1;
#endif
    if (n > FRAME_PIPE_MAX_THREADS) n = FRAME_PIPE_MAX_THREADS;
    if (n > count) n = count;
    return n > 1 ? n : 1;
}

spn_status frame_pipe_open(frame_pipe **pipe, spn_frames *frames, int threads, frame_pipe_fn fn, void *user)
{
    *pipe = NULL;
    frame_pipe *p = calloc(1, sizeof *p);
    if (!p) return spn_error(SPN_ERR_NOMEM, "out of memory");
    p->frames = frames, p->fn = fn, p->user = user;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->changed, NULL);
    int width, height;
    spn_frames_size(frames, &width, &height);
    if (threads < 1) threads = 1;
    if (threads > FRAME_PIPE_MAX_THREADS) threads = FRAME_PIPE_MAX_THREADS;
    for (; p->nslots < threads; p->nslots++) {
        pipe_slot *s = &p->slot[p->nslots];
        s->p = p, s->index = p->nslots;
        if (!(s->rgba = malloc((size_t)width * height * 4))) break;
        /* stop signals reach the main thread, whose handler stops the run
         * between steps, and never interrupt a frame's write half way */
        if (cli_start_helper(&s->thread, worker, s) != 0) {
            free(s->rgba);
            break;
        }
    }
    if (p->nslots == 0) {
        frame_pipe_close(p, NULL);
        return spn_error(SPN_ERR_NOMEM, "cannot start a frame-drawing thread");
    }
    *pipe = p;
    return SPN_OK;
}

void frame_pipe_report(frame_pipe *p, spn_progress *bar, int total)
{
    p->bar = bar, p->total = total;
}

spn_status frame_pipe_push(frame_pipe *p, int frame, const spn_world *w)
{
    pthread_mutex_lock(&p->lock);
    pipe_slot *s = NULL;
    while (p->failed == SPN_OK && !s) {
        for (int i = 0; i < p->nslots && !s; i++)
            if (!p->slot[i].busy) s = &p->slot[i];
        if (!s) pthread_cond_wait(&p->changed, &p->lock);
    }
    spn_status st = p->failed;
    pthread_mutex_unlock(&p->lock);
    if (st != SPN_OK) return spn_error(st, "%s", p->message);
    /* an idle slot's world is the main thread's alone */
    if (w && s->world) st = spn_world_copy_into(s->world, w);
    else if (w && !(s->world = spn_world_clone(w)))
        st = spn_error(SPN_ERR_NOMEM, "out of memory copying the world for frame %d", frame);
    if (st != SPN_OK) return st;
    s->drawn = w ? s->world : NULL;
    pthread_mutex_lock(&p->lock);
    s->frame = frame, s->seq = p->pushed++, s->busy = true;
    pthread_cond_broadcast(&p->changed);
    pthread_mutex_unlock(&p->lock);
    return SPN_OK;
}

spn_status frame_pipe_close(frame_pipe *p, int *added)
{
    if (added) *added = 0;
    if (!p) return SPN_OK;
    pthread_mutex_lock(&p->lock);
    while (p->turn != p->pushed) pthread_cond_wait(&p->changed, &p->lock);
    spn_status st = p->failed;
    p->quit = true;
    pthread_cond_broadcast(&p->changed);
    pthread_mutex_unlock(&p->lock);
    for (int i = 0; i < p->nslots; i++) {
        pthread_join(p->slot[i].thread, NULL);
        spn_world_destroy(p->slot[i].world);
        free(p->slot[i].rgba);
    }
    if (st != SPN_OK) spn_error(st, "%s", p->message);
    if (added) *added = p->added;
    pthread_cond_destroy(&p->changed);
    pthread_mutex_destroy(&p->lock);
    free(p);
    return st;
}

spn_status frame_pipe_run(spn_frames *frames, int count, frame_pipe_fn fn, void *user, spn_progress *bar,
                          int *added)
{
    *added = 0;
    frame_pipe *pipe;
    spn_status st = frame_pipe_open(&pipe, frames, frame_pipe_threads(count), fn, user);
    if (st != SPN_OK) return st;
    frame_pipe_report(pipe, bar, count);
    for (int i = 0; i < count && st == SPN_OK && !spn_interrupted(); i++) st = frame_pipe_push(pipe, i, NULL);
    spn_status closed = frame_pipe_close(pipe, added);
    return st == SPN_OK ? closed : st;
}

/* See frame_pipe.h. One worker thread, one slot: `job` is the world copy
 * being drawn (or waiting to be), `busy` while it is. Two copies take turns:
 * the main thread refills `spare` (spn_world_copy_into, no new memory once
 * the sizes are reached: a fresh clone of a 1M-particle web took about a
 * second, most of it on new pages) while the worker draws the other. Errors
 * are per thread (spn_last_error), so the worker keeps the first failure's
 * status and message, and the main thread raises them again as its own. */
#include "frame_pipe.h"

#include "cli.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

struct frame_pipe {
    frame_pipe_fn fn;
    void *user;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    spn_world *job, *spare;
    int job_frame;
    bool busy, quit;
    spn_status failed;
    char message[1024];
};

static void *worker(void *arg)
{
    frame_pipe *p = arg;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->busy && !p->quit) pthread_cond_wait(&p->changed, &p->lock);
        if (!p->busy) break;
        spn_world *w = p->job;
        int frame = p->job_frame;
        bool skip = p->failed != SPN_OK;
        pthread_mutex_unlock(&p->lock);
        spn_status st = skip ? SPN_OK : p->fn(p->user, frame, w);
        pthread_mutex_lock(&p->lock);
        if (st != SPN_OK && p->failed == SPN_OK) {
            p->failed = st;
            snprintf(p->message, sizeof p->message, "%s", spn_last_error());
        }
        p->busy = false; /* `job` stays until the next hand-over swaps it for the spare */
        pthread_cond_broadcast(&p->changed);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

spn_status frame_pipe_open(frame_pipe **pipe, frame_pipe_fn fn, void *user)
{
    *pipe = NULL;
    frame_pipe *p = calloc(1, sizeof *p);
    if (!p) return spn_error(SPN_ERR_NOMEM, "out of memory");
    p->fn = fn;
    p->user = user;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->changed, NULL);
    /* Stop signals reach the main thread, whose handler stops the run
     * between steps, and never interrupt a frame's write half way. */
    int started = cli_start_helper(&p->thread, worker, p);
    if (started != 0) {
        pthread_cond_destroy(&p->changed);
        pthread_mutex_destroy(&p->lock);
        free(p);
        return spn_error(SPN_ERR_NOMEM, "cannot start the frame-writing thread");
    }
    *pipe = p;
    return SPN_OK;
}

/* Wait until no frame is in flight (the lock held); the failure so far. */
static spn_status drain(frame_pipe *p)
{
    while (p->busy) pthread_cond_wait(&p->changed, &p->lock);
    return p->failed;
}

spn_status frame_pipe_push(frame_pipe *p, int frame, const spn_world *w)
{
    /* `spare` is the main thread's alone: the worker only reads `job` */
    spn_status st = SPN_OK;
    if (p->spare) st = spn_world_copy_into(p->spare, w);
    else if (!(p->spare = spn_world_clone(w))) st = spn_error(SPN_ERR_NOMEM, "out of memory copying the world for frame %d", frame);
    if (st != SPN_OK) return st;
    pthread_mutex_lock(&p->lock);
    st = drain(p);
    if (st == SPN_OK) {
        spn_world *drawn = p->job;
        p->job = p->spare;
        p->spare = drawn;
        p->job_frame = frame;
        p->busy = true;
        pthread_cond_broadcast(&p->changed);
    }
    pthread_mutex_unlock(&p->lock);
    return st == SPN_OK ? SPN_OK : spn_error(st, "%s", p->message);
}

spn_status frame_pipe_close(frame_pipe *p)
{
    if (!p) return SPN_OK;
    pthread_mutex_lock(&p->lock);
    spn_status st = drain(p);
    p->quit = true;
    pthread_cond_broadcast(&p->changed);
    pthread_mutex_unlock(&p->lock);
    pthread_join(p->thread, NULL);
    if (st != SPN_OK) spn_error(st, "%s", p->message);
    spn_world_destroy(p->job);
    spn_world_destroy(p->spare);
    pthread_cond_destroy(&p->changed);
    pthread_mutex_destroy(&p->lock);
    free(p);
    return st;
}

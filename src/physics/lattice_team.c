/* A team of threads kept for the whole of one spn_world_advance call on the
 * lattice path: its parallel work (blocked passes, single-step sweeps, the
 * state's load and write-back) goes to the team as jobs instead of opening
 * an OpenMP parallel region each time.
 *
 * Why. A blocked pass of the 5k web is 40-60 us of work on two threads. As
 * a parallel region of its own it paid three hand-overs a pass (the fork,
 * the barrier between the ghost copies and the fronts, the join), and
 * libgomp makes each a futex system call: about 1 us each on the Zen 5 VM
 * (rdtsc around each part, forty-fourth session), some 8% of a pass.
 * Here one OpenMP region spans the call: its thread 0 (the master) runs
 * the steps and posts each piece of parallel work as a job; the others
 * wait for a job, run their share, and count themselves done; the master
 * runs share 0 and waits for the count. Hand-overs are an atomic counter
 * each, read by the waiting side.
 *
 * Waiting. A thread waiting spins (with a pause) for a while, then yields
 * its core: a waiting worker, after yielding for a while longer, sleeps on
 * a condition variable until the next job is posted. So the wait between
 * two passes (a few microseconds of bookkeeping on the master) costs
 * nothing but a spinning core, while a call that the governor keeps on one
 * thread (lattice.c, a busy machine) leaves the other core free after a
 * fraction of a millisecond.
 *
 * Outside a team (spn_world_step, a call the governor keeps on one thread
 * at its start, or threads the team does not have) a job runs in an OpenMP
 * region of its own, as before. Either way a job is two phases, `first`
 * for every share, then `then` for every share, with a barrier between
 * them; the shares of a phase may run in any order on any thread, so the
 * results cannot depend on which thread ran what. */
#include "lattice_rows.h"
#include "world_internal.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

/* Pause-spins before a waiting thread yields, and yields before a worker
 * with no job sleeps (each a few tens of nanoseconds and about a
 * microsecond: some 0.1 ms of spinning, then about 0.1 ms of yielding).
 * Tests set them lower (spn__lat_team_set_patience), between calls. */
static int team_spins = 4096, team_yields = 128;

void spn__lat_team_set_patience(int spins, int yields)
{
    team_spins = spins >= 0 ? spins : 4096;
    team_yields = yields >= 0 ? yields : 128;
}

typedef struct spn__lat_team {
    int size;                    /* threads: the master (0) and size - 1 workers */
    _Atomic unsigned posted;     /* jobs posted (a worker runs each once) */
    _Atomic int left;            /* workers not yet done with the current job */
    _Atomic unsigned phase_gen;  /* the current job's barrier passed (its count) */
    _Atomic int phase_left;      /* threads not yet at the current job's barrier */
    _Atomic int sleepers;        /* workers asleep on `wake` or about to be */
    spn__lat_job first, then;    /* the job (NULL first: leave the team) */
    void *ctx;
    int shares;
    pthread_mutex_t mu;
    pthread_cond_t wake;
} spn__lat_team;

static inline void pause_once(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ volatile("yield");
#endif
}

/* Until *a != old: spin, then yield. */
static unsigned wait_change(_Atomic unsigned *a, unsigned old)
{
    unsigned now;
    for (int i = 0; (now = atomic_load_explicit(a, memory_order_acquire)) == old; i++) {
        if (i < team_spins) pause_once();
        else sched_yield();
    }
    return now;
}

/* Until *a == 0: spin, then yield. */
static void wait_zero(_Atomic int *a)
{
    for (int i = 0; atomic_load_explicit(a, memory_order_acquire) != 0; i++) {
        if (i < team_spins) pause_once();
        else sched_yield();
    }
}

/* Shares [lo, hi) of `shares` for thread t of n. */
static void share_range(int shares, int t, int n, int *lo, int *hi)
{
    *lo = (int)((long long)shares * t / n), *hi = (int)((long long)shares * (t + 1) / n);
}

/* Thread t's part of the current job: its shares of the first phase, the
 * barrier, its shares of the second. */
static void team_part(spn__lat_team *T, int t)
{
    int lo, hi;
    share_range(T->shares, t, T->size, &lo, &hi);
    for (int s = lo; s < hi; s++) T->first(T->ctx, s, t);
    if (!T->then) return;
    const unsigned gen = atomic_load_explicit(&T->phase_gen, memory_order_acquire);
    if (atomic_fetch_sub_explicit(&T->phase_left, 1, memory_order_acq_rel) == 1) {
        atomic_store_explicit(&T->phase_left, T->size, memory_order_relaxed);
        atomic_store_explicit(&T->phase_gen, gen + 1, memory_order_release);
    } else {
        wait_change(&T->phase_gen, gen);
    }
    for (int s = lo; s < hi; s++) T->then(T->ctx, s, t);
}

/* A worker: each job posted, until the master posts none. */
static void serve(spn__lat_team *T, int t)
{
    unsigned seen = 0;
    for (;;) {
        unsigned now;
        int i = 0;
        while ((now = atomic_load_explicit(&T->posted, memory_order_acquire)) == seen) {
            if (i < team_spins) {
                pause_once(), i++;
            } else if (i < team_spins + team_yields) {
                sched_yield(), i++;
            } else {
                /* asleep until a post: the master reads sleepers after it
                 * posts, this thread reads posted after counting itself in
                 * (both sequentially consistent), so one of the two sees
                 * the other; the check under the mutex closes the gap to
                 * pthread_cond_wait */
                atomic_fetch_add(&T->sleepers, 1);
                pthread_mutex_lock(&T->mu);
                while (atomic_load(&T->posted) == seen) pthread_cond_wait(&T->wake, &T->mu);
                pthread_mutex_unlock(&T->mu);
                atomic_fetch_sub(&T->sleepers, 1);
                i = 0;
            }
        }
        seen = now;
        if (!T->first) return;
        team_part(T, t);
        atomic_fetch_sub_explicit(&T->left, 1, memory_order_release);
    }
}

/* Post a job (first NULL: the end of the team) and run the master's part. */
static void post(spn__lat_team *T, spn__lat_job first, spn__lat_job then, void *ctx, int shares)
{
    T->first = first, T->then = then, T->ctx = ctx, T->shares = shares;
    atomic_store_explicit(&T->left, T->size - 1, memory_order_relaxed);
    atomic_store_explicit(&T->phase_left, T->size, memory_order_relaxed);
    atomic_fetch_add(&T->posted, 1);
    if (atomic_load(&T->sleepers) > 0) {
        pthread_mutex_lock(&T->mu);
        pthread_cond_broadcast(&T->wake);
        pthread_mutex_unlock(&T->mu);
    }
    if (!first) return;
    team_part(T, 0);
    wait_zero(&T->left);
}

void spn__lat_run(const spn__lattice *L, int threads, int shares, spn__lat_job first, spn__lat_job then, void *ctx)
{
    spn__lat_team *T = L->team;
    if (threads > shares) threads = shares;
    if (threads <= 1) {
        for (int s = 0; s < shares; s++) first(ctx, s, 0);
        if (then)
            for (int s = 0; s < shares; s++) then(ctx, s, 0);
        return;
    }
    if (T && T->size == threads) {
        post(T, first, then, ctx, shares);
        return;
    }
#pragma omp parallel num_threads(threads)
    {
        const int t = spn__thread_num();
        int lo, hi;
        share_range(shares, t, spn__thread_count(), &lo, &hi);
        for (int s = lo; s < hi; s++) first(ctx, s, t);
        if (then) {
#pragma omp barrier
            for (int s = lo; s < hi; s++) then(ctx, s, t);
        }
    }
}

/* A loop over [0, count) in contiguous chunks, one share each. */
typedef struct {
    void (*body)(void *ctx, size_t lo, size_t hi);
    void *ctx;
    size_t count;
    int shares;
} for_job;

static void for_share(void *p, int s, int thread)
{
    (void)thread;
    const for_job *f = p;
    const size_t lo = f->count * (size_t)s / (size_t)f->shares, hi = f->count * ((size_t)s + 1) / (size_t)f->shares;
    if (lo < hi) f->body(f->ctx, lo, hi);
}

void spn__lat_for(const spn__lattice *L, int threads, size_t count, void (*body)(void *ctx, size_t lo, size_t hi),
                  void *ctx)
{
    if (threads < 1) threads = 1;
    for_job f = {body, ctx, count, threads};
    spn__lat_run(L, threads, threads, for_share, NULL, &f);
}

spn_status spn__lattice_team_call(spn_world *w, int threads, spn_status (*body)(spn_world *, void *), void *ctx)
{
    spn__lattice *L = w->lat;
    if (threads < 2 || L->team) return body(w, ctx);
    spn__lat_team T;
    memset(&T, 0, sizeof T);
    if (pthread_mutex_init(&T.mu, NULL)) return body(w, ctx);
    if (pthread_cond_init(&T.wake, NULL)) {
        pthread_mutex_destroy(&T.mu);
        return body(w, ctx);
    }
    spn_status st = SPN_OK;
#pragma omp parallel num_threads(threads)
    {
        const int t = spn__thread_num();
        /* (no barrier here: a worker reads size only after a post) */
        if (t == 0) {
            T.size = spn__thread_count();
            if (T.size > 1) L->team = &T;
            st = body(w, ctx);
            if (w->lat) w->lat->team = NULL; /* (w->lat again: a replayable run keeps its lattice, but in case) */
            if (T.size > 1) post(&T, NULL, NULL, NULL, 0);
        } else {
            serve(&T, t);
        }
    }
    pthread_cond_destroy(&T.wake);
    pthread_mutex_destroy(&T.mu);
    return st;
}

int spn__lattice_team_size(const spn_world *w) { return w->lat && w->lat->team ? w->lat->team->size : 0; }

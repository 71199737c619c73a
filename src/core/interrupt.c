/* SIGINT/SIGTERM handling for long commands (see interrupt.h).
 *
 * The handler may only do async-signal-safe things: it reads fixed slots of
 * temporary paths and unlinks them, formats numbers by hand into a stack
 * buffer, write()s one line and _exit()s. The slots are lock-free atomic
 * pointers: a thread takes a free one by compare-and-swap (`animate` writes
 * frames on a second thread while the main one may save states), the
 * handler loads them, and a slot is cleared before its string is freed. */
#define _POSIX_C_SOURCE 200809L
#include "spinneret/interrupt.h"

#include "core_internal.h"

#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

enum { TEMP_SLOTS = 64 };

static _Atomic(const char *) temps[TEMP_SLOTS];
_Static_assert(ATOMIC_POINTER_LOCK_FREE == 2, "the signal handler reads the slots: they must be lock-free");
static volatile sig_atomic_t graceful, caught;
static volatile uint64_t progress_done, progress_total;
static char label[64] = "spinneret", unit[32] = "steps";

void spn__temp_track(const char *tmp_path)
{
    for (int i = 0; i < TEMP_SLOTS; i++) {
        const char *empty = NULL;
        if (atomic_compare_exchange_strong(&temps[i], &empty, tmp_path)) return;
    }
    /* More than 64 outputs open at once: the extra ones are not cleaned up
     * by a signal (they are still removed by abort and never renamed). */
}

void spn__temp_untrack(const char *tmp_path)
{
    for (int i = 0; i < TEMP_SLOTS; i++) {
        const char *mine = tmp_path;
        atomic_compare_exchange_strong(&temps[i], &mine, NULL);
    }
}

const char *spn_signal_name(int sig)
{
    static char other[24];
    if (sig == SIGINT) return "SIGINT";
    if (sig == SIGTERM) return "SIGTERM";
    snprintf(other, sizeof other, "signal %d", sig);
    return other;
}

/* Appends `s` to buf at *n (async-signal-safe). */
static void put(char *buf, size_t *n, size_t cap, const char *s)
{
    while (*s && *n + 1 < cap) buf[(*n)++] = *s++;
}

static void put_number(char *buf, size_t *n, size_t cap, uint64_t v)
{
    char digits[24];
    int k = 0;
    do digits[k++] = (char)('0' + v % 10);
    while ((v /= 10) && k < 23);
    while (k > 0 && *n + 1 < cap) buf[(*n)++] = digits[--k];
}

static void die(int sig)
{
    for (int i = 0; i < TEMP_SLOTS; i++) {
        const char *path = atomic_load(&temps[i]);
        if (path) unlink(path);
    }
    char line[256];
    size_t n = 0;
    put(line, &n, sizeof line, label);
    put(line, &n, sizeof line, sig == SIGINT ? ": interrupted (SIGINT)" : ": interrupted (SIGTERM)");
    uint64_t done = progress_done, total = progress_total;
    if (total > 0) {
        put(line, &n, sizeof line, " after ");
        put_number(line, &n, sizeof line, done);
        put(line, &n, sizeof line, " of ");
        put_number(line, &n, sizeof line, total);
        put(line, &n, sizeof line, " ");
        put(line, &n, sizeof line, unit);
    }
    put(line, &n, sizeof line, "; finished outputs kept, the unfinished one removed\n");
    ssize_t w = write(2, line, n);
    (void)w;
    _exit(128 + sig);
}

static void handler(int sig)
{
    if (sig == SIGALRM) die(caught ? caught : SIGTERM); /* the frame in progress took too long */
    if (graceful && !caught) {
        caught = sig;
        /* A loop stuck inside one frame would never poll: `timeout` and
         * service managers send one SIGTERM, which must still end us. */
        alarm(SPN_INTERRUPT_GRACE_SECONDS);
        return;
    }
    die(sig);
}

void spn_interrupt_catch(const char *what, const char *units)
{
    snprintf(label, sizeof label, "%s", what ? what : "spinneret");
    snprintf(unit, sizeof unit, "%s", units ? units : "steps");
    caught = 0;
    graceful = 0;
    progress_done = progress_total = 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGALRM, &sa, NULL);
}

void spn_interrupt_release(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = SIG_DFL;
    sigemptyset(&sa.sa_mask);
    alarm(0);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGALRM, &sa, NULL);
    caught = 0;
    graceful = 0;
}

void spn_interrupt_graceful(bool on)
{
    graceful = on;
}

int spn_interrupted(void)
{
    return caught;
}

void spn_interrupt_progress(uint64_t done, uint64_t total)
{
    progress_done = done;
    progress_total = total;
}

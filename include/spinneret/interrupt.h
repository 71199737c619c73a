/* Interrupting a long command (SIGINT, SIGTERM) without losing work or
 * leaving debris.
 *
 * spn_interrupt_catch() installs the handlers. By default a signal removes
 * every temporary output still open (spn_atomic_open ... commit), prints one
 * line saying how far the command got, and exits with 128 + the signal: the
 * outputs already committed stay, the one being written never appears, and an
 * older file of the same name is not touched.
 *
 * A loop that can stop cleanly between frames turns on graceful mode: a
 * signal then only sets a flag, the loop polls spn_interrupted(), finishes the
 * frame it is on, commits what is complete and says so. A second signal exits
 * at once as above, and so does a frame that has not finished
 * SPN_INTERRUPT_GRACE_SECONDS after the first (a single SIGTERM, as sent by
 * `timeout` or a service manager, always ends the program). */
#ifndef SPINNERET_INTERRUPT_H
#define SPINNERET_INTERRUPT_H

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

/// How long a graceful stop waits for the frame in progress [s].
#define SPN_INTERRUPT_GRACE_SECONDS 10

/// Catch SIGINT and SIGTERM (and SIGALRM, for the grace period). `label` starts the message ("spinneret render"),
/// `unit` names what progress counts ("frames", "steps"); both are copied.
SPN_API void spn_interrupt_catch(const char *label, const char *unit);
/// Restore the default handlers and clear the flag.
SPN_API void spn_interrupt_release(void);
/// Graceful mode on or off (see above).
SPN_API void spn_interrupt_graceful(bool on);
/// The signal that arrived (SIGINT, SIGTERM) in graceful mode, or 0.
SPN_API int spn_interrupted(void);
/// How far the command is, for the message: `done` of `total` units.
SPN_API void spn_interrupt_progress(uint64_t done, uint64_t total);
/// "SIGINT", "SIGTERM" or "signal N".
SPN_API const char *spn_signal_name(int sig);

#ifdef __cplusplus
}
#endif

#endif

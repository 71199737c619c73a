/* Independent frames drawn on several threads and added in order.
 *
 * `spinneret render --turntable` and `spinneret build --frames` draw frames
 * that do not depend on each other (a camera moving round a still web, the
 * construction at fractions of its length). One after the other, each frame
 * was drawn and then compressed while the other core stood idle. Here each
 * thread claims the next frame number, draws it into its own buffer,
 * encodes it (spn_frames_encode: a folder's PNG compressed in memory) and
 * waits for its turn to add it to the sequence (spn_frames_add_encoded), so
 * the file names, the video's order and every byte are what one thread
 * gives.
 *
 * Frames are claimed in order and every claimed frame is finished, so when
 * a stop signal (spn_interrupted) or a failure ends the run the frames
 * added are frames 0 .. added - 1, with no gap. A failure's status and
 * message are the first failing frame's. */
#ifndef SPN_FRAME_FAN_H
#define SPN_FRAME_FAN_H

#include <spinneret/spinneret.h>

/* Draw frame `frame` into `rgba` (the sequence's width x height x 4 bytes).
 * `slot` (0 .. threads - 1) names the calling thread, for state a drawer
 * keeps per thread; slot 0 is the caller's own thread. */
typedef spn_status (*frame_fan_fn)(void *user, int slot, int frame, uint8_t *rgba);

/* The threads frame_fan_run uses for `count` frames: OpenMP's thread count
 * (OMP_NUM_THREADS), else the processors online, at most 8 and at most
 * `count`. A drawer that keeps state per slot sizes it by this. */
int frame_fan_threads(int count);

/* Frames 0 .. count - 1 of `frames`, drawn by fn on `threads` threads
 * (1: all on the caller's thread) and added in order; `bar` (may be NULL)
 * and spn_interrupt_progress follow the frames added. *added: how many
 * were added. The first failure, else SPN_OK (also when stopped). */
spn_status frame_fan_run(spn_frames *frames, int count, int threads, frame_fan_fn fn, void *user, spn_progress *bar,
                         int *added);

#endif

/* Frames drawn on other threads and added in order.
 *
 * `spinneret animate` spent as long drawing and compressing a frame of a
 * species web (30 + 12 ms at 1200 x 1200) as stepping it through a frame, one
 * after the other; with the pipe the next frame's steps run while the last
 * frames are drawn. Each frame is drawn from a copy of the world taken when
 * it is handed over (each drawing thread has its copy, refilled by
 * spn_world_copy_into), so the pictures are the same bits as drawing in
 * turn. Frames that need no world handed over (a turntable's camera round a
 * still web, the construction at fractions of its length, a recorded shot)
 * go through frame_pipe_run. With several drawing threads, frames are drawn
 * side by side; each is encoded on its thread (spn_frames_encode: a
 * folder's PNG compressed in memory) and added in the order handed over
 * (spn_frames_add_encoded), so names, order and bytes are what one thread
 * gives. Handing over waits for a free thread. A frame that fails is
 * reported by the next hand-over or by the close, with its own message; no
 * frame after it is added. */
#ifndef SPN_FRAME_PIPE_H
#define SPN_FRAME_PIPE_H

#include <spinneret/spinneret.h>

/* The most drawing threads a pipe has. */
#define FRAME_PIPE_MAX_THREADS 8

typedef struct frame_pipe frame_pipe;
/* Draws frame `frame` into `rgba` (the sequence's width x height x 4 bytes)
 * on drawing thread `slot` (0 .. threads - 1, for state a drawer keeps per
 * thread): of world `w`, the copy handed over, or NULL when none was. */
typedef spn_status (*frame_pipe_fn)(void *user, int slot, int frame, const spn_world *w, uint8_t *rgba);

/* The drawing threads for `count` frames: OpenMP's thread count
 * (OMP_NUM_THREADS), else the processors online, at most
 * FRAME_PIPE_MAX_THREADS and at most `count`, at least 1. A drawer that
 * keeps state per slot sizes it by this. */
int frame_pipe_threads(int count);

/* A pipe into `frames` with `threads` drawing threads (1..FRAME_PIPE_MAX_THREADS). */
spn_status frame_pipe_open(frame_pipe **pipe, spn_frames *frames, int threads, frame_pipe_fn fn, void *user);
/* Follow the frames added with `bar` (may be NULL) and spn_interrupt_progress
 * (of `total`). */
void frame_pipe_report(frame_pipe *pipe, spn_progress *bar, int total);
/* Hand over frame `frame`: a copy of `w`, or no world (NULL); fails with an
 * earlier frame's error, or when the copy cannot be made. */
spn_status frame_pipe_push(frame_pipe *pipe, int frame, const spn_world *w);
/* Wait for the frames in flight and stop the threads; the first error, if
 * any; *added (may be NULL): the frames added. NULL-safe. */
spn_status frame_pipe_close(frame_pipe *pipe, int *added);

/* Frames 0 .. count - 1, none with a world, on frame_pipe_threads(count)
 * threads, until one fails or a stop signal (spn_interrupted) arrives: the
 * frames handed over are all finished, so the ones added are 0 .. *added - 1
 * with no gap. */
spn_status frame_pipe_run(spn_frames *frames, int count, frame_pipe_fn fn, void *user, spn_progress *bar,
                          int *added);

#endif

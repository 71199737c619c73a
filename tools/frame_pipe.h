/* Frames drawn and written on other threads while the simulation goes on.
 * `spinneret animate` spent as long drawing and compressing a frame of a
 * species web (30 + 12 ms at 1200 x 1200) as stepping it through a frame, one
 * after the other; with the pipe the next frame's steps run while the last
 * frames are drawn. Each frame is drawn from a copy of the world taken when
 * it is handed over (each drawing thread has its copy, refilled by
 * spn_world_copy_into), so the pictures are the same bits as drawing in
 * turn. With several drawing threads, frames that are dearer to draw than
 * to step (dew, a photograph behind the web, a web at rest) are drawn
 * side by side; each is encoded on its thread (spn_frames_encode) and added
 * in the order handed over (spn_frames_add_encoded). Handing over waits
 * for a free thread. A frame that fails is reported by the next hand-over
 * or by the close, with its own message; no frame after it is added. */
#ifndef SPN_FRAME_PIPE_H
#define SPN_FRAME_PIPE_H

#include <spinneret/spinneret.h>

typedef struct frame_pipe frame_pipe;
/* Draws frame `frame` of world `w` into `rgba` (the sequence's width x
 * height x 4 bytes), on drawing thread `slot`. */
typedef spn_status (*frame_pipe_fn)(void *user, int slot, int frame, const spn_world *w, uint8_t *rgba);

/* A pipe into `frames` with `threads` drawing threads (1..8). */
spn_status frame_pipe_open(frame_pipe **pipe, spn_frames *frames, int threads, frame_pipe_fn fn, void *user);
/* Copy `w` and hand it over as frame `frame`; fails with an earlier frame's
 * error, or when the copy cannot be made. */
spn_status frame_pipe_push(frame_pipe *pipe, int frame, const spn_world *w);
/* Wait for the frames in flight and stop the threads; the first error, if
 * any. NULL-safe. */
spn_status frame_pipe_close(frame_pipe *pipe);

#endif

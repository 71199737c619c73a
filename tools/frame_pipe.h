/* Frames drawn and written on a second thread while the simulation goes on.
 * `spinneret animate` spent as long drawing and compressing a frame of a
 * species web (30 + 12 ms at 1200 x 1200) as stepping it through a frame, one
 * after the other; with the pipe the next frame's steps run while the last
 * frame is drawn. Each frame is drawn from a copy of the world taken when
 * it is handed over (two copies take turns, refilled by spn_world_copy_into),
 * so the pictures are the same bits as drawing in turn. One frame is in flight at a time: handing
 * over the next waits for the one before. A frame that fails is reported by
 * the next hand-over or by the close, with its own message. */
#ifndef SPN_FRAME_PIPE_H
#define SPN_FRAME_PIPE_H

#include <spinneret/spinneret.h>

typedef struct frame_pipe frame_pipe;
/* Draws and writes frame `frame` of world `w` (on the pipe's thread). */
typedef spn_status (*frame_pipe_fn)(void *user, int frame, const spn_world *w);

spn_status frame_pipe_open(frame_pipe **pipe, frame_pipe_fn fn, void *user);
/* Copy `w` and hand it over as frame `frame`; fails with an earlier frame's
 * error, or when the copy cannot be made. */
spn_status frame_pipe_push(frame_pipe *pipe, int frame, const spn_world *w);
/* Wait for the frame in flight and stop the thread; its error, if any. NULL-safe. */
spn_status frame_pipe_close(frame_pipe *pipe);

#endif

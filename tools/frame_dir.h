/* Frame folders for `drop` and `film`: DIR/frame_00000.EXT, ... Each frame is
 * written atomically; when a run fails, the frames it wrote (and the folder,
 * if the run made it) are removed, so a failed run leaves nothing behind. */
#ifndef SPN_FRAME_DIR_H
#define SPN_FRAME_DIR_H

#include <spinneret/spinneret.h>

typedef struct frame_dir {
    const char *path;
    const char *ext; /* "obj", "pov" */
    bool created;
    int count;       /* frames written */
    char name[4200];
} frame_dir;

/* Use `path` as the folder (created when missing); false with a message. */
bool frame_dir_open(frame_dir *d, const char *cmd, const char *path, const char *ext);
/* The path of frame i (valid until the next call). */
const char *frame_dir_frame(frame_dir *d, int i, const char *ext);
/* Write frame number d->count through `write` and count it. */
spn_status frame_dir_write(frame_dir *d, spn_status (*write)(void *ctx, spn_sink *sink), void *ctx);
/* Remove what this run wrote: frames (with any .png beside them) and the folder if made here. */
void frame_dir_discard(frame_dir *d);

#endif

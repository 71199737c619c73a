#include "frame_dir.h"

#include "cli.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

bool frame_dir_open(frame_dir *d, const char *cmd, const char *path, const char *ext)
{
    memset(d, 0, sizeof *d);
    d->path = path;
    d->ext = ext;
    if (strlen(path) > 4000) return cli_fail(cmd, "%s: path too long", path), false;
    struct stat sb;
    if (stat(path, &sb) == 0) {
        if (!S_ISDIR(sb.st_mode)) return cli_fail(cmd, "%s: exists and is not a folder", path), false;
        return true;
    }
    if (mkdir(path, 0777) != 0) return cli_fail(cmd, "%s: cannot make the folder: %s", path, strerror(errno)), false;
    d->created = true;
    return true;
}

const char *frame_dir_frame(frame_dir *d, int i, const char *ext)
{
    snprintf(d->name, sizeof d->name, "%s/frame_%05d.%s", d->path, i, ext ? ext : d->ext);
    return d->name;
}

spn_status frame_dir_write(frame_dir *d, spn_status (*write)(void *ctx, spn_sink *sink), void *ctx)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, frame_dir_frame(d, d->count, NULL), true);
    if (st != SPN_OK) return st;
    spn_sink sink = spn_sink_file(f.fp);
    st = write(ctx, &sink);
    if (st != SPN_OK) {
        spn_atomic_abort(&f);
        return st;
    }
    st = spn_atomic_commit(&f);
    if (st == SPN_OK) d->count++;
    return st;
}

void frame_dir_discard(frame_dir *d)
{
    for (int i = 0; i < d->count; i++) {
        remove(frame_dir_frame(d, i, NULL));
        remove(frame_dir_frame(d, i, "png"));
    }
    if (d->created) rmdir(d->path);
}

/* Frame sequences: a folder of PNGs (DIR/frame_%05d.png), or raw RGBA frames
 * piped into the ffmpeg program for .mp4 (H.264, yuv420p, so every player
 * opens it) and .gif (a palette made from the whole clip with palettegen,
 * applied with paletteuse, so gradients do not band).
 * ffmpeg is found on PATH, or named by $SPN_FFMPEG. It is started with
 * fork/exec (no shell, so paths need no quoting) and writes to a temporary
 * beside the target, renamed into place only when ffmpeg exits cleanly on a
 * committed close: a failed or abandoned encode leaves no partial video.
 * SIGPIPE is ignored while a pipe is open, so an ffmpeg that dies turns into
 * an error from spn_frames_add instead of killing the program. */
#include "render_internal.h"

#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

typedef enum frames_kind { FRAMES_PNG, FRAMES_MP4, FRAMES_GIF } frames_kind;

struct spn_frames {
    frames_kind kind;
    int width, height, index;
    double fps;
    char *dir;                 /* PNG folder */
    spn_atomic_file video;     /* ffmpeg output */
    pid_t pid;
    int pipe_fd;
    struct sigaction old_pipe;
    uint8_t *scratch;          /* one frame of RGBA for spn_frames_add_world */
};

static const char *ffmpeg_program(void)
{
    const char *env = getenv("SPN_FFMPEG");
    return env && *env ? env : "ffmpeg";
}

bool spn_frames_have_ffmpeg(void)
{
    const char *prog = ffmpeg_program();
    if (strchr(prog, '/')) return access(prog, X_OK) == 0;
    const char *path = getenv("PATH");
    if (!path) return false;
    char buf[4096];
    for (const char *p = path; *p;) {
        const char *colon = strchr(p, ':');
        size_t n = colon ? (size_t)(colon - p) : strlen(p);
        if (n > 0 && n + strlen(prog) + 2 < sizeof buf) {
            snprintf(buf, sizeof buf, "%.*s/%s", (int)n, p, prog);
            if (access(buf, X_OK) == 0) return true;
        }
        p += n + (colon ? 1 : 0);
    }
    return false;
}

static frames_kind kind_of(const char *out)
{
    size_t n = strlen(out);
    if (n > 4 && strcasecmp(out + n - 4, ".mp4") == 0) return FRAMES_MP4;
    if (n > 4 && strcasecmp(out + n - 4, ".gif") == 0) return FRAMES_GIF;
    return FRAMES_PNG;
}

static spn_status open_dir(spn_frames *f, const char *out)
{
    struct stat sb;
    if (stat(out, &sb) == 0 && !S_ISDIR(sb.st_mode))
        return spn_error(SPN_ERR_INVALID, "%s: exists and is not a folder (frames go to a folder, .mp4 or .gif)", out);
    if (mkdir(out, 0777) != 0 && errno != EEXIST)
        return spn_error(SPN_ERR_IO, "%s: cannot make folder: %s", out, strerror(errno));
    f->dir = strdup(out);
    return f->dir ? SPN_OK : spn_error(SPN_ERR_NOMEM, "out of memory");
}

/* The ffmpeg command line: raw RGBA frames on stdin, the video to `path`. */
static void ffmpeg_args(const spn_frames *f, const char *path, char size[32], char rate[32], const char *argv[32])
{
    int n = 0;
    snprintf(size, 32, "%dx%d", f->width, f->height);
    snprintf(rate, 32, "%.6g", f->fps);
    const char *head[] = {ffmpeg_program(), "-hide_banner", "-loglevel", "error", "-nostdin", "-y", "-f", "rawvideo",
                          "-pix_fmt", "rgba", "-s", size, "-r", rate, "-i", "-"};
    for (size_t i = 0; i < sizeof head / sizeof head[0]; i++) argv[n++] = head[i];
    if (f->kind == FRAMES_MP4) {
        /* yuv420p needs even sides: pad by one pixel when odd. */
        const char *tail[] = {"-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
                              "-crf", "18", "-movflags", "+faststart", "-f", "mp4"};
        for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) argv[n++] = tail[i];
    } else {
        const char *tail[] = {"-filter_complex", "[0:v]split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=sierra2_4a",
                              "-loop", "0", "-f", "gif"};
        for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) argv[n++] = tail[i];
    }
    argv[n++] = path;
    argv[n] = NULL;
}

static spn_status start_ffmpeg(spn_frames *f, const char *out)
{
    if (!spn_frames_have_ffmpeg())
        return spn_error(SPN_ERR_UNSUPPORTED,
                         "%s: the ffmpeg program is not installed (or not on PATH); install ffmpeg, or give a folder "
                         "(e.g. -o frames/) to write the frames as PNGs",
                         out);
    spn_status st = spn_atomic_open(&f->video, out, false);
    if (st != SPN_OK) return st;
    char size[32], rate[32];
    const char *argv[32];
    ffmpeg_args(f, f->video.tmp_path, size, rate, argv);
    int fds[2];
    if (pipe(fds) != 0) {
        spn_atomic_abort(&f->video);
        return spn_error(SPN_ERR_IO, "%s: cannot start ffmpeg: %s", out, strerror(errno));
    }
    pid_t pid = fork();
    if (pid == 0) {
        /* A Ctrl-C reaches the whole process group: ffmpeg ignores it, so the
         * program can stop between frames and close the video cleanly. */
        signal(SIGINT, SIG_IGN);
        dup2(fds[0], 0);
        close(fds[0]);
        close(fds[1]);
        execvp(argv[0], (char *const *)argv);
        _exit(127);
    }
    close(fds[0]);
    if (pid < 0) {
        close(fds[1]);
        spn_atomic_abort(&f->video);
        return spn_error(SPN_ERR_IO, "%s: cannot start ffmpeg: %s", out, strerror(errno));
    }
    f->pid = pid;
    f->pipe_fd = fds[1];
    struct sigaction ign;
    memset(&ign, 0, sizeof ign);
    ign.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &ign, &f->old_pipe);
    return SPN_OK;
}

spn_status spn_frames_open(const char *out, int width, int height, double fps, spn_frames **frames)
{
    *frames = NULL;
    if (!out || !*out) return spn_error(SPN_ERR_INVALID, "frames: output path is empty");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return spn_error(SPN_ERR_INVALID, "frames: size must be between 1x1 and 16384x16384, got %dx%d", width, height);
    if (!(fps > 0 && fps <= 1000)) return spn_error(SPN_ERR_INVALID, "frames: fps must be in (0, 1000], got %g", fps);
    spn_frames *f = calloc(1, sizeof *f);
    if (!f) return spn_error(SPN_ERR_NOMEM, "out of memory");
    f->kind = kind_of(out);
    f->width = width;
    f->height = height;
    f->fps = fps;
    f->pipe_fd = -1;
    spn_status st = f->kind == FRAMES_PNG ? open_dir(f, out) : start_ffmpeg(f, out);
    if (st != SPN_OK) {
        free(f->dir);
        free(f);
        return st;
    }
    *frames = f;
    return SPN_OK;
}

void spn_frames_set_first_index(spn_frames *frames, int index) { frames->index = index; }

void spn_frames_size(const spn_frames *frames, int *width, int *height)
{
    *width = frames->width;
    *height = frames->height;
}

static spn_status write_all(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return spn_error(SPN_ERR_IO, "frames: ffmpeg stopped reading: %s", strerror(errno));
        p += k;
        n -= (size_t)k;
    }
    return SPN_OK;
}

/* Bytes of one RGBA frame of the sequence. */
static size_t frame_bytes(const spn_frames *f) { return (size_t)f->width * f->height * 4; }

/* Frame `index`'s PNG file in the folder; NULL when out of memory. */
static char *png_path(const spn_frames *f, int index)
{
    size_t n = strlen(f->dir) + 32;
    char *path = malloc(n);
    if (path) snprintf(path, n, "%s/frame_%05d.png", f->dir, index);
    return path;
}

spn_status spn_frames_encode(const spn_frames *frames, const uint8_t *rgba, uint8_t **bytes, size_t *size)
{
    *bytes = NULL, *size = 0;
    const size_t raw = frame_bytes(frames);
    if (frames->kind != FRAMES_PNG) {
        if (!(*bytes = malloc(raw))) return spn_error(SPN_ERR_NOMEM, "frames: out of memory");
        memcpy(*bytes, rgba, raw);
        *size = raw;
        return SPN_OK;
    }
    spn__png_pixels px = {rgba, frames->width, frames->height, (size_t)frames->width * 4, false};
    return spn__png_encode_memory(&px, SPN__PNG_LEVEL_FRAME, bytes, size);
}

/* Encoded bytes into the next PNG file: a temporary renamed into place. */
static spn_status add_png(spn_frames *f, const uint8_t *bytes, size_t size)
{
    char *path = png_path(f, f->index);
    if (!path) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_atomic_file out;
    spn_status st = spn_atomic_open(&out, path, true);
    if (st == SPN_OK) {
        if (fwrite(bytes, 1, size, out.fp) != size || fflush(out.fp) != 0) {
            st = spn_error(SPN_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
            spn_atomic_abort(&out);
        } else {
            st = spn_atomic_commit(&out);
        }
    }
    free(path);
    return st;
}

spn_status spn_frames_add_encoded(spn_frames *frames, const uint8_t *bytes, size_t size)
{
    const size_t raw = frame_bytes(frames);
    if (frames->kind != FRAMES_PNG && size != raw)
        return spn_error(SPN_ERR_INVALID, "frames: an encoded video frame is %zu bytes, not %zu", size, raw);
    spn_status st = frames->kind == FRAMES_PNG ? add_png(frames, bytes, size) : write_all(frames->pipe_fd, bytes, size);
    if (st == SPN_OK) frames->index++;
    return st;
}

spn_status spn_frames_add(spn_frames *frames, const uint8_t *rgba)
{
    if (frames->kind != FRAMES_PNG) return spn_frames_add_encoded(frames, rgba, frame_bytes(frames));
    uint8_t *bytes;
    size_t size;
    spn_status st = spn_frames_encode(frames, rgba, &bytes, &size);
    if (st == SPN_OK) st = spn_frames_add_encoded(frames, bytes, size);
    free(bytes);
    return st;
}

spn_status spn_frames_add_world(spn_frames *frames, const spn_world *w, const spn_render_def *def)
{
    if (def->width != frames->width || def->height != frames->height)
        return spn_error(SPN_ERR_INVALID, "frames: picture is %dx%d but the sequence is %dx%d", def->width,
                         def->height, frames->width, frames->height);
    if (!frames->scratch) frames->scratch = malloc(frame_bytes(frames));
    if (!frames->scratch) return spn_error(SPN_ERR_NOMEM, "frames: out of memory");
    spn_status st = spn_render_rgba(w, def, frames->scratch);
    return st == SPN_OK ? spn_frames_add(frames, frames->scratch) : st;
}

/* Close the pipe, wait for ffmpeg; true when it exited with status 0. */
static bool finish_ffmpeg(spn_frames *f)
{
    if (f->pipe_fd >= 0) close(f->pipe_fd);
    int status = 0;
    pid_t r;
    do r = waitpid(f->pid, &status, 0);
    while (r < 0 && errno == EINTR);
    sigaction(SIGPIPE, &f->old_pipe, NULL);
    return r == f->pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

spn_status spn_frames_close(spn_frames *frames, bool commit)
{
    if (!frames) return SPN_OK;
    spn_status st = SPN_OK;
    if (frames->kind != FRAMES_PNG) {
        if (!commit) kill(frames->pid, SIGTERM);
        bool ok = finish_ffmpeg(frames);
        if (commit && ok && frames->index > 0) {
            st = spn_atomic_commit(&frames->video);
        } else {
            if (commit) st = spn_error(SPN_ERR_IO, "%s: ffmpeg failed to encode the video%s", frames->video.path,
                                       frames->index > 0 ? "" : " (no frames)");
            spn_atomic_abort(&frames->video);
        }
    }
    free(frames->dir);
    free(frames->scratch);
    free(frames);
    return st;
}

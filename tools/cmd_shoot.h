/* Shared by tools/cmd_shoot.c (options, running the shot) and
 * tools/cmd_shoot_out.c (writing JSON and rendered frames). */
#ifndef SPN_CMD_SHOOT_H
#define SPN_CMD_SHOOT_H

#include "cli.h"

/* Every frame of a shot, recorded at 1/fps. */
typedef struct recording {
    uint32_t n, frames, cap;
    spn_vec3 *strand;   /* frames * n points */
    spn_vec3 *character;
    double *t, *alpha, *shake;
    uint32_t *count;    /* strand points in the frame (0 when gone) */
    spn_shot_phase *phase;
} recording;

/* How frames are rendered. The camera frames the whole shot unless eye or
 * look-at are given (then those win, so several shots can share a view). */
typedef struct video_options {
    int width, height;
    double fps;
    bool quiet;
    bool have_eye, have_look;
    spn_vec3 eye, look;
} video_options;

int shoot_write_json(const char *cmd, const char *path, const spn_shot *s, const recording *r, double fps);
int shoot_write_video(const char *cmd, const char *path, const recording *r, const video_options *v);

#endif

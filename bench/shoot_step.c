/* Cost of web shots in a game loop: 16 shots stepped at 60 Hz from firing
 * until gone, timed per phase. Prints one JSON line per phase with the mean
 * time of one spn_shot_step call, so "many shots at 60 Hz" has a number. */
#define _POSIX_C_SOURCE 200809L
#include <spinneret/spinneret.h>

#include <stdio.h>
#include <time.h>

enum { SHOTS = 16 };

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(void)
{
    spn_shot *s[SHOTS];
    spn_shot_def def = spn_shot_def_default();
    def.speed = 22;
    for (int i = 0; i < SHOTS; i++) {
        def.seed = (uint64_t)i + 1;
        def.target.z = 0.25 * i;
        if (spn_shot_create(&def, &s[i]) != SPN_OK) {
            fprintf(stderr, "%s\n", spn_last_error());
            return 1;
        }
    }
    double spent[SPN_SHOT_DONE + 1] = {0};
    long calls[SPN_SHOT_DONE + 1] = {0};
    for (int live = SHOTS; live > 0;) {
        live = 0;
        for (int i = 0; i < SHOTS; i++) {
            spn_shot_phase ph = spn_shot_phase_now(s[i]);
            if (ph == SPN_SHOT_DONE) continue;
            double t0 = now();
            if (spn_shot_step(s[i], 1.0 / 60) != SPN_OK) return 1;
            spent[ph] += now() - t0;
            calls[ph]++;
            live++;
        }
    }
    for (int p = 0; p < SPN_SHOT_DONE; p++)
        printf("{\"bench\":\"shoot_step\",\"phase\":\"%s\",\"points\":%d,\"dt\":%.6g,\"steps\":%ld,"
               "\"us_per_step\":%.2f}\n",
               spn_shot_phase_name((spn_shot_phase)p), def.points, 1.0 / 60, calls[p],
               calls[p] ? 1e6 * spent[p] / calls[p] : 0.0);
    for (int i = 0; i < SHOTS; i++) spn_shot_destroy(s[i]);
    return 0;
}

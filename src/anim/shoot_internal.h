/* The shot's private layout, shared by shoot.c (definition, THWIP motion,
 * queries), shoot_path.c (path and noise) and shoot_phases.c (the spring
 * phases). All arrays are allocated by spn_shot_create. */
#ifndef SPN_SHOOT_INTERNAL_H
#define SPN_SHOOT_INTERNAL_H

#include "spinneret/shoot.h"
#include "spinneret/world.h"

struct spn_shot {
    spn_shot_def def;
    spn_ballistic path;
    uint32_t n;               /* strand points: 0 = hand end, n - 1 = head */
    double amplitude;         /* noise offset amplitude [m] */
    int noise_samples;
    double *noise_side, *noise_lift;

    /* THWIP: the motion runs on fixed ticks so it looks the same at any frame
     * rate; frames between ticks are interpolated. */
    double tick;              /* [s] */
    uint32_t ticks_per_point; /* ticks while the head advances one point spacing */
    uint32_t ticks_done, ticks_total;
    double *off, *off_prev;   /* per point: (side, lift) offsets, 2 n each */
    spn_vec3 *tick_a, *tick_b;/* positions at the previous and the current tick */
    spn_vec3 *pos;            /* the polyline given out */

    double t;                 /* shot time [s] */
    spn_shot_phase phase;
    double phase_start[SPN_SHOT_DONE + 1];
    double alpha;

    /* the spring phases */
    spn_world *world;
    double seg_rest, seg_mass, k, kd, dt_sub;
    double *rest0, *wave_at;  /* per spring: rest at contact, start of tightening */
    double thwap_end, zipp_end;
    double h_start, h_min;    /* character heights in the swing */
    spn_vec3 up;
    spn_vec3 char_pos, char_vel; /* character at release */
};

/* shoot_path.c */
double spn__noise_at(const double *curve, int samples, double u);
/* Unit vectors normal to the path's direction at time t: side (horizontal)
 * and lift (in the vertical plane of travel). */
void spn__path_frame(const spn_ballistic *b, double t, spn_vec3 *side, spn_vec3 *lift);

/* shoot_phases.c */
spn_status spn__springs_create(spn_shot *s);
void spn__thwap_begin(spn_shot *s);
/* Advance the spring phases up to time `until`; may end early at a phase
 * change (the caller loops). */
spn_status spn__springs_advance(spn_shot *s, double until);

#endif

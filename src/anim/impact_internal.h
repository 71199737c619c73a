/* The prey impact's private state, shared by impact.c (prey, contact, glue)
 * and impact_ledger.c (energy bookkeeping and the report). */
#ifndef SPN_IMPACT_INTERNAL_H
#define SPN_IMPACT_INTERNAL_H

#include "anim_internal.h"

#define MAX_TETHERS 256

/* The glue holding prey p to segment s, attached at point u: tension-only,
 * rest length `rest` from the prey's centre. It stands for all the droplets
 * of the segment's length within the prey's sticky outline (impact.c). */
typedef struct spn__tether {
    int prey;
    uint32_t s;
    double u, rest;
    double strength; /* it lets go past this pull [N]: glue over its contact length */
    double k;        /* strength / SPN_GLUE_STRETCH [N/m] */
    int slot;    /* its index in the implicit solver's contact list of the step just taken; -1: not in it */
} spn__tether;

#define MAX_PREY 8

struct spn_impact {
    spn_impact_def def;
    int nprey;
    uint32_t prey[MAX_PREY];
    double radius[MAX_PREY];
    spn_vec3 dir0[MAX_PREY];
    double speed0[MAX_PREY];
    bool touched[MAX_PREY];
    bool hit_known[MAX_PREY];
    spn_vec3 hit[MAX_PREY];      /* prey centre at the end of its first step in contact */
    const spn_world *world;      /* for the break callback */
    double web_radius;
    double break_dist_max, break_dist_sum;
    bool strike_done;             /* every prey arrested or through: snapshot taken */
    double strike_time;
    spn_impact_report strike;     /* the ledger at that moment */ /* broken springs' distance from the nearest hit */
    double kc;    /* contact stiffness [N/m] */
    /* springs, cached at creation (the graph does not change) */
    uint32_t ns, np;
    uint32_t *sa, *sb;
    double *k, *kd, *rest;
    uint8_t *tension_only, *broken, *slot;
    uint32_t *tag;
    double *rest0;  /* rest lengths at creation (yield and breaking refer to them) */
    double *len0;   /* lengths at creation */
    /* ledger */
    int nkinds;
    spn_kind_energy kinds[SPN_KIND_SLOTS];
    double elastic0[SPN_KIND_SLOTS], elastic[SPN_KIND_SLOTS], damp_prev[SPN_KIND_SLOTS];
    double viscous, viscous_prev;
    double air_prev, wind_prev, air_work, wind_work;
    double total0, prey_ke0, contact;
    uint32_t breaks;
    spn_force_fn wind_fn;
    void *wind_user;
    spn_vec3 *fbuf;
    /* implicit contacts (impact_contact.c): the list handed to the world
     * before a step */
    bool listed;                  /* the list holds this step's contacts */
    spn_contact *cl;
    uint32_t ncl, cap_cl;
    spn_vec3 *x0, *v0;            /* state before the step, for the solver's loss */
    double *coff;                 /* per prey and segment: contact offset, < 0 when not touching */
    double *cend;                 /* per prey and segment: the solver's depth at the last step's end */
    uint32_t *cseg;               /* per listed contact: its segment (tethers: UINT32_MAX) */
    bool offsets;                 /* contacts use the offsets (the implicit path) */
    double solver;                /* backward Euler's own dissipation so far [J] */
    /* glue */
    spn__tether tethers[MAX_TETHERS];
    int ntethers;
    double glue_lost, glue_energy;
    uint32_t detached;
};

/* Closest point of segment s to c: squared distance, parameter u, offset c - q. */
double spn__impact_closest(const spn_impact *im, uint32_t s, const spn_vec3 *x, spn_vec3 c, double *u, spn_vec3 *r);
/* Contact and glue forces into f (when not NULL); returns their potential energy. */
double spn__impact_contact(spn_impact *im, const spn_vec3 *x, spn_vec3 *f);
/* The ledger's starting point (state of the world at creation). */
void spn__impact_ledger_start(spn_impact *im, const spn_world *w);
/* Yielding after a step: a spring stretched past its yield strain lengthens its
 * rest so its force follows the post-yield line; the elastic energy this
 * releases is dissipated (silk's hysteresis). */
void spn__impact_yield(spn_impact *im, spn_world *w);
/* The depth a contact of geometric depth `depth` (> 0) counts from, by its
 * offset (impact_contact.c); `update` brings the offset up to date. */
double spn__impact_offset_depth(spn_impact *im, size_t i, double depth, bool update);
/* Backward Euler's numerical dissipation over the step just taken (exact for
 * linear springs): 1/2 dv^T M dv + 1/2 dx^T K dx, contacts included. */
double spn__impact_solver_loss(spn_impact *im, const spn_world *w);

/* Glue after a step: new droplets where prey touch capture thread, droplets
 * that let go. */
void spn__impact_glue_update(spn_impact *im, const spn_world *w);

#endif

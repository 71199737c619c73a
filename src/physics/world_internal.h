/* The spring world's private layout. Particle and spring fields live in
 * separate flat arrays (structure of arrays): the stepping loops read only the
 * hot ones (positions, velocities, inverse masses, spring ends, stiffness,
 * rest lengths). A CSR adjacency (particle -> incident springs, in spring id
 * order) lets forces be gathered per particle without atomics, so the sum is
 * done in a fixed order and the result is the same with any thread count. */
#ifndef SPN_WORLD_INTERNAL_H
#define SPN_WORLD_INTERNAL_H

#include "spinneret/world.h"

#define SPN_SPRING_TENSION_ONLY 1u
#define SPN_SPRING_BROKEN 2u

typedef struct spn_collider {
    int kind; /* 0 plane, 1 sphere */
    spn_vec3 p; /* plane normal or sphere centre */
    double d;   /* plane offset (n.x = d on the plane) or sphere radius */
    double restitution, friction;
} spn_collider;

typedef struct spn_tag_diameter {
    uint32_t tag;
    double diameter;
} spn_tag_diameter;

struct spn_world {
    spn_world_def def;

    /* particles */
    uint32_t np, cap_p;
    spn_vec3 *x, *v;
    double *mass, *inv_mass;
    uint32_t *ptag;

    /* springs */
    uint32_t ns, cap_s;
    uint32_t *sa, *sb;
    double *k, *kd, *rest, *bmin, *bmax;
    uint8_t *sflags;
    uint32_t *stag, *sstage, *sorder;

    /* compiled data: valid while `compiled` */
    bool compiled;
    uint32_t *adj_start;  /* np + 1 */
    uint32_t *adj;        /* spring id << 1 | (1 if the particle is end b) */
    spn_vec3 *fs;         /* per-spring force on end a (scratch) */
    spn_vec3 *fair;       /* per-spring air force, half to each end (scratch) */
    double *sdiam;        /* per-spring diameter for air drag */
    spn_vec3 *f, *x0, *v0, *kx[4], *kv[4], *xt, *vt; /* per-particle scratch */

    /* time and statistics */
    double t;
    uint64_t steps;
    spn_step_report last;
    double external_work, dissipated;

    /* callbacks */
    spn_force_fn force_fn;
    void *force_user;
    spn_break_fn break_fn;
    void *break_user;
    spn_collide_fn collide_fn;
    void *collide_user;
    spn_air_fn air_fn;
    void *air_user;
    double air_rho, air_mu;
    spn_tag_diameter *diam;
    uint32_t ndiam;

    spn_collider *colliders;
    uint32_t ncolliders;

    char *metadata;
};

/* Forces on state (x, v) at time t into f (all particles; fixed ones too). */
void spn__eval_forces(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f);
/* Spring force on end a of spring s for state (x, v); zero when broken or slack. */
spn_vec3 spn__spring_force(const spn_world *w, uint32_t s, const spn_vec3 *x, const spn_vec3 *v);
/* Elastic energy of the springs at positions x. */
double spn__elastic_energy(const spn_world *w, const spn_vec3 *x);
double spn__kinetic_energy(const spn_world *w, const spn_vec3 *v);
double spn__gravity_energy(const spn_world *w, const spn_vec3 *x);

#endif

/* A world of mesh objects: the factory adds each mesh, the triangle collider
 * keeps free vertices out of other objects, and `advance` steps the world in
 * sub-steps small enough for explicit stability. Symplectic Euler on a
 * damped oscillator (stiffness k, damping c, mass m, step h) is stable when
 * h^2 k/m + 2 h c/m < 4 (the Jury conditions on its 2x2 step matrix). A
 * particle whose springs sum to K and C, with neighbours that move too, is
 * bounded by the same test with 2K and 2C (Gershgorin); we take 0.4 of the
 * largest h that passes, over all free particles.
 * Collisions are resolved after each sub-step, outside the world's step,
 * because the response needs the velocity (friction, moving triangles), which
 * the per-particle callback of world.h does not see. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct scene_object {
    spn_mesh mesh;
    spn_mesh_stats stats;
} scene_object;

struct spn_mesh_scene {
    spn_mesh_scene_def def;
    spn_world *w;
    spn_tri_collider *col;
    scene_object *obj;
    uint32_t nobj;
    double substep; /* 0: to be computed */
    spn_vec3 *x0;
    uint32_t cap_x0;
    uint64_t contacts;
};

spn_mesh_scene_def spn_mesh_scene_def_default(void)
{
    spn_mesh_scene_def d;
    memset(&d, 0, sizeof d);
    d.world = spn_world_def_default();
    d.restitution = 0.3;
    d.friction = 0.2;
    d.skin = 0.003;
    d.max_substep = 1e-3;
    d.ground_restitution = 0.5;
    d.ground_friction = 0.2;
    return d;
}

spn_status spn_mesh_scene_create(const spn_mesh_scene_def *def, spn_mesh_scene **out)
{
    *out = NULL;
    spn_mesh_scene_def d = def ? *def : spn_mesh_scene_def_default();
    if (!(d.restitution >= 0 && d.restitution <= 1) || !(d.friction >= 0 && d.friction <= 1))
        return spn_error(SPN_ERR_INVALID, "mesh scene: restitution and friction must be in [0, 1]");
    if (!(d.skin > 0) || !isfinite(d.skin)) return spn_error(SPN_ERR_INVALID, "mesh scene: skin must be positive");
    if (!(d.max_substep > 0) || !isfinite(d.max_substep))
        return spn_error(SPN_ERR_INVALID, "mesh scene: max_substep must be positive");
    spn_mesh_scene *s = calloc(1, sizeof *s);
    if (!s) return spn_error(SPN_ERR_NOMEM, "out of memory");
    s->def = d;
    s->w = spn_world_create(&d.world);
    s->col = spn__tri_collider_create(d.skin, d.restitution, d.friction);
    spn_status st = s->w && s->col ? SPN_OK : spn_error(SPN_ERR_NOMEM, "out of memory");
    if (st == SPN_OK && d.ground)
        st = spn_world_add_plane(s->w, spn_v3(0, 1, 0), d.ground_y, d.ground_restitution, d.ground_friction);
    if (st != SPN_OK) {
        spn_mesh_scene_destroy(s);
        return st;
    }
    *out = s;
    return SPN_OK;
}

void spn_mesh_scene_destroy(spn_mesh_scene *s)
{
    if (!s) return;
    for (uint32_t i = 0; i < s->nobj; i++) spn_mesh_free(&s->obj[i].mesh);
    free(s->obj);
    free(s->x0);
    spn__tri_collider_destroy(s->col);
    spn_world_destroy(s->w);
    free(s);
}

spn_status spn_mesh_scene_add(spn_mesh_scene *s, const spn_mesh *m, const spn_mesh_spring_def *def, uint32_t *object)
{
    scene_object *grown = realloc(s->obj, (s->nobj + 1) * sizeof *grown);
    if (!grown) return spn_error(SPN_ERR_NOMEM, "out of memory");
    s->obj = grown;
    scene_object *o = &s->obj[s->nobj];
    memset(o, 0, sizeof *o);
    spn_status st = spn_mesh_add_to_world(s->w, m, def, &o->stats);
    if (st == SPN_OK) st = spn_mesh_copy(&o->mesh, m);
    if (st != SPN_OK) return st; /* the world may hold part of the object; the caller discards the scene */
    uint32_t id = s->nobj++;
    bool moving = o->stats.fixed < o->stats.particles;
    st = spn__tri_collider_add(s->col, m->triangles, m->triangle_count, o->stats.first_particle, id, moving);
    if (st == SPN_OK) st = spn__tri_collider_set_owner(s->col, o->stats.first_particle, o->stats.particles, id);
    s->substep = 0;
    if (object) *object = id;
    return st;
}

spn_world *spn_mesh_scene_world(spn_mesh_scene *s) { return s->w; }
uint32_t spn_mesh_scene_object_count(const spn_mesh_scene *s) { return s->nobj; }
uint64_t spn_mesh_scene_contacts(const spn_mesh_scene *s) { return s->contacts; }

const spn_mesh_stats *spn_mesh_scene_object_stats(const spn_mesh_scene *s, uint32_t object)
{
    return object < s->nobj ? &s->obj[object].stats : NULL;
}

spn_status spn_mesh_scene_object_mesh(const spn_mesh_scene *s, uint32_t object, spn_mesh *out)
{
    memset(out, 0, sizeof *out);
    if (object >= s->nobj) return spn_error(SPN_ERR_INVALID, "mesh scene: no object %u", object);
    spn_status st = spn_mesh_copy(out, &s->obj[object].mesh);
    if (st != SPN_OK) return st;
    const spn_vec3 *x = spn_world_positions(s->w);
    memcpy(out->vertices, x + s->obj[object].stats.first_particle, out->vertex_count * sizeof *x);
    return SPN_OK;
}

double spn_mesh_scene_substep(spn_mesh_scene *s)
{
    if (s->substep > 0) return s->substep;
    /* 0.4 of the springs' stable step (Gershgorin's bound, the world's drag
     * in it; until 2026-12-05 a copy of that bound here left the drag out
     * and counted broken springs), at most max_substep; that too when out
     * of memory (0) */
    const double stable = spn_world_stable_step(s->w, 0);
    s->substep = stable > 0 ? fmin(s->def.max_substep, 0.4 * stable) : s->def.max_substep;
    return s->substep;
}

spn_status spn_mesh_scene_advance(spn_mesh_scene *s, double dt)
{
    if (!(dt >= 0) || !isfinite(dt)) return spn_error(SPN_ERR_INVALID, "mesh scene: time step must be >= 0");
    if (dt == 0) return SPN_OK;
    double h = spn_mesh_scene_substep(s);
    double n = ceil(dt / h - 1e-9);
    uint32_t np = spn_world_particle_count(s->w);
    if (!spn__grow((void **)&s->x0, &s->cap_x0, np ? np : 1, sizeof *s->x0))
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (double i = 0; i < n; i++) {
        memcpy(s->x0, spn_world_positions(s->w), np * sizeof *s->x0);
        spn_status st = spn_world_step(s->w, dt / n);
        if (st != SPN_OK) return st;
        s->contacts += spn__tri_collider_resolve(s->col, s->w, s->x0);
    }
    return SPN_OK;
}

double spn_mesh_scene_kinetic(const spn_mesh_scene *s)
{
    return spn_world_energy(s->w).kinetic;
}

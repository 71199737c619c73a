/* Shared scenes (see scenes.h). The standard orb web is the benchmark and test
 * web of the performance issue: hub, rings x radials, outer ring fixed,
 * pre-strained, EA ~ 0.07 N. Thread material follows DESIGN: k = EA / r and
 * segment mass shared by its ends, so refinement does not change behaviour. */
#include "spinneret/scenes.h"
#include "spinneret/web.h"

#include <math.h>
#include <stdlib.h>

spn_orb_scene_def spn_orb_scene_def_default(void)
{
    spn_orb_scene_def d;
    d.centre = spn_v3(0, 0, 0);
    d.radius = 0.15;
    d.hub_radius = 0;
    d.rings = 20;
    d.radials = 24;
    d.prestrain = 0.02;
    d.ea = 0.07;
    d.damping_ratio = 0.02;
    d.linear_density = 1e-6;
    d.tension_only = true;
    return d;
}

uint32_t spn_orb_scene_particles(int rings, int radials) { return 1u + (uint32_t)rings * (uint32_t)radials; }

/* Add a segment laid at its current length, rest = length / (1 + prestrain). */
static spn_status add_segment(spn_world *w, const spn_orb_scene_def *d, uint32_t a, uint32_t b, uint32_t tag,
                              uint32_t stage, uint32_t order, double *mass)
{
    double len = spn_v3_len(spn_v3_sub(spn_world_position(w, a), spn_world_position(w, b)));
    spn_spring_def s = spn_spring_def_default();
    s.a = a;
    s.b = b;
    s.rest = len / (1 + d->prestrain);
    s.k = d->ea / s.rest;
    double m_seg = d->linear_density * s.rest;
    s.kd = d->damping_ratio * 2 * sqrt(s.k * fmax(m_seg, 1e-30));
    s.tension_only = d->tension_only;
    s.tag = tag;
    s.stage = stage;
    s.order = order;
    mass[a] += 0.5 * m_seg;
    mass[b] += 0.5 * m_seg;
    return spn_world_add_spring(w, &s, NULL);
}

spn_status spn_scene_orb(const spn_world_def *world_def, const spn_orb_scene_def *def, spn_world **out)
{
    spn_orb_scene_def d = def ? *def : spn_orb_scene_def_default();
    *out = NULL;
    if (d.rings < 1 || d.radials < 3 || d.rings > 100000 || d.radials > 100000 || !(d.radius > 0) ||
        !(d.ea > 0) || !(d.linear_density > 0) || !(d.prestrain > -1))
        return spn_error(SPN_ERR_INVALID, "orb scene: need rings >= 1, radials >= 3, positive radius, EA and density");
    double hub = d.hub_radius > 0 ? d.hub_radius : d.radius / d.rings;
    spn_world *w = spn_world_create(world_def);
    uint32_t np = spn_orb_scene_particles(d.rings, d.radials);
    double *mass = calloc(np, sizeof *mass);
    if (!w || !mass) {
        spn_world_destroy(w);
        free(mass);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    spn_status st = SPN_OK;
    spn_particle_def p = spn_particle_def_default();
    p.position = d.centre;
    p.tag = SPN_PARTICLE_HUB;
    st = spn_world_add_particle(w, &p, NULL);
    /* Particle 1 + j * radials + i: ring j (0 = innermost), radial i. */
    for (int j = 0; j < d.rings && st == SPN_OK; j++) {
        double r = d.rings == 1 ? d.radius : hub + (d.radius - hub) * j / (d.rings - 1);
        for (int i = 0; i < d.radials && st == SPN_OK; i++) {
            double a = 2 * SPN_PI * i / d.radials;
            p.position = spn_v3_add(d.centre, spn_v3(r * cos(a), r * sin(a), 0));
            p.fixed = j == d.rings - 1;
            p.tag = p.fixed ? SPN_PARTICLE_ANCHOR : SPN_PARTICLE_SPIRAL;
            st = spn_world_add_particle(w, &p, NULL);
        }
    }
    uint32_t order = 0;
    for (int i = 0; i < d.radials && st == SPN_OK; i++) {
        uint32_t prev = 0;
        for (int j = 0; j < d.rings && st == SPN_OK; j++) {
            uint32_t cur = 1u + (uint32_t)(j * d.radials + i);
            st = add_segment(w, &d, prev, cur, SPN_THREAD_RADIUS, 1, order++, mass);
            prev = cur;
        }
    }
    for (int j = 0; j < d.rings && st == SPN_OK; j++) {
        uint32_t tag = j == d.rings - 1 ? SPN_THREAD_FRAME : SPN_THREAD_CAPTURE;
        for (int i = 0; i < d.radials && st == SPN_OK; i++) {
            uint32_t a = 1u + (uint32_t)(j * d.radials + i), b = 1u + (uint32_t)(j * d.radials + (i + 1) % d.radials);
            st = add_segment(w, &d, a, b, tag, tag == SPN_THREAD_FRAME ? 0 : 2, order++, mass);
        }
    }
    for (uint32_t i = 0; i < np && st == SPN_OK; i++) {
        bool fixed = spn_world_is_fixed(w, i);
        st = spn_world_set_mass(w, i, mass[i] > 0 ? mass[i] : d.linear_density * d.radius / d.rings);
        if (fixed) spn_world_set_fixed(w, i, true);
    }
    free(mass);
    if (st != SPN_OK) {
        spn_world_destroy(w);
        return st;
    }
    *out = w;
    return SPN_OK;
}

spn_status spn_scene_chain(const spn_world_def *world_def, spn_vec3 a, spn_vec3 b, int segments, double length,
                           double mass, double k, double kd, spn_world **out)
{
    *out = NULL;
    if (segments < 1 || segments > 10000000 || !(length > 0) || !(mass > 0) || !(k > 0) || !(kd >= 0))
        return spn_error(SPN_ERR_INVALID, "chain: need segments >= 1 and positive length, mass and stiffness");
    spn_world *w = spn_world_create(world_def);
    if (!w) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    double m = mass / segments;
    for (int i = 0; i <= segments && st == SPN_OK; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), (double)i / segments));
        p.mass = (i == 0 || i == segments) ? m / 2 : m;
        p.fixed = i == 0 || i == segments;
        st = spn_world_add_particle(w, &p, NULL);
    }
    for (int i = 0; i < segments && st == SPN_OK; i++) {
        spn_spring_def s = spn_spring_def_default();
        s.a = (uint32_t)i;
        s.b = (uint32_t)i + 1;
        s.k = k;
        s.kd = kd;
        s.rest = length / segments;
        s.order = (uint32_t)i;
        st = spn_world_add_spring(w, &s, NULL);
    }
    if (st != SPN_OK) {
        spn_world_destroy(w);
        return st;
    }
    *out = w;
    return SPN_OK;
}

spn_status spn_scene_cloth(const spn_world_def *world_def, int nx, int ny, double size, double height, double mass,
                           double k, double kd, unsigned pinned_corners, spn_world **out)
{
    *out = NULL;
    if (nx < 2 || ny < 2 || nx > 10000 || ny > 10000 || !(size > 0) || !(mass > 0) || !(k > 0) || !(kd >= 0))
        return spn_error(SPN_ERR_INVALID, "cloth: need at least 2x2 particles and positive size, mass, stiffness");
    spn_world *w = spn_world_create(world_def);
    if (!w) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    double m = mass / ((double)nx * ny);
    for (int j = 0; j < ny && st == SPN_OK; j++)
        for (int i = 0; i < nx && st == SPN_OK; i++) {
            spn_particle_def p = spn_particle_def_default();
            p.position = spn_v3(size * i / (nx - 1) - size / 2, height, size * j / (ny - 1) - size / 2);
            p.mass = m;
            int corner = (i == 0 && j == 0) ? 0 : (i == nx - 1 && j == 0) ? 1 : (i == 0 && j == ny - 1) ? 2
                       : (i == nx - 1 && j == ny - 1) ? 3 : -1;
            p.fixed = corner >= 0 && (pinned_corners & (1u << corner));
            st = spn_world_add_particle(w, &p, NULL);
        }
    static const int offs[4][3] = {{1, 0, 0}, {0, 1, 0}, {1, 1, 1}, {-1, 1, 1}};
    for (int j = 0; j < ny && st == SPN_OK; j++)
        for (int i = 0; i < nx && st == SPN_OK; i++)
            for (int o = 0; o < 4 && st == SPN_OK; o++) {
                int i2 = i + offs[o][0], j2 = j + offs[o][1];
                if (i2 < 0 || i2 >= nx || j2 >= ny) continue;
                spn_spring_def s = spn_spring_def_default();
                s.a = (uint32_t)(j * nx + i);
                s.b = (uint32_t)(j2 * nx + i2);
                s.k = offs[o][2] ? k / 2 : k;
                s.kd = kd;
                s.tag = SPN_THREAD_STRETCH;
                st = spn_world_add_spring(w, &s, NULL);
            }
    if (st != SPN_OK) {
        spn_world_destroy(w);
        return st;
    }
    *out = w;
    return SPN_OK;
}

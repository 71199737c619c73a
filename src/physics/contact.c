/* One-sided point-segment contacts inside the implicit solver.
 *
 * A prey of a few hundred mg pressing on threads whose particles weigh
 * 1e-10 kg: as an explicit force the contact needs dt < sqrt(m / k) ~ 1e-7 s
 * (minutes of computing per simulated tenth of a second). Here the contact
 * joins backward Euler's system like a spring (Baraff & Witkin 1998, eq. 6),
 * so the light thread particles move with the heavy body at the solver's
 * normal step.
 *
 * Contact c: separation g = x_p - (1 - u) x_a - u x_b, y = depth - n . dg,
 * force k y n on p, -(1 - u) k y n on a, -u k y n on b. With G the 3 x 9 map
 * x -> g, df/dx = -k G^T n n^T G (n and u frozen over the step; the curvature
 * term of a rotating normal is left out, as Baraff & Witkin leave out the
 * damping's dependence on x, so A stays symmetric positive definite). The
 * system gains A += h^2 k G^T n n^T G and b += h k G^T n (depth - h n . G v0).
 * Rows of fixed particles stay the identity.
 *
 * One-sided: the linear model pulls where the real contact would let go. After
 * a solve, every active contact whose end y = depth - h n . G v1 is on the
 * wrong side (negative for a push, positive for a tether) is dropped and the
 * step solved again (at most a few rounds; a contact dropped stays dropped for
 * the step, so the rounds end). */
#include "world_internal.h"

#include <stdlib.h>
#include <string.h>

spn_status spn_world_set_contacts(spn_world *w, const spn_contact *contacts, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        const spn_contact *c = &contacts[i];
        if (c->p >= w->np || c->a >= w->np || c->b >= w->np || !(c->u >= 0 && c->u <= 1) || !(c->k >= 0) ||
            !spn_v3_finite(c->n))
            return spn_error(SPN_ERR_INVALID, "contact %u: particles must exist, u in [0, 1], k >= 0, n finite", i);
    }
    if (n > w->cap_contacts) {
        spn_contact *p = realloc(w->contacts, n * sizeof *p);
        if (!p) return spn_error(SPN_ERR_NOMEM, "out of memory for %u contacts", n);
        w->contacts = p;
        w->cap_contacts = n;
    }
    if (n) memcpy(w->contacts, contacts, n * sizeof *contacts);
    w->ncontacts = n;
    return SPN_OK;
}

/* n . G q for the contact's three particles. */
static double along(const spn_contact *c, const spn_vec3 *q)
{
    const spn_vec3 g = spn_v3_sub(q[c->p], spn_v3_add(spn_v3_scale(q[c->a], 1 - c->u), spn_v3_scale(q[c->b], c->u)));
    return spn_v3_dot(c->n, g);
}

/* out += s G^T n, skipping fixed particles (their rows are the identity). */
static void spread(const spn_world *w, const spn_contact *c, double s, spn_vec3 *out)
{
    const uint32_t id[3] = {c->p, c->a, c->b};
    const double wt[3] = {1, -(1 - c->u), -c->u};
    for (int j = 0; j < 3; j++)
        if (w->inv_mass[id[j]] > 0) out[id[j]] = spn_v3_add(out[id[j]], spn_v3_scale(c->n, s * wt[j]));
}

static bool involved(const spn_contact *c, uint32_t i) { return c->p == i || c->a == i || c->b == i; }

/* h^2 k w_i^2 n n^T per active contact added to particle i's block (its
 * springs' part, which build_rhs put there). */
static void contact_block(const spn_world *w, uint32_t i, double h, double *pblock)
{
    double *d = pblock + 6 * (size_t)i;
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        if (!c->active || !involved(c, i)) continue;
        const double wt = (c->p == i ? 1 : 0) - (c->a == i ? 1 - c->u : 0) - (c->b == i ? c->u : 0);
        const double s = h * h * c->k * wt * wt;
        const spn_vec3 n = c->n;
        d[0] += s * n.x * n.x, d[1] += s * n.y * n.y, d[2] += s * n.z * n.z;
        d[3] += s * n.x * n.y, d[4] += s * n.x * n.z, d[5] += s * n.y * n.z;
    }
}

void spn__contact_begin(spn_world *w)
{
    for (uint32_t k = 0; k < w->ncontacts; k++) w->contacts[k].active = true;
}

void spn__contact_system(spn_world *w, double h, spn_vec3 *b, double *pblock)
{
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        if (c->active) spread(w, c, h * c->k * (c->depth - h * along(c, w->v)), b);
    }
    /* Each particle's block once (serial: a handful of contacts). */
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        const uint32_t id[3] = {c->p, c->a, c->b};
        for (int j = 0; j < 3; j++) {
            const uint32_t i = id[j];
            if (!(w->inv_mass[i] > 0)) continue;
            bool seen = false;
            for (uint32_t q = 0; q < k && !seen; q++) seen = involved(&w->contacts[q], i);
            for (int q = 0; q < j && !seen; q++) seen = id[q] == i;
            if (!seen) contact_block(w, i, h, pblock);
        }
    }
}

double spn__contact_apply(const spn_world *w, double h, const spn_vec3 *p, spn_vec3 *ap)
{
    double dot = 0;
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        if (!c->active) continue;
        const double g = along(c, p), s = h * h * c->k * g;
        spread(w, c, s, ap);
        dot += s * g;
    }
    return dot;
}

bool spn__contact_release(spn_world *w, double h, const spn_vec3 *dv)
{
    bool changed = false;
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        spn_contact *c = &w->contacts[k];
        if (!c->active) continue;
        const double y = c->depth - h * (along(c, w->v) + along(c, dv));
        if (c->pull ? y > 0 : y < 0) {
            c->active = false;
            changed = true;
        }
    }
    return changed;
}

const spn_contact *spn_world_contacts(const spn_world *w, uint32_t *n)
{
    if (n) *n = w->ncontacts;
    return w->contacts;
}

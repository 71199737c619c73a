/* The equilibrium solver's multigrid (equilibrium_mg.c) as the preconditioner
 * of the implicit step's CG (implicit.c).
 *
 * Backward Euler's matrix A = M - h D - h^2 K is the spring Hessian (with
 * damping and air terms) plus a mass diagonal: the same graph and the same
 * 50:1 thread anisotropy the multigrid was built for, only better
 * conditioned. Block Jacobi needs 400-600 CG iterations a step on a 20k web
 * at dt 0.05 s; the multigrid a few tens (docs/physics-implicit-mg.md).
 *
 * The particles that carry a live spring (spn__eq_init's free set) get the
 * V-cycle; every other free particle (a prey body held only by contacts) its
 * inverted 3x3 block; fixed rows stay zero. Level 0 is assembled every step
 * from the per-spring Jacobian: for spring s with u, iso, axial, air the
 * off-diagonal block is -(iso - air) I - (axial + air) u u^T, and a particle's
 * diagonal block is the one block Jacobi inverts (contacts included: the
 * contacts' couplings between particles are left out, which keeps the
 * preconditioner symmetric positive definite; CG still solves the full A).
 *
 * Reuse: the hierarchy (aggregates, prolongators, coarse operators) is built
 * once and kept while the set of live springs and fixed particles is the
 * same; each step refreshes level 0 and the line factors only, as the
 * equilibrium solver does between Newton steps. A break, a new fixed point
 * or a recompiled world changes the signature and the hierarchy is rebuilt.
 * On a hub + rings x radials web SPN_PRECOND_CYCLIC, and auto from
 * SPN__IMPLICIT_MG_MIN particles at any step, take the cyclic preconditioner (equilibrium_cyclic.c)
 * on the same level 0 instead of the V-cycle: the 20k web in a breeze at
 * 1/60 s, 15.2 -> 1.9 CG and 79 -> 13 ms a step (docs/physics-implicit-mg.md).
 * Where auto would take the V-cycle, a web of up to SPN__IMPLICIT_DIRECT_MAX
 * free particles gets a sparse Cholesky factor of level 0 instead
 * (sparse_chol.c; ordered and analysed once with the hierarchy's signature):
 * a factor of one step's matrix preconditions the next steps too while a
 * step on it costs no more than the average step since the factorisation,
 * its price included (spn__imp_mg_solved: the next step factorises), and
 * while a solve on it has not run that price past that average
 * (spn__imp_mg_restart_due: the solve factorises this step's matrix and
 * goes on; outrun so in the step after its own, the next steps factorise
 * at their start), and until the step length changes. The Araneus web in
 * air: 15.8 -> 3.7 CG and 6.3 -> 1.6 ms a step (docs/physics-implicit-mg.md,
 * "A factorised preconditioner"). A small web's steps with contacts take
 * the factor or block Jacobi, a lattice web's too (spn__imp_mg_prepare).
 * The preconditioner is a fixed linear map within a solve (a restart begins
 * CG again from where it is), so CG's result
 * differs from block Jacobi's only within the solver tolerance; every product
 * is summed in a fixed order, so the bits do not depend on the thread count. */
#include "core/big_alloc.h"
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"
#include "sparse_chol.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Prey particles whose rows prey_rows keeps exact (the impact's MAX_PREY). */
#define SPN__PREY_ROWS_MAX 8u

struct spn__imp_mg {
    spn__eq e;
    spn__mg *mg;
    spn__cyc *cyc;     /* a rings x radials web: the cyclic preconditioner instead of the V-cycle */
    spn__chol *chol;   /* a small web under auto: a factor of an earlier step's matrix instead */
    bool chol_ready;   /* chol holds a factor */
    bool chol_on;      /* the factor preconditions this step (on a lattice web: a step with contacts) */
    bool chol_tried;   /* the factor was analysed (at create; a lattice web's at its first contacts) */
    bool chol_stale;   /* the last step cost more than the factor's average step: factorise */
    bool chol_fresh;   /* the factor is of this step's matrix */
    double chol_h;     /* the step the factor's matrix was assembled for */
    uint64_t cycle_iterations; /* since the factorisation: its price and the CG iterations */
    uint32_t cycle_steps;      /* ... over this many steps (0: none yet) */
    uint32_t hold, hold_len;   /* steps left that factorise at their start; the last hold's length */
    uint32_t factorisations;
    uint32_t *espring; /* eq spring -> internal spring id */
    double *inv0;      /* 6 n: inverted diagonal blocks in eq order */
    double *r, *z;     /* 3 n */
    uint64_t sig;      /* of the live springs and fixed particles it was built for */
    bool failed;       /* the build failed for this signature: block Jacobi until it changes */
    /* Steps with contacts on the factor (prey_rows): the prey's rows and
     * columns of A kept exactly, by their Schur complement on the factor. */
    int32_t *local;    /* world particle -> eq id, -1 for none */
    double h;          /* the step prepare was last asked for */
    uint32_t nprey;    /* prey (contacts' bodies outside the system) kept so; 0: block Jacobi's */
    uint32_t cols_cap; /* prey the columns have room for */
    uint32_t prey[SPN__PREY_ROWS_MAX];
    double *cols;      /* 3 nprey columns of 3 n: B, the web's rows of the prey's columns of A */
    double *xcols;     /* the same: X = F^-1 B */
    double schur[3 * SPN__PREY_ROWS_MAX * 3 * SPN__PREY_ROWS_MAX]; /* S = C - B^T X, its Cholesky factor */
};

/* A change of choice drops the hierarchy: create() decided from the choice
 * whether it holds the cyclic preconditioner or the V-cycle, so kept it would
 * go on serving the old choice (multigrid then cyclic on a lattice web: still
 * the V-cycle), and a choice that no longer wants it (spn_web_settle's cyclic
 * put back to auto on a small web) would leave it allocated for nothing. The
 * next step that wants one builds it afresh. */
spn_status spn_world_set_implicit_preconditioner(spn_world *w, spn_precond p)
{
    uint8_t code;
    switch (p) {
    case SPN_PRECOND_AUTO: code = 0; break;
    case SPN_PRECOND_BLOCK_JACOBI: code = 1; break;
    case SPN_PRECOND_MULTIGRID: code = 2; break;
    case SPN_PRECOND_CYCLIC: code = 3; break;
    default:
        return spn_error(SPN_ERR_INVALID, "implicit preconditioner: block-jacobi, multigrid, cyclic or auto, not %s",
                         spn_precond_name(p));
    }
    if (code != w->implicit_pc) {
        spn__imp_mg_free(w->imp_mg);
        w->imp_mg = NULL;
        w->implicit_pc = code;
        w->imp_bj_long = 0;
    }
    return SPN_OK;
}

spn_precond spn_world_implicit_preconditioner(const spn_world *w)
{
    static const spn_precond kinds[] = {SPN_PRECOND_AUTO, SPN_PRECOND_BLOCK_JACOBI, SPN_PRECOND_MULTIGRID,
                                        SPN_PRECOND_CYCLIC};
    return kinds[w->implicit_pc];
}

void spn__imp_mg_free(spn__imp_mg *m)
{
    if (!m) return;
    spn__mg_free(m->mg);
    spn__cyc_free(m->cyc);
    spn__chol_free(m->chol);
    spn__eq_free(&m->e);
    free(m->espring), free(m->inv0), free(m->r), free(m->z);
    free(m->local), free(m->cols), free(m->xcols);
    free(m);
}

/* FNV-1a over the dead springs and the fixed particles (O(springs + particles),
 * nothing next to one CG iteration). */
static uint64_t signature(const spn_world *w)
{
    uint64_t h = 1469598103934665603u;
#define MIX(v) (h = (h ^ (uint64_t)(v)) * 1099511628211u)
    MIX(w->np), MIX(w->ns);
    for (uint32_t s = 0; s < w->ns; s++)
        if (!(w->hs[s].k > 0)) MIX(s);
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] == 0) MIX(i | 0x80000000u);
#undef MIX
    return h;
}

/* The eq spring order of spn__eq_init (gather_springs), mapped to internal ids. */
static bool map_springs(spn__imp_mg *m, const spn_world *w)
{
    const spn__eq *e = &m->e;
    int32_t *local = m->local = malloc((w->np ? w->np : 1) * sizeof *local);
    m->espring = malloc((e->m ? e->m : 1) * sizeof *m->espring);
    if (!local || !m->espring) return false;
    for (uint32_t i = 0; i < w->np; i++) local[i] = -1;
    for (uint32_t l = 0; l < e->nl; l++) local[e->world_id[l]] = (int32_t)l;
    uint32_t k = 0;
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t s = 0; s < w->ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            if (si.broken || !(si.k > 0) || si.a == si.b) continue;
            int32_t a = local[si.a], b = local[si.b];
            bool fa = a >= 0 && (uint32_t)a < e->n, fb = b >= 0 && (uint32_t)b < e->n;
            if ((!fa && !fb) || (pass == 0) != (fa && fb)) continue;
            if (k < e->m) m->espring[k] = w->iperm[s];
            k++;
        }
    return k == e->m;
}

static void analyse(spn__imp_mg *m)
{
    m->chol_tried = true;
    if (m->e.n <= SPN__IMPLICIT_DIRECT_MAX)
        m->chol = spn__chol_analyze(m->e.n, m->e.adj_start, m->e.adj_other, 200 * (size_t)m->e.n);
}

static spn__imp_mg *create(const spn_world *w)
{
    spn__imp_mg *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.threads = 0; /* the world's */
    if (spn__eq_init(&m->e, w, &d) != SPN_OK) {
        free(m);
        return NULL;
    }
    /* without the spring blocks the V-cycle's level-0 residual uses the
     * assembled matrix (the Jacobian's air terms do not fit that form) */
    free(m->e.hs);
    m->e.hs = NULL;
    m->e.offd = spn__big_alloc(12 * (size_t)(m->e.m ? m->e.m : 1) * sizeof *m->e.offd);
    size_t n = m->e.n ? m->e.n : 1;
    m->inv0 = malloc(6 * n * sizeof *m->inv0);
    m->r = malloc(3 * n * sizeof *m->r);
    m->z = malloc(3 * n * sizeof *m->z);
    if (!m->e.offd || !m->inv0 || !m->r || !m->z || !map_springs(m, w)) {
        spn__imp_mg_free(m);
        return NULL;
    }
    if (w->implicit_pc == 0 || w->implicit_pc == 3) { /* auto or cyclic: a lattice web takes it */
        const char *why;
        m->cyc = spn__cyc_build(&m->e, &why);
    }
    /* auto on a web that is no lattice: the factor (NULL if it would hold
     * more than 200 numbers a particle: the V-cycle then); a lattice web's
     * only for its steps with contacts (spn__imp_mg_prepare) */
    if (w->implicit_pc == 0 && !m->cyc) analyse(m);
    return m;
}

/* Each active contact's coupling of its segment's ends, h^2 k (1 - u) u n n^T
 * (contact.c), into the off-diagonal blocks of their spring's entries, for
 * the factor (prey_rows); their diagonal parts are in level 0 already. */
static void contact_offd(spn__imp_mg *m, const spn_world *w, double h)
{
    spn__eq *e = &m->e;
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        const int32_t a = m->local[c->a], b = m->local[c->b];
        if (!c->active || a < 0 || b < 0 || (uint32_t)a >= e->n || (uint32_t)b >= e->n || a == b) continue;
        const double s = h * h * c->k * (1 - c->u) * c->u;
        const spn_vec3 n = c->n;
        const double add[6] = {s * n.x * n.x, s * n.y * n.y, s * n.z * n.z,
                               s * n.x * n.y, s * n.x * n.z, s * n.y * n.z};
        for (int end = 0; end < 2; end++) {
            const int32_t row = end ? b : a, col = end ? a : b;
            for (uint32_t j = e->adj_start[row]; j < e->adj_start[row + 1]; j++)
                if (e->adj_other[j] == col) { /* (the factor sums entries between one pair: the first takes it) */
                    for (int f = 0; f < 6; f++) e->offd[6 * (size_t)j + f] += add[f];
                    break;
                }
        }
    }
}

/* Level 0 from the step's Jacobian (w->jac) and diagonal blocks (w->pblock,
 * contacts included). */
static void assemble(spn__imp_mg *m, const spn_world *w, double h)
{
    spn__eq *e = &m->e;
    const uint32_t n = e->n;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, n))
    for (uint32_t i = 0; i < n; i++) {
        const uint32_t wid = e->world_id[i];
        memcpy(e->diag + 6 * (size_t)i, w->pblock + 6 * (size_t)wid, 6 * sizeof *e->diag);
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
            double *o = e->offd + 6 * (size_t)j;
            if (e->adj_other[j] < 0) {
                memset(o, 0, 6 * sizeof *o);
                continue;
            }
            const spn__jac *jc = &w->jac[m->espring[e->adj[j] >> 1]];
            const double iso = jc->iso - jc->air, ax = jc->axial + jc->air;
            const spn_vec3 u = jc->u;
            o[0] = -(iso + ax * u.x * u.x), o[1] = -(iso + ax * u.y * u.y), o[2] = -(iso + ax * u.z * u.z);
            o[3] = -ax * u.x * u.y, o[4] = -ax * u.x * u.z, o[5] = -ax * u.y * u.z;
        }
    }
    if (m->chol_on && w->ncontacts) contact_offd(m, w, h);
}

/* The slot of prey particle p among the first np of m->prey (np: none). */
static uint32_t prey_slot(const spn__imp_mg *m, uint32_t np, uint32_t p)
{
    uint32_t q = 0;
    while (q < np && m->prey[q] != p) q++;
    return q;
}

/* The prey's rows and columns of A kept exact on top of the factor F. A
 * prey's body has no springs, so the system (level 0) leaves it out, and
 * its contacts couple it to the web: with B the web's rows of the prey's
 * columns (h^2 k w_e n n^T at each contact's segment ends) and C the prey's
 * own blocks, M = [F B; B^T C] is applied through its Schur complement
 * S = C - B^T F^-1 B, three rows a prey (spn__imp_mg_apply). CG otherwise
 * builds these couplings an iteration at a time. Needs 3 solves a prey
 * each time the factor or the contacts change (prepare, refactor). */
static void prey_rows(spn__imp_mg *m, const spn_world *w, double h)
{
    const spn__eq *e = &m->e;
    const size_t len = 3 * (size_t)e->n;
    m->nprey = 0;
    if (!m->chol_on || !m->chol_ready || !w->ncontacts || !e->n) return;
    uint32_t np = 0;
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        if (!c->active || m->local[c->p] >= 0 || !(w->inv_mass[c->p] > 0)) continue;
        if (prey_slot(m, np, c->p) == np && np < SPN__PREY_ROWS_MAX) m->prey[np++] = c->p;
    }
    if (!np) return;
    if (np > m->cols_cap) { /* (out of memory: block Jacobi's blocks for the prey) */
        free(m->cols), free(m->xcols);
        m->cols = malloc(3 * np * len * sizeof *m->cols);
        m->xcols = malloc(3 * np * len * sizeof *m->xcols);
        m->cols_cap = m->cols && m->xcols ? np : 0;
        if (!m->cols_cap) return;
    }
    memset(m->cols, 0, 3 * np * len * sizeof *m->cols);
    for (uint32_t k = 0; k < w->ncontacts; k++) {
        const spn_contact *c = &w->contacts[k];
        const uint32_t q = prey_slot(m, np, c->p);
        if (!c->active || q == np) continue;
        const uint32_t ends[2] = {c->a, c->b};
        const double wt[2] = {-(1 - c->u), -c->u}, nv[3] = {c->n.x, c->n.y, c->n.z};
        for (int t = 0; t < 2; t++) {
            const int32_t l = m->local[ends[t]];
            if (l < 0 || (uint32_t)l >= e->n) continue;
            for (int cc = 0; cc < 3; cc++)
                for (int r = 0; r < 3; r++)
                    m->cols[(3 * q + cc) * len + 3 * (size_t)l + r] += h * h * c->k * wt[t] * nv[r] * nv[cc];
        }
    }
    for (uint32_t i = 0; i < 3 * np; i++) spn__chol_solve(m->chol, m->cols + i * len, m->xcols + i * len);
    /* S = C - B^T X, lower triangle, then its Cholesky factor in place */
    const uint32_t d = 3 * np;
    double *S = m->schur;
    for (uint32_t i = 0; i < d; i++)
        for (uint32_t j = 0; j <= i; j++) {
            double dot = 0;
            for (size_t f = 0; f < len; f++) dot += m->cols[i * len + f] * m->xcols[j * len + f];
            S[i * d + j] = -dot;
        }
    for (uint32_t q = 0; q < np; q++) {
        const double *cq = w->pblock + 6 * (size_t)m->prey[q]; /* the prey's block */
        static const uint8_t sym[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b <= a; b++) S[(3 * q + a) * d + 3 * q + b] += cq[sym[a][b]];
    }
    /* not definite (a stale factor): block Jacobi's blocks */
    if (!spn__dense_cholesky(S, d, 1)) return;
    for (uint32_t j = 0; j < d; j++)
        if (!isfinite(S[j * d + j])) return;
    m->nprey = np;
}

/* A factorisation of level 0 (assemble): false when the matrix is not
 * positive definite, or refused for a test (spn__imp_mg_refuse). */
static bool factorise(spn_world *w, spn__imp_mg *m)
{
    bool ok = spn__chol_factor(m->chol, m->e.diag, m->e.offd);
    m->factorisations++;
    if (w->imp_refuse) w->imp_refuse--, ok = false;
    return ok;
}

/* A refusal forced for a test (spn__imp_mg_refuse_setup), used up. */
static bool refused(spn_world *w, unsigned which)
{
    if (!(w->imp_refuse_pc & which)) return false;
    w->imp_refuse_pc &= (uint8_t)~which;
    return true;
}

/* spn__imp_mg_prepare's choice and set-up, the inverses aside. */
static bool prepare(spn_world *w, double h)
{
    /* auto: where the multigrid pays (the cyclic preconditioner instead on a
     * lattice web); on a big lattice web (w->lat: numbered as the cyclic
     * preconditioner reads it) the cyclic preconditioner at short steps too,
     * where block Jacobi still needs hundreds of iterations (dt 1e-4 s:
     * 158, 614 and 1,000 on the 5k, 100k and 1M webs, the cyclic 2); block
     * Jacobi on small webs and on short steps of other webs, where it needs
     * few iterations and nothing to set up, unless it took too many at this
     * step length or a shorter one (imp_bj_long: a web of stiff silk) */
    const bool auto_pc = w->implicit_pc == 0, auto_big = auto_pc && w->np >= SPN__IMPLICIT_MG_MIN;
    const bool long_rule = auto_pc && w->imp_bj_long > 0 && h >= w->imp_bj_long;
    const bool auto_mg = (auto_big && h >= SPN__IMPLICIT_MG_DT) || long_rule;
    const bool want = w->implicit_pc >= 2 || auto_mg || (auto_big && w->lat);
    if (!want) return false;
    const uint64_t sig = signature(w);
    if (w->imp_mg && w->imp_mg->sig != sig) {
        spn__imp_mg_free(w->imp_mg);
        w->imp_mg = NULL;
    }
    if (!w->imp_mg) {
        if (!(w->imp_mg = create(w))) return false; /* out of memory: block Jacobi does the step */
        w->imp_mg->sig = sig;
    }
    spn__imp_mg *m = w->imp_mg;
    m->h = h;
    m->nprey = 0;
    if (m->failed || m->e.n == 0) return false;
    if (w->implicit_pc == 0 && !auto_mg && !m->cyc) return false; /* a short step without the cyclic one */
    /* A small web's steps with contacts take the factor, or block Jacobi.
     * Every preconditioner here sees a held prey's particles through their
     * diagonal blocks only, so CG must build the prey's coupling to the web
     * itself: on top of the exact factor that takes a few iterations (the
     * difference is of low rank: test_anim_strike's Araneus webs 9-17 CG a
     * step, 17 s -> 1.2 s, where block Jacobi ran to its 1,000), but on top
     * of the V-cycle or the cyclic preconditioner many (the strike on
     * scene:orb 12 s -> 39 s, the small Araneus webs once 12 s -> 80 s). */
    const bool contacts = auto_pc && !auto_big && w->ncontacts;
    if (contacts && !m->chol_tried) analyse(m);
    if (contacts && !m->chol) return false;
    m->chol_on = m->chol && (!m->cyc || contacts);
    /* level 0 for a factorisation, the cyclic preconditioner or the
     * V-cycle: not when a kept factor serves (spn__imp_mg_refactor
     * assembles it if the step then wants a factor of its own) */
    if (m->chol_on) {
        m->chol_fresh = !m->chol_ready || m->chol_stale || h != m->chol_h || m->hold > 0;
        if (m->hold) m->hold--;
        if (m->chol_fresh) {
            assemble(m, w, h);
            m->chol_ready = factorise(w, m);
            m->chol_h = h;
        }
        m->chol_stale = false;
        if (m->chol_ready) {
            prey_rows(m, w, h);
            return true;
        }
        spn__chol_free(m->chol); /* not definite: the multigrid from here on */
        m->chol = NULL;
        m->chol_on = false;
        if (contacts) return false;
    } else assemble(m, w, h);
    if (m->cyc) {
        if (spn__cyc_factor(m->cyc, &m->e) && !refused(w, SPN__REFUSE_CYCLIC)) return true;
        spn__cyc_free(m->cyc); /* not definite: the multigrid from here on */
        m->cyc = NULL;
    }
    const uint32_t n = m->e.n; /* the V-cycle's smoother: level 0's inverted blocks */
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, n))
    for (uint32_t i = 0; i < n; i++) spn__invert_sym3(m->e.diag + 6 * (size_t)i, m->inv0 + 6 * (size_t)i);
    if (spn__mg_setup(&m->mg, &m->e, m->inv0) != SPN_OK || refused(w, SPN__REFUSE_VCYCLE)) {
        spn__mg_free(m->mg);
        m->mg = NULL;
        m->failed = true;
        return false;
    }
    return true;
}

bool spn__imp_mg_prepare(spn_world *w, double h)
{
    if (!prepare(w, h)) return false;
    spn__implicit_invert(w, w->imp_mg->local, w->imp_mg->e.n); /* the particles outside the system */
    return true;
}

void spn__imp_mg_apply(const spn_world *w, const spn_vec3 *r, spn_vec3 *z)
{
    const spn__imp_mg *m = w->imp_mg;
    const spn__eq *e = &m->e;
    const uint32_t n = e->n, np = w->np;
    const double *pinv = w->pinv;
    const int32_t *local = m->local;
    /* (a factorisation that failed mid-solve, spn__imp_mg_refactor: block
     * Jacobi for all) */
    const bool bj_only = m->chol_on && !m->chol_ready;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) { /* block Jacobi for the particles outside the system */
        if (!bj_only && (uint32_t)local[i] < n) continue; /* (-1: none) */
        const double *q = pinv + 6 * (size_t)i;
        const spn_vec3 ri = r[i];
        z[i] = spn_v3(q[0] * ri.x + q[3] * ri.y + q[4] * ri.z, q[3] * ri.x + q[1] * ri.y + q[5] * ri.z,
                      q[4] * ri.x + q[5] * ri.y + q[2] * ri.z);
    }
    if (bj_only) return;
    const uint32_t d = 3 * m->nprey; /* (0 unless the factor preconditions: prey_rows) */
    if (m->chol_on && !d) { /* straight from the world's order to the factor's and back */
        spn__chol_solve_at(m->chol, e->world_id, (const double *)r, (double *)z);
        return;
    }
    for (uint32_t i = 0; i < n; i++) memcpy(m->r + 3 * (size_t)i, &r[e->world_id[i]], 3 * sizeof(double));
    if (m->chol_on) spn__chol_solve(m->chol, m->r, m->z);
    else if (m->cyc) spn__cyc_apply(m->cyc, e, m->r, m->z);
    else spn__mg_apply(m->mg, e, m->r, m->z);
    double t[3 * SPN__PREY_ROWS_MAX];
    if (d) { /* the prey's rows (prey_rows): t = S^-1 (r_p - B^T y), then y -= X t */
        const size_t len = 3 * (size_t)n;
        for (uint32_t i = 0; i < d; i++) {
            double v = (&r[m->prey[i / 3]].x)[i % 3];
            for (size_t f = 0; f < len; f++) v -= m->cols[i * len + f] * m->z[f];
            t[i] = v;
        }
        spn__dense_cholesky_solve(m->schur, d, t, t, 1);
        for (uint32_t i = 0; i < d; i++)
            for (size_t f = 0; f < len; f++) m->z[f] -= m->xcols[i * len + f] * t[i];
    }
    for (uint32_t i = 0; i < n; i++) memcpy(&z[e->world_id[i]], m->z + 3 * (size_t)i, 3 * sizeof(double));
    for (uint32_t q = 0; 3 * q < d; q++) z[m->prey[q]] = spn_v3(t[3 * q], t[3 * q + 1], t[3 * q + 2]);
}

bool spn__imp_mg_refactor(spn_world *w)
{
    spn__imp_mg *m = w->imp_mg;
    if (!m || !m->chol_on || m->chol_fresh) return false;
    assemble(m, w, m->h); /* (prepare did not: the kept factor served) */
    /* not definite: block Jacobi for the rest of this solve (apply), and the
     * next step's prepare factorises again, and drops the factor if that
     * fails too */
    m->chol_ready = factorise(w, m);
    m->chol_fresh = true;
    if (!m->chol_ready) spn__implicit_invert(w, NULL, 0);
    prey_rows(m, w, m->h);
    /* A factor that one step has outrun says the next will outrun this one
     * too: the next steps factorise at their start, 1, 2, 4 ... 16 of them
     * as such steps keep coming (a kept factor that serves resets it). */
    if (m->cycle_steps == 1) {
        const uint32_t twice = 2 * m->hold_len;
        m->hold = m->hold_len = !twice ? 1 : twice < SPN__IMPLICIT_HOLD_MAX ? twice : SPN__IMPLICIT_HOLD_MAX;
    }
    return true;
}

/* When to factorise again. A factor's steps cost its price once
 * (SPN__IMPLICIT_FACTOR_PRICE) and then each step's CG iterations, which
 * grow as the matrix moves away from the factor's. The average cost of a
 * step since the factorisation falls while a step costs less than it, and
 * is least where the next step would cost more: then the next step
 * factorises. A growing sequence has its least average there (the rule of
 * replacing a wearing part). The counts are the CG iterations, not times,
 * so the choice, and the bits, are the same on every machine. */
void spn__imp_mg_solved(spn_world *w, int iterations)
{
    spn__imp_mg *m = w->imp_mg;
    if (!m || !m->chol_on) return;
    const uint32_t it = (uint32_t)iterations;
    if (m->chol_fresh) {
        m->cycle_iterations = SPN__IMPLICIT_FACTOR_PRICE + it, m->cycle_steps = 1;
        return;
    }
    if ((uint64_t)it * m->cycle_steps > m->cycle_iterations) m->chol_stale = true;
    else if (m->cycle_steps == 1) m->hold_len = 0; /* a factor one step old served */
    m->cycle_iterations += it, m->cycle_steps++;
}

bool spn__imp_mg_restart_due(const spn_world *w, int iterations)
{
    const spn__imp_mg *m = w->imp_mg;
    if (!m || !m->chol_on || m->chol_fresh || !m->cycle_steps) return false;
    /* iterations > average + price: a factorisation now costs less than
     * what this solve has spent past an average step */
    return (uint64_t)iterations * m->cycle_steps >
           m->cycle_iterations + (uint64_t)SPN__IMPLICIT_FACTOR_PRICE * m->cycle_steps;
}

uint32_t spn__imp_mg_factorisations(const spn_world *w)
{
    return w->imp_mg && w->imp_mg->chol ? w->imp_mg->factorisations : 0;
}

void spn__imp_mg_refuse(spn_world *w, uint32_t n) { w->imp_refuse = n; }
void spn__imp_mg_refuse_setup(spn_world *w, unsigned which) { w->imp_refuse_pc = (uint8_t)which; }

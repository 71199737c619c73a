// Peer benchmark: the standard orb web (spn_scene_orb) stepped by Bullet's
// btSoftBody and by Spinneret's symplectic Euler in one run: same nodes,
// masses, fixed flags, springs, rest lengths, dt and step count. Prints one
// JSON line per size with both costs in ns per spring per step and the ratio.
//
// Bullet recomputes rest lengths from the current positions on its first
// step; the web is pre-strained, so after updateConstants() we clear
// m_bUpdateRtCst and write the rest lengths (m_rl, m_c1 = rl^2, m_c0) ourselves.
// Bullet's links are position-based (stiffness kLST in [0, 1], one iteration;
// we give each link the kLST that matches our spring's stiffness at this dt):
// the figure compares the cost of a step, and the strain error after the run
// (against a reference run at a tenth of the step) says what each step buys.
// This is the one place C++ is allowed (Bullet is C++).
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>

extern "C" {
#include <spinneret/spinneret.h>
}

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <vector>

static double seconds_now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU time of the process: on a shared machine the wall clock also measures
// the neighbours (both runs here are single-threaded).
static double cpu_now()
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static spn_world *make_web(int rings, int radials)
{
    spn_world_def def = spn_world_def_default();
    def.threads = 1;
    spn_orb_scene_def d = spn_orb_scene_def_default();
    d.rings = rings;
    d.radials = radials;
    d.damping_ratio = 0; // Bullet's links have no axial damping: compare like with like
    d.tension_only = false;
    spn_world *w = nullptr;
    if (spn_scene_orb(&def, &d, &w) != SPN_OK) {
        std::fprintf(stderr, "bullet_orb: %s\n", spn_last_error());
        std::exit(1);
    }
    return w;
}

// Largest |strain - reference strain| over the springs of w.
static double strain_error(const spn_world *w, const std::vector<double> &ref)
{
    double e = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        e = std::fmax(e, std::fabs((si.length - si.rest) / si.rest - ref[s]));
    }
    return e;
}

static std::vector<double> strains(const spn_world *w)
{
    std::vector<double> out(spn_world_spring_count(w));
    for (uint32_t s = 0; s < out.size(); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        out[s] = (si.length - si.rest) / si.rest;
    }
    return out;
}

struct bullet_run {
    double ns_per_spring_step;
    double cpu_ns_per_spring_step;
    double strain_error;
};

static bullet_run run_bullet(const spn_world *w, double dt, int steps, const std::vector<double> &ref)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    btSoftBodyWorldInfo info;
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    info.m_dispatcher = &dispatcher;
    info.m_broadphase = &broadphase;
    spn_vec3 g = spn_world_get_def(w)->gravity;
    info.m_gravity.setValue(g.x, g.y, g.z);
    info.m_sparsesdf.Initialize();

    std::vector<btVector3> x(np);
    std::vector<btScalar> m(np);
    for (uint32_t i = 0; i < np; i++) {
        spn_vec3 p = spn_world_position(w, i);
        x[i].setValue(p.x, p.y, p.z);
        m[i] = spn_world_is_fixed(w, i) ? 0 : spn_world_mass(w, i);
    }
    btSoftBody *sb = new btSoftBody(&info, (int)np, x.data(), m.data());
    // A link's kLST is the fraction of its constraint error removed per step;
    // k dt^2 (1/m_a + 1/m_b) gives the same impulse per step as our spring of
    // stiffness k, so both engines step the same physical web.
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        btSoftBody::Material *mat = sb->appendMaterial();
        double im = (m[si.a] > 0 ? 1 / m[si.a] : 0) + (m[si.b] > 0 ? 1 / m[si.b] : 0);
        mat->m_kLST = (btScalar)std::fmin(1.0, si.k * dt * dt * im);
        sb->appendLink((int)si.a, (int)si.b, mat);
    }
    sb->m_cfg.piterations = 1;
    sb->m_cfg.kDP = 0;
    sb->m_cfg.collisions = 0;
    sb->updateConstants();
    sb->m_bUpdateRtCst = false;
    for (uint32_t s = 0; s < ns; s++) {
        btSoftBody::Link &l = sb->m_links[(int)s];
        l.m_rl = spn_world_spring(w, s).rest;
        l.m_c1 = l.m_rl * l.m_rl;
        l.m_c0 = (l.m_n[0]->m_im + l.m_n[1]->m_im) / l.m_material->m_kLST;
    }
    double t0 = seconds_now(), c0 = cpu_now();
    for (int k = 0; k < steps; k++) {
        sb->predictMotion(dt);
        sb->solveConstraints();
        sb->integrateMotion();
    }
    double t1 = seconds_now(), c1 = cpu_now();
    // Strain error of Bullet's end state, measured with our springs' rest lengths.
    spn_world *copy = spn_world_clone(w);
    for (uint32_t i = 0; i < np; i++) {
        const btVector3 &p = sb->m_nodes[(int)i].m_x;
        spn_world_set_position(copy, i, spn_v3(p.x(), p.y(), p.z()));
    }
    bullet_run r = {(t1 - t0) * 1e9 / ((double)ns * steps), (c1 - c0) * 1e9 / ((double)ns * steps),
                    strain_error(copy, ref)};
    spn_world_destroy(copy);
    delete sb;
    return r;
}

// Wall and CPU ns per spring-step of our symplectic Euler (one advance call)
// in `precision` (float32: Bullet's own precision, as Debian builds it).
// *path: "lattice" (the stencil step of a regular web) or "general". Set-up
// is not timed, as Bullet's (its soft body built, updateConstants) is not:
// the world is compiled and one short call takes the path the timed one
// will (allocating the lattice's arrays: on the 1M web tens of MB, touched
// for the first time), then its particles are put back where they were, so
// the timed call starts from w's state as Bullet's run does.
static void run_spinneret(spn_world *w, double dt, int steps, spn_precision precision, double *wall, double *cpu,
                          const char **path)
{
    spn_world_set_integrator(w, SPN_INTEGRATOR_SYMPLECTIC);
    spn_world_set_precision(w, precision);
    spn_world_compile(w);
    const uint32_t np = spn_world_particle_count(w);
    std::vector<spn_vec3> x(np), v(np);
    for (uint32_t i = 0; i < np; i++) x[i] = spn_world_position(w, i), v[i] = spn_world_velocity(w, i);
    const double time = spn_world_time(w);
    if (spn_world_advance(w, dt, 2) != SPN_OK) {
        std::fprintf(stderr, "bullet_orb: %s\n", spn_last_error());
        std::exit(1);
    }
    for (uint32_t i = 0; i < np; i++) spn_world_set_position(w, i, x[i]), spn_world_set_velocity(w, i, v[i]);
    spn_world_set_time(w, time);
    *path = spn_world_step_path(w);
    double t0 = seconds_now(), c0 = cpu_now();
    if (spn_world_advance(w, dt, steps) != SPN_OK) {
        std::fprintf(stderr, "bullet_orb: %s\n", spn_last_error());
        std::exit(1);
    }
    double per = 1e9 / ((double)spn_world_spring_count(w) * steps);
    *wall = (seconds_now() - t0) * per;
    *cpu = (cpu_now() - c0) * per;
}

// Cost at equal accuracy: Bullet steps the same simulated time with the step
// divided by 1, 2, 4, ... (its links' kLST recomputed for each step, so the
// physical web stays the same) until its largest strain error is no more than
// `target` (ours at the standard step); it gives up when the next run would
// pass `budget` CPU seconds or when two halvings in a row fail to beat its
// best error. Debian's Bullet is built with float32 btScalar, and a node's
// velocity is its position change over the step: each step's rounding of a
// position (~1e-8 m here) becomes a velocity error of rounding / dt, so a
// smaller step makes that noise larger (5k web, measured: 0.012, 0.15, 0.78
// at dt, dt/2, dt/4). Solver iterations are not the knob: with kLST matched
// to the spring stiffness, more iterations per step make the links stiffer,
// a different web, not a more accurate one.
struct equal_accuracy {
    int refine;           // step divisor of the last run
    double strain_error;  // its largest strain error
    double cpu_seconds;   // its CPU time for the whole simulated span
    bool reached;         // strain_error <= target
    int best_refine;      // the divisor that gave the smallest error
    double best_error;    // that error (Bullet's error need not fall as its step shrinks)
};

static equal_accuracy bullet_equal_accuracy(const spn_world *w, double dt, int steps, const std::vector<double> &ref,
                                            double target, const bullet_run &first, double budget)
{
    const double spring_steps = (double)spn_world_spring_count(w) * steps;
    equal_accuracy e = {1, first.strain_error, first.cpu_ns_per_spring_step * spring_steps * 1e-9,
                        first.strain_error <= target, 1, first.strain_error};
    int worse = 0; // successive runs with no better error than the best so far
    while (!e.reached && worse < 2 && 2 * e.cpu_seconds <= budget) {
        e.refine *= 2;
        bullet_run b = run_bullet(w, dt / e.refine, steps * e.refine, ref);
        e.strain_error = b.strain_error;
        e.cpu_seconds = b.cpu_ns_per_spring_step * spring_steps * e.refine * 1e-9;
        e.reached = b.strain_error <= target;
        if (b.strain_error < e.best_error) {
            e.best_error = b.strain_error;
            e.best_refine = e.refine;
            worse = 0;
        } else {
            worse++;
        }
        std::fprintf(stderr, "bullet_orb: %u particles, Bullet at dt/%d: strain error %.3g (target %.3g)\n",
                     spn_world_particle_count(w), e.refine, b.strain_error, target);
    }
    return e;
}

int main(int argc, char **argv)
{
    // The nominal dt of each web, divided down to the explicit stability limit
    // of its stiffest (innermost, shortest) segments (spn_anim_stable_substeps,
    // a Gershgorin bound with a 0.8 margin): at 1e-6 s the 100k web grows
    // without bound (slowly enough that no single step trips the blow-up
    // check), and the 1M web is unstable even at 1e-7 s (energy 1e14 J by step
    // 20), so it runs at a third of that.
    struct size { int rings, radials, steps; double dt; } sizes[] = {
        {40, 125, 2000, 1e-6}, {250, 400, 100, 1e-7}, {1000, 1000, 10, 1e-7}};
    // --small: the 5k web only; --budget S: CPU seconds the equal-accuracy
    // search may spend on Bullet per web (the runs double, so about 2 S at most).
    int nsizes = 3;
    double budget = 60;
    for (int i = 1; i < argc; i++) {
        if (std::strcmp(argv[i], "--small") == 0) nsizes = 1;
        else if (std::strcmp(argv[i], "--budget") == 0 && i + 1 < argc) budget = std::atof(argv[++i]);
        else if (std::strcmp(argv[i], "--sizes") == 0 && i + 1 < argc) nsizes = std::atoi(argv[++i]);
        else {
            std::fprintf(stderr, "usage: bench_peer_bullet [--small] [--sizes 1..3] [--budget CPU_SECONDS]\n");
            return 2;
        }
    }
    if (nsizes < 1 || nsizes > 3 || !(budget >= 0)) {
        std::fprintf(stderr, "bench_peer_bullet: --sizes must be 1..3 and --budget >= 0\n");
        return 2;
    }
    for (int k = 0; k < nsizes; k++) {
        const size &sz = sizes[k];
        spn_world *w0 = make_web(sz.rings, sz.radials); // initial state, for every Bullet run
        const double dt = sz.dt / spn_anim_stable_substeps(w0, 1 / sz.dt, SPN_INTEGRATOR_SYMPLECTIC, 0);
        spn_world *reference = spn_world_clone(w0);
        for (int i = 0; i < sz.steps * 10; i++) spn_world_step(reference, dt / 10);
        std::vector<double> ref = strains(reference);
        spn_world_destroy(reference);

        bullet_run b = run_bullet(w0, dt, sz.steps, ref);
        spn_world *w = spn_world_clone(w0);
        double ours, ours_cpu;
        const char *path;
        run_spinneret(w, dt, sz.steps, SPN_PRECISION_FLOAT64, &ours, &ours_cpu, &path);
        const double our_error = strain_error(w, ref);
        // the same run in float32, Bullet's precision: a like-for-like figure
        // beside the float64 one (which the ratio is about)
        spn_world *w32 = spn_world_clone(w0);
        double ours32, ours32_cpu;
        const char *path32;
        run_spinneret(w32, dt, sz.steps, SPN_PRECISION_FLOAT32, &ours32, &ours32_cpu, &path32);
        const double our_error32 = strain_error(w32, ref);
        spn_world_destroy(w32);
        const double spring_steps = (double)spn_world_spring_count(w) * sz.steps;
        equal_accuracy e = bullet_equal_accuracy(w0, dt, sz.steps, ref, our_error, b, budget);
        std::printf("{\"bench\":\"peer_bullet_softbody\",\"particles\":%u,\"springs\":%u,\"dt\":%g,\"steps\":%d,"
                    "\"threads\":1,\"bullet_ns_per_spring_step\":%.3f,\"spinneret_ns_per_spring_step\":%.3f,"
                    "\"ratio\":%.2f,\"bullet_cpu_ns_per_spring_step\":%.3f,\"spinneret_cpu_ns_per_spring_step\":%.3f,"
                    "\"cpu_ratio\":%.2f,\"bullet_strain_error\":%.3g,\"spinneret_strain_error\":%.3g,"
                    "\"spinneret_path\":\"%s\",\"equal_accuracy_bullet_refine\":%d,"
                    "\"equal_accuracy_bullet_strain_error\":%.3g,\"equal_accuracy_reached\":%s,"
                    "\"equal_accuracy_cpu_ratio\":%.2f,\"bullet_best_refine\":%d,\"bullet_best_strain_error\":%.3g,"
                    "\"spinneret_float32_ns_per_spring_step\":%.3f,\"spinneret_float32_cpu_ns_per_spring_step\":%.3f,"
                    "\"float32_cpu_ratio\":%.2f,\"spinneret_float32_strain_error\":%.3g}\n",
                    spn_world_particle_count(w), spn_world_spring_count(w), dt, sz.steps, b.ns_per_spring_step, ours,
                    b.ns_per_spring_step / ours, b.cpu_ns_per_spring_step, ours_cpu,
                    b.cpu_ns_per_spring_step / ours_cpu, b.strain_error, our_error, path, e.refine,
                    e.strain_error, e.reached ? "true" : "false", e.cpu_seconds / (ours_cpu * spring_steps * 1e-9),
                    e.best_refine, e.best_error, ours32, ours32_cpu, b.cpu_ns_per_spring_step / ours32_cpu,
                    our_error32);
        std::fflush(stdout);
        spn_world_destroy(w);
        spn_world_destroy(w0);
    }
    return 0;
}

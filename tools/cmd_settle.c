/* spinneret settle FILE -o OUT: step a web until it is at rest (or out of
 * time) with spn_world_settle and write the result as a web file. The report
 * goes to stderr; a run that blows up writes nothing and exits 1. Implicit
 * steps are held to creating no energy (--energy-limit,
 * spn_world_set_energy_limit).
 * --method equilibrium solves for the rest state directly instead
 * (spn_world_equilibrium: Newton on the potential; docs/physics-equilibrium.md). */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const CMD = "settle";

static void usage(FILE *out)
{
    spn_settle_def d = spn_settle_def_default();
    spn_equilibrium_def e = spn_equilibrium_def_default();
    fprintf(out,
            "usage: spinneret settle FILE -o OUT [options]\n"
            "Step the web in FILE until it is at rest, then write it to OUT (a web file).\n"
            "At rest: kinetic energy <= --max-kinetic and the largest net force on a free\n"
            "particle <= --tol. Exits 0 when converged or timed out (the report on stderr\n"
            "says which), 1 when the simulation blew up (nothing written).\n\n"
            "  -o, --output OUT      the settled web file (required; may be FILE itself;\n"
            "                        .spnw: binary, else JSON; FILE may be either)\n"
            "      --method NAME     dynamic (step in time, the default) or equilibrium (solve\n"
            "                        for the static rest state directly: springs, gravity, --load;\n"
            "                        no damping or time, velocities set to 0)\n"
            "      --rel-tol X       equilibrium: largest net force <= X times the largest spring\n"
            "                        tension at the start, in [0, 1]; default %g (or --tol, in N)\n"
            "      --load FX,FY,FZ   equilibrium: constant force on every free particle [N]; default 0\n"
            "      --preconditioner NAME  equilibrium: auto, block-jacobi, jacobi, sgs, multigrid or cyclic\n"
            "      --solver NAME     euler, symplectic, rk4, adaptive or implicit (kept in OUT)\n"
            "                        (default: the integrator named in FILE)\n"
            "      --dt S            time step [s], in [1e-9, 1]; default %g\n"
            "      --tol N           residual force threshold [N], in [0, 1e6]; default %g\n"
            "      --max-time S      give up after this much simulated time [s], in [1e-9, 1e7]; default %g\n"
            "      --max-kinetic J   kinetic energy threshold [J], in [0, 1e6]; default %g\n"
            "      --drag D          air drag [1/s] at least this while settling, in [0, 1e6]\n"
            "                        (the path to rest, not the rest state); default: FILE's\n"
            "      --energy-limit L  implicit: always (default: no step may create energy; its move\n"
            "                        is halved until it does not), unfinished (only a step whose CG\n"
            "                        solve stopped at its cap), or off (steps taken whole)\n"
            "  -h, --help            this text\n",
            e.tolerance, d.dt, d.max_residual, d.max_time, d.max_kinetic);
}

typedef struct settle_options {
    const char *input, *output, *solver;
    spn_settle_def def;
    bool equilibrium, tol_given;
    spn_equilibrium_def eq;
    spn_energy_limit limit;
} settle_options;

enum {
    OPT_SOLVER = 256,
    OPT_DT,
    OPT_TOL,
    OPT_MAX_TIME,
    OPT_MAX_KINETIC,
    OPT_METHOD,
    OPT_REL_TOL,
    OPT_LOAD,
    OPT_PRECOND,
    OPT_ENERGY_LIMIT,
    OPT_DRAG
};

/* --energy-limit names, in spn_energy_limit order. */
static const char *const LIMITS[] = {"off", "unfinished", "always"};

/* One option (cli_option_fn). */
static int parse_one(int c, const char *arg, void *ctx)
{
    settle_options *o = ctx;
    bool ok = true;
    switch (c) {
    case 'o': o->output = arg; break;
    case OPT_SOLVER: o->solver = arg; break;
    case OPT_DT: ok = cli_double(CMD, "--dt", arg, 1e-9, 1, &o->def.dt); break;
    case OPT_TOL:
        ok = cli_double(CMD, "--tol", arg, 0, 1e6, &o->def.max_residual);
        o->tol_given = true;
        break;
    case OPT_MAX_TIME: ok = cli_double(CMD, "--max-time", arg, 1e-9, 1e7, &o->def.max_time); break;
    case OPT_MAX_KINETIC: ok = cli_double(CMD, "--max-kinetic", arg, 0, 1e6, &o->def.max_kinetic); break;
    case OPT_DRAG: ok = cli_double(CMD, "--drag", arg, 0, 1e6, &o->def.drag); break;
    case OPT_METHOD:
        if (strcmp(arg, "equilibrium") == 0 || strcmp(arg, "static") == 0) o->equilibrium = true;
        else if (strcmp(arg, "dynamic") == 0) o->equilibrium = false;
        else return cli_usage(CMD, "--method: '%s' is not dynamic or equilibrium", arg), -1;
        break;
    case OPT_REL_TOL: ok = cli_double(CMD, "--rel-tol", arg, 0, 1, &o->eq.tolerance); break;
    case OPT_LOAD: ok = cli_vec3_bounded(CMD, "--load", arg, CLI_MAX_FORCE, &o->eq.load); break;
    case OPT_PRECOND:
        if (spn_precond_parse(arg, &o->eq.preconditioner) != SPN_OK)
            return cli_usage(CMD, "--preconditioner: %s", spn_last_error()), -1;
        break;
    case OPT_ENERGY_LIMIT: {
        const int i = cli_choice(arg, LIMITS, 3);
        if (i < 0) return cli_usage(CMD, "--energy-limit: '%s' is not off, unfinished or always", arg), -1;
        o->limit = (spn_energy_limit)i;
        return 1;
    }
    default: return 0;
    }
    return ok ? 1 : -1;
}

/* Fills `o` from argv; returns -1 to go on, else the exit code. */
static int parse_options(int argc, char **argv, settle_options *o)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"solver", required_argument, NULL, OPT_SOLVER},
                                            {"dt", required_argument, NULL, OPT_DT},
                                            {"tol", required_argument, NULL, OPT_TOL},
                                            {"max-time", required_argument, NULL, OPT_MAX_TIME},
                                            {"max-kinetic", required_argument, NULL, OPT_MAX_KINETIC},
                                            {"method", required_argument, NULL, OPT_METHOD},
                                            {"rel-tol", required_argument, NULL, OPT_REL_TOL},
                                            {"load", required_argument, NULL, OPT_LOAD},
                                            {"preconditioner", required_argument, NULL, OPT_PRECOND},
                                            {"energy-limit", required_argument, NULL, OPT_ENERGY_LIMIT},
                                            {"drag", required_argument, NULL, OPT_DRAG},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    int r = cli_parse_options(CMD, argc, argv, ":o:h", options, usage, parse_one, o);
    if (r >= 0) return r;
    if (optind >= argc) return cli_usage(CMD, "missing FILE");
    if (optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    o->input = argv[optind];
    if (!o->output || !*o->output) return cli_usage(CMD, "-o/--output: the output file is required");
    spn_integrator integ;
    if (o->solver && spn_integrator_parse(o->solver, &integ) != SPN_OK)
        return cli_usage(CMD, "--solver: %s", spn_last_error());
    return -1;
}

static void print_report(const spn_settle_report *r, const spn_settle_def *d, const char *solver)
{
    if (r->reason == SPN_SETTLE_CONVERGED)
        fprintf(stderr, "settle: converged after %g s simulated (%llu steps, %s)\n", r->time,
                (unsigned long long)r->steps, solver);
    else
        fprintf(stderr, "settle: timed out after %g s simulated (%llu steps, %s): not at rest\n", r->time,
                (unsigned long long)r->steps, solver);
    fprintf(stderr, "  kinetic energy %.6g J (threshold %g)\n", r->kinetic, d->max_kinetic);
    fprintf(stderr, "  largest residual force %.6g N (threshold %g)\n", r->residual, d->max_residual);
    fprintf(stderr, "  final energy (kinetic + elastic + gravitational) %.9g J\n", r->total_energy);
}

static void print_equilibrium(const spn_equilibrium_report *r, const spn_equilibrium_def *d)
{
    if (r->reason == SPN_EQUILIBRIUM_CONVERGED)
        fprintf(stderr, "settle: static equilibrium after %d Newton steps (%d CG iterations, %s)\n", r->iterations,
                r->cg_iterations, spn_precond_name(r->preconditioner));
    else
        fprintf(stderr, "settle: no static equilibrium (%s) after %d Newton steps: not at rest\n",
                spn_equilibrium_reason_name(r->reason), r->iterations);
    double target = fmax(d->abs_tolerance, d->tolerance * r->force_scale);
    fprintf(stderr, "  largest residual force %.6g N at particle %u (threshold %g; started at %.6g)\n", r->residual,
            r->worst, target, r->residual_start);
    fprintf(stderr, "  force scale %.6g N, energy change %.9g J, largest move %.6g m\n", r->force_scale,
            r->energy_change, r->max_displacement);
}

/* --method equilibrium: solve, report; returns 0 or the exit code of a failure. */
static int settle_static(spn_world *w, settle_options *o)
{
    if (o->tol_given) {
        o->eq.abs_tolerance = o->def.max_residual;
        o->eq.tolerance = 0;
    }
    spn_equilibrium_report report;
    spn_status st = spn_world_equilibrium(w, &o->eq, &report);
    if (st != SPN_OK) return cli_fail(CMD, "%s: %s; nothing written", o->input, spn_last_error());
    print_equilibrium(&report, &o->eq);
    return 0;
}

int cmd_settle(int argc, char **argv)
{
    settle_options o = {NULL,  NULL,  NULL, spn_settle_def_default(), false, false, spn_equilibrium_def_default(),
                        SPN_ENERGY_LIMIT_ALWAYS};
    int code = parse_options(argc, argv, &o);
    if (code >= 0) return code;

    spn_world *w = NULL;
    if (spn_web_load(o.input, &w) != SPN_OK) return cli_fail(CMD, "%s", spn_last_error());
    if (!cli_output_writable(CMD, o.output)) { /* before the work, not after it */
        spn_world_destroy(w);
        return CLI_EXIT_FAIL;
    }
    if (o.solver) {
        spn_integrator integ = SPN_INTEGRATOR_SYMPLECTIC;
        spn_integrator_parse(o.solver, &integ);
        spn_world_set_integrator(w, integ);
    }
    spn_status st = SPN_OK;
    if (o.equilibrium) {
        code = settle_static(w, &o);
        if (code) {
            spn_world_destroy(w);
            return code;
        }
    } else {
        spn_settle_report report;
        /* Settling wants rest, not a faithful path. Implicit 5 ms steps of
         * species webs as built (Zen 4, CPU s): Zilla seed 6 ran away without
         * the limit (7e-4 J to 3,750 J and 1,348 N in 3 s), came to rest in
         * 5.2 s with it (either mode); a 5 cm Zygiella timed out at 3e-4 N
         * with `unfinished` as with `off` and came to rest in 0.08 s with
         * `always`; Argiope timed out (`off`, 39 s), came to rest in 9.0 s
         * (`unfinished`) and 14.8 s (`always`). So `always`. */
        st = spn_world_set_energy_limit(w, o.limit);
        if (st == SPN_OK) st = spn_world_settle(w, &o.def, &report);
        if (st != SPN_OK) {
            spn_world_destroy(w);
            return cli_fail(CMD, "%s: %s; nothing written", o.input, spn_last_error());
        }
        print_report(&report, &o.def, spn_integrator_name(spn_world_get_def(w)->integrator));
    }
    st = spn_web_save(w, o.output);
    spn_world_destroy(w);
    if (st != SPN_OK) return cli_fail(CMD, "%s", spn_last_error());
    fprintf(stderr, "  wrote %s\n", o.output);
    return 0;
}

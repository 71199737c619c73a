#!/usr/bin/env python3
"""Make the README's speed tables from a `make bench` results file.

    scripts/bench-table.py bench/results/<machine>.json            # print Markdown
    scripts/bench-table.py bench/results/<machine>.json --readme README.md

The results file holds one JSON object per line: first the machine (name,
CPU, its family and model, the vector extension the kernels pick, cores,
date), then one line per figure, each with a "bench" key. Known
benches get a table with chosen columns; any other bench gets a table of all
its keys, so a new benchmark shows up without editing this script. With
--readme, the text between the markers <!-- bench-table:begin --> and
<!-- bench-table:end --> is replaced (written atomically). When the
results folder holds other machines' files, issue 10's targets are also
set side by side for each of them."""
import glob
import json
import os
import sys
import tempfile

BEGIN, END = "<!-- bench-table:begin -->", "<!-- bench-table:end -->"

# bench -> (title, [(key, heading)]); keys missing from a line print as "".
KNOWN = {
    "equilibrium": ("Static equilibrium (`spn_world_equilibrium`, bench/bench_equilibrium.c)", [
        ("scene", "scene"), ("precond", "preconditioner"), ("threads", "threads"),
        ("tolerance", "tol / T0"), ("cold", "cold"), ("seconds", "wall s"), ("cpu_seconds", "CPU s"),
        ("newton", "Newton"), ("cg", "CG"), ("residual_over_t0", "checked residual / T0"),
        ("sag_rel_error", "sag vs direct")]),
    "equilibrium_reference": ("Reference: Newton with a direct banded Cholesky solve", [
        ("scene", "scene"), ("method", "method"), ("newton", "Newton"), ("seconds", "wall s"),
        ("cpu_seconds", "CPU s"), ("residual_over_t0", "residual / T0")]),
    "peer_bullet_softbody": ("Explicit step against Bullet btSoftBody (bench/peers/bullet_orb.cpp)", [
        ("particles", "particles"), ("springs", "springs"), ("steps", "steps"),
        ("bullet_ns_per_spring_step", "Bullet ns/spring/step"),
        ("spinneret_ns_per_spring_step", "Spinneret ns/spring/step"), ("ratio", "ratio"),
        ("bullet_strain_error", "Bullet strain error"), ("spinneret_strain_error", "Spinneret strain error"),
        ("spinneret_path", "Spinneret path"), ("equal_accuracy_reached", "Bullet reaches our error"),
        ("equal_accuracy_bullet_refine", "Bullet step divisor tried"),
        ("equal_accuracy_bullet_strain_error", "its strain error"),
        ("equal_accuracy_cpu_ratio", "CPU ratio at that divisor"),
        ("spinneret_float32_ns_per_spring_step", "Spinneret float32 ns/spring/step"),
        ("float32_cpu_ratio", "CPU ratio in float32 (Bullet's precision)"),
        ("spinneret_float32_strain_error", "Spinneret float32 strain error")]),
    "mg_rates": ("Equilibrium preconditioners as stationary iterations: energy-norm contraction per cycle, "
                 "the rate of cycles 25-32 (bench/bench_mg_rates.c; the same on any machine)", [
        ("scene", "scene"), ("system", "Newton system"), ("precond", "preconditioner"),
        ("component", "error"), ("contraction", "contraction"), ("worst_cycle", "largest factor"),
        ("setup_seconds", "setup wall s")]),
    "floor": ("What this machine's floating-point units do at most, one thread, L1-resident loops "
              "(bench/bench_floor.c; ns per operation, and the least a float64 spring-step could take)", [
        ("kernel", "kernel"), ("integrator", "step"), ("ns_per_op", "ns per op"),
        ("ghz_if_3_cycles", "GHz if an add takes 3 cycles"), ("gflops", "Gflop/s"),
        ("flops_per_spring", "flops per spring counted"), ("divider_ns", "sqrt + div ns"),
        ("arithmetic_ns", "arithmetic ns"), ("ns_per_spring_step", "floor ns per spring-step")]),
    "bandwidth": ("Memory bandwidth (bench/bench_bandwidth.c, STREAM-style)", [
        ("kernel", "kernel"), ("threads", "threads"), ("gb_per_s", "GB/s")]),
    "web_settle": ("A built species or geometric web brought to rest (`spn_web_settle`, as `build --settle`; "
                   "bench/bench_web_settle.c, 1 thread)", [
        ("species", "species"), ("seed", "seed"), ("build", "web"), ("particles", "particles"),
        ("build_cpu_ms", "build CPU ms"), ("how", "how"), ("converged", "at rest"), ("newton_steps", "Newton steps"),
        ("steps", "implicit steps"), ("simulated_s", "simulated s"), ("residual_n", "residual N"), ("ms", "wall ms"),
        ("cpu_ms", "CPU ms")]),
    "inscribe": ("\"PIG\" written into README's physical web (`spinneret inscribe --solver implicit`: the rest "
                 "state solved for after editing, stepped where that falls short; bench/bench_inscribe.c, 1 thread, "
                 "the settle after editing)", [
        ("emphasis", "emphasis"), ("settle", "settle"), ("particles", "particles"), ("how", "how"),
        ("converged", "at rest"), ("newton_steps", "Newton steps"), ("steps", "implicit steps"),
        ("simulated_s", "simulated s"), ("residual_n", "residual N"), ("ms", "wall ms"), ("cpu_ms", "CPU ms")]),
    "air": ("Turbulent air (`--wind air`; bench/bench_air.c, 1 thread): a time slice of the cached field, a sample "
            "of it, and the Araneus web (1,924 particles) animated in still air and in wind", [
        ("case", "case"), ("nodes", "grid nodes"), ("ms_per_slice", "ms a slice"), ("ns_per_sample", "ns a sample"),
        ("solver", "solver"), ("wind", "wind"), ("dt", "dt s"), ("cpu_s_per_sim_s", "CPU s per simulated s"),
        ("cg_per_step", "CG a step"), ("ms_per_step", "ms a step"), ("ns_per_spring_step", "ns a spring-step")]),
    "frames": ("A frame of `spinneret animate` besides the physics: the Araneus web drawn at 1,200 x 1,200 and written "
               "as a PNG (bench/bench_frames.c, 1 thread, CPU)", [
        ("case", "look"), ("draw_ms", "draw ms"), ("write_ms", "write ms"), ("bytes", "bytes a frame")]),
}


# Issue 10's targets: (the figure, its limit, the rule that picks its line,
# the key of its value, and (label, rule, key) of the values shown beside
# it). Each is read off the run's own lines, never typed in.
def _step(integ, particles, threads, precision="float64"):
    return lambda r: (r.get("bench") == "step" and r.get("integrator") == integ and r.get("particles") == particles
                      and r.get("threads") == threads and r.get("path") == "lattice"
                      and r.get("precision") == precision)


def _equilibrium(scene, threads, cold=None, precond="cyclic"):
    return lambda r: (r.get("bench") == "equilibrium" and r.get("scene") == scene and r.get("precond") == precond
                      and r.get("threads") == threads and r.get("tolerance") == 1e-6
                      and (cold is None or r.get("cold") == cold))


FLOOR = "this machine's float64 floor"


def _floor(integ):
    return lambda r: r.get("bench") == "floor" and r.get("kernel") == "spring_step" and r.get("integrator") == integ


# (figure, target, rule, key, beside, floor): floor the rule of bench_floor's
# line for the figure, or None.
TARGETS = [
    ("explicit (symplectic) step, 5k web, float64, ns per spring-step", 1.2, _step("symplectic", 5001, 1),
     "ns_per_spring_step", [("float32", _step("symplectic", 5001, 1, "float32"), "ns_per_spring_step"),
                            ("two threads (wall)", _step("symplectic", 5001, 2), "ns_per_spring_step"),
                            ("float32 on two threads (wall)", _step("symplectic", 5001, 2, "float32"),
                             "ns_per_spring_step")],
     _floor("symplectic")),
    ("explicit step, 1M web, float64, 2 threads, ns per spring-step (wall)", 3.5, _step("symplectic", 1000001, 2),
     "ns_per_spring_step", [("one thread", _step("symplectic", 1000001, 1), "ns_per_spring_step"),
                            ("float32", _step("symplectic", 1000001, 2, "float32"), "ns_per_spring_step"),
                            ("float32, a world's first call (it allocates the float32 state)",
                             _step("symplectic", 1000001, 2, "float32"), "first_call_ns_per_spring_step")], None),
    ("RK4 step, 5k web, ns per spring-step", 5, _step("rk4", 5001, 1), "ns_per_spring_step",
     [("float32", _step("rk4", 5001, 1, "float32"), "ns_per_spring_step"),
      ("two threads (wall)", _step("rk4", 5001, 2), "ns_per_spring_step"),
      ("float32 on two threads (wall)", _step("rk4", 5001, 2, "float32"), "ns_per_spring_step")], _floor("rk4")),
    ("RK4 step, 1M web, 2 threads, ns per spring-step (wall)", 12, _step("rk4", 1000001, 2), "ns_per_spring_step",
     [("one thread", _step("rk4", 1000001, 1), "ns_per_spring_step"),
      ("float32", _step("rk4", 1000001, 2, "float32"), "ns_per_spring_step"),
      ("float32, a world's first call", _step("rk4", 1000001, 2, "float32"), "first_call_ns_per_spring_step")], None),
    ("static equilibrium, 5k web, 1e-6 T0, s (fastest of ten solves; cyclic, what auto takes)", 0.020,
     _equilibrium("orb-5k", 1), "seconds",
     [("first solve in the process, CPU", _equilibrium("orb-5k", 1), "cpu_first_seconds"),
      ("multigrid", _equilibrium("orb-5k", 1, precond="multigrid"), "seconds")], None),
    ("static equilibrium, 1M web, 1e-6 T0, 2 threads, s (wall; the process's first solve; cyclic)", 5,
     _equilibrium("orb-1M", 2, cold=True), "seconds",
     [("the same after another 1M solve", _equilibrium("orb-1M", 2, cold=False), "seconds"),
      ("one thread", _equilibrium("orb-1M", 1), "seconds"),
      ("multigrid, after the cyclic solves", _equilibrium("orb-1M", 2, precond="multigrid"), "seconds")], None),
]


def value(lines, rule, key):
    """The first of a run's lines that the rule takes, its key; None if none."""
    return next((l[key] for l in lines if rule(l) and key in l), None)


def targets(lines):
    """Issue 10's table against this run: each figure, its target and
    whether this run met it, with the figures beside it (other precisions,
    thread counts, a cold or warm process, the machine's floor)."""
    out = ["**Issue 10's targets against this run**", "",
           "| figure | target | this run | beside it | met |", "|---|---:|---:|---|---|"]
    for name, limit, rule, key, beside, floor_rule in TARGETS:
        v = value(lines, rule, key)
        if v is None:
            continue
        floor = value(lines, floor_rule, "ns_per_spring_step") if floor_rule else None
        side = [(label, value(lines, r2, k2)) for label, r2, k2 in beside] + [(FLOOR + " (bench_floor)", floor)]
        side = "; ".join(f"{label} {cell(b)}" for label, b in side if b is not None)
        met = "yes" if v <= limit else "no, and the target is under this machine's floor" \
            if floor is not None and floor > limit else "no"
        out.append(f"| {name} | ≤ {cell(limit)} | {cell(v)} | {side} | {met} |")
    return "\n".join(out) + "\n" if len(out) > 4 else ""


def machines_table(runs):
    """Issue 10's targets on every machine with a results file beside this
    one (bench/results/*.json, read as (path, lines) in runs): the same
    guest has run on more than one processor, and a figure from one must
    not be read against another."""
    named = []
    for path, lines in sorted(runs, key=lambda run: run[0]):
        machine = next((l for l in lines if "bench" not in l), {})
        isa = {"avx512": "AVX-512", "avx2": "AVX2", "baseline": "no AVX2"}.get(machine.get("isa"), "")
        named.append((f"`{machine.get('machine', os.path.basename(path))}` "
                      f"({', '.join(x for x in (isa, machine.get('date', '')) if x)})", lines))
    if len(named) < 2:
        return ""
    out = ["**Issue 10's targets on each machine measured (each a whole `make bench` run)**", "",
           "| figure | target | " + " | ".join(name for name, _ in named) + " |",
           "|---|---:|" + "---:|" * len(named)]
    for name, limit, rule, key, _, _ in TARGETS:
        vals = [value(lines, rule, key) for _, lines in named]
        if all(v is None for v in vals):
            continue
        out.append(f"| {name} | ≤ {cell(limit)} | " + " | ".join(
            "" if v is None else f"{cell(v)} ({'met' if v <= limit else 'not met'})" for v in vals) + " |")
    return "\n".join(out) + "\n"


def bandwidth_table(rows):
    """Each lattice step's unavoidable traffic (bench_step's model: a pass
    reads the state, masses and spring slots once and writes the state once)
    per second of wall time, against bench_bandwidth's triad on as many
    threads in the same run, and where one pass fits (bench_bandwidth's
    cache sizes: a thread's share of the pass in its core's L2, the pass in
    the L3, or neither; a size the machine did not give, 0, decides
    nothing): a pass that fits in a cache streams from it, and its
    share of the memory's triad only says how little memory it needs."""
    triad = {r["threads"]: r["gb_per_s"] for r in rows
             if r.get("bench") == "bandwidth" and r.get("kernel") == "triad"}
    caches = next((r for r in rows if r.get("bench") == "caches"), {})
    steps = [r for r in rows if r.get("bench") == "step" and "model_gb_per_s" in r]
    if not steps or not triad:
        return ""

    def fits(r):
        kib = r["pass_mib"] * 1024
        if caches.get("l2_kib_per_core") and kib / r["threads"] <= caches["l2_kib_per_core"]:
            return "L2"
        if caches.get("l3_kib") and kib <= caches["l3_kib"]:
            return "L3"
        if not caches.get("l2_kib_per_core"):
            return "?"
        return "memory" if caches.get("l3_kib") else "beyond L2"
    out = ["**The share of the machine's memory bandwidth the lattice steps reach (bench/bench_step.c; "
           "the traffic a model, docs/physics-lattice.md)**", "",
           "| integrator | particles | threads | bytes per spring-step | one pass, MiB | pass fits in | GB/s "
           "| triad GB/s | share of the triad |",
           "|---|---:|---:|---:|---:|---|---:|---:|---:|"]
    for r in steps:
        t = triad.get(r["threads"])
        name = r["integrator"] + (" float32" if r.get("precision") == "float32" else "")
        share = f"{r['model_gb_per_s'] / t:.0%}" if t else "–"
        out.append(f"| {name} | {r['particles']:,} | {r['threads']} | {r['model_bytes_per_spring_step']:.1f} | "
                   f"{r['pass_mib']:.1f} | {fits(r)} | {r['model_gb_per_s']:.1f} | {t if t else '–'} | {share} |")
    return "\n".join(out) + "\n"


def cell(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.3g}" if (abs(v) < 1e-3 or abs(v) >= 1e5) and v != 0 else f"{v:.4g}"
    return str(v)


def table(title, columns, rows):
    out = [f"**{title}**", "", "| " + " | ".join(h for _, h in columns) + " |",
           "|" + "---|" * len(columns)]
    for r in rows:
        out.append("| " + " | ".join(cell(r.get(k)) for k, _ in columns) + " |")
    return "\n".join(out) + "\n"


def read_run(path):
    with open(path) as f:
        return [json.loads(s) for s in f if s.strip()]


def render(path):
    lines = read_run(path)
    machine = next((l for l in lines if "bench" not in l), {})
    groups = {}
    for l in lines:
        if "bench" in l:
            groups.setdefault(l["bench"], []).append(l)
    hardware = ", ".join(x for x in (
        f"family {machine['cpu_family']}" if machine.get("cpu_family") else "",
        f"model {machine['cpu_model']}" if machine.get("cpu_model") else "",
        {"avx512": "AVX-512", "avx2": "AVX2, no AVX-512", "baseline": "no AVX2"}.get(machine.get("isa"), "")) if x)
    out = [f"Measured by `make bench` on `{machine.get('machine', '?')}`: {machine.get('cpu', '?')}"
           f"{f' ({hardware})' if hardware else ''}, "
           f"{machine.get('cores', '?')} cores, {machine.get('date', '?')} "
           f"(results: `{os.path.relpath(path)}`; tables made by `scripts/bench-table.py`).", ""]
    here = os.path.abspath(path)
    runs = [(here, lines)] + [(p, read_run(p)) for p in glob.glob(os.path.join(os.path.dirname(here), "*.json"))
                              if os.path.abspath(p) != here]
    for extra in (targets(lines), machines_table(runs), bandwidth_table(lines)):
        if extra:
            out.append(extra)
    for name in list(KNOWN) + sorted(set(groups) - set(KNOWN)):
        if name not in groups:
            continue
        if name in KNOWN:
            title, cols = KNOWN[name]
        else:
            keys = []
            for r in groups[name]:
                keys += [k for k in r if k != "bench" and k not in keys]
            title, cols = f"`{name}`", [(k, k) for k in keys]
        out.append(table(title, cols, groups[name]))
    return "\n".join(out)


def write_readme(readme, text):
    with open(readme) as f:
        doc = f.read()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"bench-table: {readme}: markers {BEGIN} / {END} not found")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = head + BEGIN + "\n" + text + END + tail
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(readme)), prefix=".readme.")
    with os.fdopen(fd, "w") as f:
        f.write(new)
    os.replace(tmp, readme)


def main(argv):
    if len(argv) not in (2, 4) or (len(argv) == 4 and argv[2] != "--readme"):
        sys.exit("usage: bench-table.py RESULTS.json [--readme README.md]")
    text = render(argv[1])
    if len(argv) == 4:
        write_readme(argv[3], text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main(sys.argv)

#!/usr/bin/env python3
"""Make the README's speed tables from a `make bench` results file.

    scripts/bench-table.py bench/results/<machine>.json            # print Markdown
    scripts/bench-table.py bench/results/<machine>.json --readme README.md

The results file holds one JSON object per line: first the machine (name,
CPU, cores, date), then one line per figure, each with a "bench" key. Known
benches get a table with chosen columns; any other bench gets a table of all
its keys, so a new benchmark shows up without editing this script. With
--readme, the text between the markers <!-- bench-table:begin --> and
<!-- bench-table:end --> is replaced (written atomically)."""
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
        ("equal_accuracy_cpu_ratio", "CPU ratio at that divisor")]),
    "mg_rates": ("Equilibrium preconditioners as stationary iterations: energy-norm contraction per cycle, "
                 "the rate of cycles 25-32 (bench/bench_mg_rates.c; the same on any machine)", [
        ("scene", "scene"), ("system", "Newton system"), ("precond", "preconditioner"),
        ("component", "error"), ("contraction", "contraction"), ("worst_cycle", "largest factor"),
        ("setup_seconds", "setup wall s")]),
    "bandwidth": ("Memory bandwidth (bench/bench_bandwidth.c, STREAM-style)", [
        ("kernel", "kernel"), ("threads", "threads"), ("gb_per_s", "GB/s")]),
}


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


def render(path):
    with open(path) as f:
        lines = [json.loads(s) for s in f if s.strip()]
    machine = next((l for l in lines if "bench" not in l), {})
    groups = {}
    for l in lines:
        if "bench" in l:
            groups.setdefault(l["bench"], []).append(l)
    out = [f"Measured by `make bench` on `{machine.get('machine', '?')}`: {machine.get('cpu', '?')}, "
           f"{machine.get('cores', '?')} cores, {machine.get('date', '?')} "
           f"(results: `{os.path.relpath(path)}`; tables made by `scripts/bench-table.py`).", ""]
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

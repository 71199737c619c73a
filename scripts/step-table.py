#!/usr/bin/env python3
"""Compact tables for README's Speed section from a bench results file
(JSON lines, as written by scripts/bench.sh): bench_step per integrator and
size, and the Bullet peer.

    scripts/step-table.py bench/results/<machine>.json
"""
import json
import sys


def load(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip().startswith("{")]


def step_table(rows):
    steps = [r for r in rows if r.get("bench") == "step"]
    sizes = sorted({r["particles"] for r in steps})
    stencil = {r["integrator"] for r in steps if r.get("path") == "lattice"}

    def label(r):
        # the general path of an integrator that also has the lattice (stencil) one
        general = r.get("path") == "general" and r["integrator"] in stencil
        f32 = r.get("precision") == "float32"  # the opt-in float32 lattice step
        return r["integrator"] + (" float32" if f32 else "") + (" (general path)" if general else "")
    integrators = []
    for r in steps:
        if label(r) not in integrators:
            integrators.append(label(r))
    get = {(label(r), r["particles"], r["threads"]): r for r in steps}
    head = " | ".join(f"{n:,}" for n in sizes)
    out = [f"| integrator | {head} | 2 threads, CPU (wall) |",
           "|---|" + "---:|" * len(sizes) + "---:|"]
    for integ in integrators:
        one, two = [], []
        for n in sizes:
            r1, r2 = get.get((integ, n, 1)), get.get((integ, n, 2))
            one.append(f"{r1['cpu_ns_per_spring_step']:.1f} ({r1['ns_per_spring_step']:.0f})" if r1 else "–")
            two.append(f"{r2['cpu_ns_per_spring_step']:.1f} ({r2['ns_per_spring_step']:.0f})" if r2 else "–")
        out.append(f"| {integ} | " + " | ".join(one) + " | " + " / ".join(two) + " |")
    imp = [r for r in steps if r["integrator"] == "implicit" and r["threads"] == 1]
    if imp:
        out.append("")
        out.append("Implicit: CG iterations per step " +
                   ", ".join(f"{r['cg_iterations_per_step']:.0f}" for r in imp) +
                   "; CPU ns per spring per CG iteration " +
                   ", ".join(f"{r.get('cpu_ns_per_spring_cg_iteration', float('nan')):.1f}" for r in imp) + ".")
    loads = [r["load"] for r in steps if "load" in r]
    if loads:
        out.append(f"Load average during the run: {min(loads):.1f}–{max(loads):.1f}.")
    return "\n".join(out)


def equal_accuracy(r):
    """Bullet's cost over ours once its strain error matches ours (the peer
    shrinks Bullet's step until it does, or gives up)."""
    if "equal_accuracy_reached" not in r:
        return "–"
    if r["equal_accuracy_reached"]:
        return f"{r['equal_accuracy_cpu_ratio']:.1f} (Bullet at dt/{r['equal_accuracy_bullet_refine']})"
    return (f"never: Bullet's best {r['bullet_best_strain_error']:.2g} at dt/{r['bullet_best_refine']}, "
            f"{r['equal_accuracy_bullet_strain_error']:.2g} at dt/{r['equal_accuracy_bullet_refine']}")


def float32_cells(r):
    """Our float32 run beside Bullet (float32 as Debian builds it); runs
    before the twenty-eighth session have none."""
    if "float32_cpu_ratio" not in r:
        return "–"
    return (f"{r['spinneret_float32_cpu_ns_per_spring_step']:.2f}, {r['float32_cpu_ratio']:.1f}×, "
            f"{r['spinneret_float32_strain_error']:.2g}")


def peer_table(rows):
    peer = [r for r in rows if r.get("bench") == "peer_bullet_softbody"]
    if not peer:
        return ""
    out = ["| particles | Bullet CPU (wall) | Spinneret CPU (wall) | ratio CPU (wall) | strain error Bullet / ours "
           "| CPU ratio at equal accuracy | in float32, Bullet's precision: CPU, ratio, strain error |",
           "|---:|---:|---:|---:|---:|---:|---:|"]
    for r in peer:
        out.append(f"| {r['particles']:,} | {r.get('bullet_cpu_ns_per_spring_step', float('nan')):.1f} "
                   f"({r['bullet_ns_per_spring_step']:.0f}) | "
                   f"{r.get('spinneret_cpu_ns_per_spring_step', float('nan')):.1f} "
                   f"({r['spinneret_ns_per_spring_step']:.0f}) | {r.get('cpu_ratio', float('nan')):.1f} "
                   f"({r['ratio']:.1f}) | {r['bullet_strain_error']:.2g} / {r['spinneret_strain_error']:.2g} | "
                   f"{equal_accuracy(r)} | {float32_cells(r)} |")
    return "\n".join(out)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: step-table.py RESULTS.json")
    rows = load(sys.argv[1])
    print(step_table(rows))
    print()
    print(peer_table(rows))


if __name__ == "__main__":
    main()

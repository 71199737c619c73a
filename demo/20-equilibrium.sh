#!/usr/bin/env bash
# Static equilibrium: a taut silk orb web (EA 0.07 N, 2% pre-strain, written
# by a few lines of Python) pushed out of its plane by a steady breeze, brought
# to rest directly with `settle --method equilibrium` (Newton). Prints the
# report, the time and the hub's deflection.
set -eu
: "${SPN:?}" "${OUT:?}"
python3 - "$OUT/equil-web.json" <<'PY'
import json, math, sys
radials, rings, R, ea, strain, rho = 24, 20, 0.15, 0.07, 0.02, 1e-6
pos, fixed = [0.0, 0.0, 0.0], [0]
for i in range(rings):
    for j in range(radials):
        r, a = R * (i + 1) / rings, 2 * math.pi * j / radials
        pos += [r * math.cos(a), r * math.sin(a), 0.0]
        fixed.append(1 if i == rings - 1 else 0)
pid = lambda i, j: 1 + i * radials + j % radials
a, b = [], []
for j in range(radials):
    a.append(0); b.append(pid(0, j))
    for i in range(rings - 1): a.append(pid(i, j)); b.append(pid(i + 1, j))
for i in range(rings):
    for j in range(radials): a.append(pid(i, j)); b.append(pid(i, j + 1))
rest = [math.dist(pos[3 * p:3 * p + 3], pos[3 * q:3 * q + 3]) / (1 + strain) for p, q in zip(a, b)]
mass = [0.0] * len(fixed)
for p, q, r in zip(a, b, rest): mass[p] += rho * r / 2; mass[q] += rho * r / 2
n = len(a)
json.dump({"format": "spinneret-web", "version": 1, "units": "SI",
           "metadata": {"builder": "demo/20-equilibrium.sh"},
           "world": {"gravity": [0, -9.81, 0], "drag": 20, "integrator": "implicit"},
           "particles": {"count": len(fixed), "position": pos, "mass": mass, "fixed": fixed},
           "springs": {"count": n, "a": a, "b": b, "k": [ea / r for r in rest], "kd": [0] * n, "rest": rest,
                       "tension_only": [1] * n}}, open(sys.argv[1], "w"))
PY
# a breeze: 1.4 mN in all (one pretension), spread over the 457 free particles
load=0,0,3.06e-6
t0=$(date +%s%N)
"$SPN" settle "$OUT/equil-web.json" -o "$OUT/equil-static.json" --method equilibrium --load $load --rel-tol 1e-9
t1=$(date +%s%N)
echo "equilibrium demo: $(( (t1 - t0) / 1000000 )) ms, program start and file IO included" >&2
# the same with the multigrid (smoothed aggregation, thread-line smoothing): the same rest state
"$SPN" settle "$OUT/equil-web.json" -o "$OUT/equil-static-mg.json" --method equilibrium --load $load --rel-tol 1e-9 \
    --preconditioner multigrid
python3 - "$OUT/equil-static.json" "$OUT/equil-static-mg.json" <<'PY'
import json, sys
z = [json.load(open(f))["particles"]["position"][2] for f in sys.argv[1:]]
print(f"equilibrium demo: the hub moved {z[0] * 1000:.3f} mm out of the plane "
      f"(multigrid: {z[1] * 1000:.3f} mm, difference {abs(z[0] - z[1]):.1e} m)", file=sys.stderr)
PY
if "$SPN" render --help >/dev/null 2>&1; then
    "$SPN" render "$OUT/equil-static.json" -o "$OUT/equil-static.png" || echo "equilibrium demo: render failed"
fi

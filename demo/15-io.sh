#!/usr/bin/env bash
# Web files, info and settle: a small dew-laden orb web written as a web file
# by a few lines of Python (any tool can make one; docs/web-format.md), settled
# under gravity by `spinneret settle`, described by `spinneret info`, and drawn
# before and after when the program has `render`.
set -eu
: "${SPN:?}" "${OUT:?}"
python3 - "$OUT/io-web.json" <<'PY'
import json, math, sys
radials, rings, R = 12, 8, 0.15
ea, mass = 0.05, 2e-5          # soft threads, heavy with dew: the web sags visibly
pos, mass_of, fixed, ptag = [], [], [], []
def add(x, y, m, fix, tag):
    pos.extend([x, y, 0.0]); mass_of.append(m); fixed.append(fix); ptag.append(tag)
    return len(mass_of) - 1
hub = add(0, 0, mass, 0, 3)
ids = [[add(R * (i + 1) / rings * math.cos(2 * math.pi * j / radials),
            R * (i + 1) / rings * math.sin(2 * math.pi * j / radials),
            mass, 1 if i == rings - 1 else 0, 1 if i == rings - 1 else 5)
        for j in range(radials)] for i in range(rings)]
a, b, tag = [], [], []
def spring(p, q, t): a.append(p); b.append(q); tag.append(t)
for j in range(radials):
    spring(hub, ids[0][j], 3)
    for i in range(rings - 1):
        spring(ids[i][j], ids[i + 1][j], 3)
for i in range(rings):
    for j in range(radials):
        spring(ids[i][j], ids[i][(j + 1) % radials], 2 if i == rings - 1 else 6)
def dist(p, q): return math.dist(pos[3 * p:3 * p + 3], pos[3 * q:3 * q + 3])
rest = [dist(p, q) for p, q in zip(a, b)]
n = len(a)
web = {"format": "spinneret-web", "version": 1, "units": "SI",
       "metadata": {"builder": "demo/15-io.sh", "parameters": {"radials": radials, "rings": rings}},
       "world": {"gravity": [0, -9.81, 0], "drag": 4, "integrator": "symplectic"},
       "particles": {"count": len(mass_of), "position": pos, "mass": mass_of, "fixed": fixed, "tag": ptag},
       "springs": {"count": n, "a": a, "b": b, "k": [ea / r for r in rest], "kd": [1e-4] * n, "rest": rest,
                   "tension_only": [1] * n, "tag": tag}}
json.dump(web, open(sys.argv[1], "w"))
PY
"$SPN" info "$OUT/io-web.json" > "$OUT/io-info-before.txt"
"$SPN" settle "$OUT/io-web.json" -o "$OUT/io-web-settled.json" --dt 5e-4 --tol 1e-7 --max-time 30
"$SPN" info "$OUT/io-web-settled.json" | tee "$OUT/io-info-settled.txt"
"$SPN" info --json "$OUT/io-web-settled.json" > "$OUT/io-info-settled.json"
if "$SPN" render --help >/dev/null 2>&1; then
    "$SPN" render "$OUT/io-web.json" -o "$OUT/io-web.png" || echo "io demo: render failed, pictures skipped"
    "$SPN" render "$OUT/io-web-settled.json" -o "$OUT/io-web-settled.png" || true
fi

#!/usr/bin/env bash
# Webs in motion (issue 5): the thesis' wind for 20 s as in Mehla 2005 figs.
# 5.46-5.47, the same web in gusty turbulent air over a backdrop with dew, and
# a slow-motion prey strike that breaks a few threads (with its energy report).
# Env: SPN = the spinneret program, OUT = the output folder.
set -eu
: "${SPN:?}" "${OUT:?}"
BIN=$(dirname "$SPN")
P="$OUT/70-wind"
VID=mp4
command -v ffmpeg > /dev/null || VID=""   # without ffmpeg: folders of PNG frames

out() { if [ -n "$VID" ]; then echo "$P-$1.$VID"; else echo "$P-$1"; fi; }

# The thesis' web values (table 5.2.1: 10 ug particles, 0.01 N/m springs,
# over-extended strands) laid out as rings and radii pinned at the rim. (The
# physical builder's thesis web hangs from four soft anchor lines; fig. 5.45's
# in-plane gusts of up to 3 W fold it into a corner within 15 s.)
python3 - "$P-thesis-web.json" <<'PY'
import json, math, sys
radials, rings, R = 24, 14, 0.15
k, m, over = 0.01, 1e-8, 1.4          # thesis spring constant and particle mass; strands laid 40% over rest
pos, mass, fixed, ptag = [0.0, 0.0, 0.0], [m], [0], [3]
for i in range(rings):
    r = R * (i + 1) / rings
    for j in range(radials):
        a = 2 * math.pi * j / radials
        pos += [r * math.cos(a), r * math.sin(a), 0.0]; mass.append(m)
        fixed.append(1 if i == rings - 1 else 0); ptag.append(1 if i == rings - 1 else 5)
pid = lambda i, j: 1 + i * radials + j % radials
A, B, tag = [], [], []
for j in range(radials):
    A.append(0); B.append(pid(0, j)); tag.append(3)
    for i in range(rings - 1):
        A.append(pid(i, j)); B.append(pid(i + 1, j)); tag.append(3)
for i in range(rings):
    for j in range(radials):
        A.append(pid(i, j)); B.append(pid(i, j + 1)); tag.append(2 if i == rings - 1 else 6)
d = lambda p, q: math.dist(pos[3 * p:3 * p + 3], pos[3 * q:3 * q + 3])
rest = [d(p, q) / over for p, q in zip(A, B)]
n = len(A)
json.dump({"format": "spinneret-web", "version": 1, "units": "SI",
           "metadata": {"builder": "demo/70-wind.sh", "parameters": {"k": k, "mass": m}},
           "world": {"gravity": [0, -9.81, 0], "drag": 0, "integrator": "symplectic"},
           "particles": {"count": len(mass), "position": pos, "mass": mass, "fixed": fixed, "tag": ptag},
           "springs": {"count": n, "a": A, "b": B, "k": [k] * n, "kd": [2e-7] * n, "rest": rest,
                       "tension_only": [1] * n, "tag": tag}}, open(sys.argv[1], "w"))
PY
"$SPN" settle "$P-thesis-web.json" -o "$P-thesis-web.json" --dt 2e-4 --max-time 10 --tol 1e-8 2> /dev/null
WEB="$P-thesis-web.json"
# A three-quarter view, so the billow along the wind shows; close on the web.
LOOK=(--camera persp --eye 0.29,0.11,0.42 --target 0,0,0 --shade 0.86,0.88,0.87 --alpha 0.8 --quiet)

# 1. Fig. 5.45 exactly, 20 s (figs. 5.46-5.47 are stills of such a run).
"$SPN" animate "$WEB" --wind thesis --duration 20 --fps 12 --size 480x480 "${LOOK[@]}" -o "$(out thesis-wind)"
"$SPN" animate "$WEB" --wind thesis --duration 20 --fps 12 --size 480x480 "${LOOK[@]}" \
    --frame-range 120-120 -o "$P-thesis-wind-frame"

# 2. The same web in gusty, turbulent air, over a backdrop, with dew.
"$BIN/example_sky_backdrop" "$P-backdrop.png" 640x640 11
SIDE=(--camera persp --eye 0.42,0.12,0.25 --target 0,0,-0.03 --shade 0.86,0.88,0.87 --alpha 0.8 --quiet)
"$SPN" animate "$WEB" --wind air --wind-speed 1.5 --gust 0.4 --turbulence 0.3 --duration 8 --fps 12 \
    --size 480x480 "${SIDE[@]}" --background "$P-backdrop.png" --dew --dew-radius 0.0012 --dew-spacing 0.006 \
    -o "$(out gusty-air)"

# 3. A prey strike in slow motion (500 frames a second played at 25): a heavy
#    beetle-sized sphere flies into the standard silk orb web (settled first)
#    near its hub at 5 m/s, stretches it, breaks a few radii (three) and goes
#    through (explicit steps: the classic contact; docs/wind-and-prey.md).
"$SPN" export scene:orb -o "$P-silk-web.json"
"$SPN" settle "$P-silk-web.json" -o "$P-silk-web.json" --solver implicit --dt 1e-3 --max-time 3 2> /dev/null
"$SPN" animate "$P-silk-web.json" --solver symplectic --duration 0.1 --fps 500 --playback-fps 25 --size 480x480 \
    --camera persp --eye 0.3,0.08,0.16 --target 0,0,-0.02 --quiet \
    --impact "0.012,0.007,0.012;0,0,-5;3e-4;0.005" --report "$P-strike.json" -o "$(out prey-strike)"
python3 - "$P-strike.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
s, e = r["strike"], r["energy"]
print("prey strike: %s, %d thread(s) broken %s; when the strike ended (%.0f ms) the radii held %.0f%% of the "
      "%.2g J the prey lost, the capture spiral %.0f%%, the air %.0f%% (energy balance within %.2g%%)"
      % (r["prey"][0]["outcome"], r["broken_total"], r["broken"], 1e3 * s["time"], 100 * s.get("radius", 0),
         s["prey_kinetic_lost"], 100 * s.get("capture", 0), 100 * s["air_drag"], 100 * e["balance_error_relative"]))
PY

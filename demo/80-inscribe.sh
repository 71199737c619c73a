#!/usr/bin/env bash
# Charlotte's web (Mehla 2005, ch. 6): the words of the book inscribed into a
# physical orb web in the four modes of the thesis (plain, cross-hatch, fill,
# outline), a logo-like image drawn by a few lines of our own code, random gaps
# (fig. 6.18), and, when the program has `animate`, the inscribed web in wind.
# Each run writes the web file, its render and the overlay of the target.
set -eu
: "${SPN:?}" "${OUT:?}"
D=$OUT/inscribe
mkdir -p "$D"

# The web: the builder's default orb web when `build` exists, else the standard web.
WEB=$D/web.json
if "$SPN" build -o "$WEB" >/dev/null 2>&1; then
    echo "web: spinneret build (default orb web)"
elif "$SPN" build --species generic -o "$WEB" >/dev/null 2>&1; then
    echo "web: spinneret build --species generic"
else
    cp tests/data/inscribe/orb.json "$WEB"
    echo "web: the standard orb web (tests/data/inscribe/orb.json)"
fi

# Settling: the implicit solver when the program has it, else small explicit
# steps. The web is brought to rest once here, so each inscription's first
# settle has nothing left to do.
if "$SPN" settle "$WEB" --solver implicit --max-time 5 -o "$WEB" >/dev/null 2>&1; then
    SETTLE=(--solver implicit --dt 1e-3 --max-time 5)
else
    SETTLE=(--solver symplectic --dt 2e-6 --max-time 0.2)
fi

inscribe() { # name, then inscribe options
    local name=$1; shift
    "$SPN" inscribe "$WEB" "$@" "${SETTLE[@]}" -o "$D/$name.json" \
        --render "$D/$name.png" --overlay "$D/$name-overlay.png" 2>"$D/$name.log" || { cat "$D/$name.log"; exit 1; }
    echo "$name: $(grep -E 'removed' "$D/$name.log" | sed 's/^ *//')"
}

inscribe some-pig-none     --text "SOME PIG" --emphasis none
inscribe terrific-crosshatch --text "TERRIFIC" --emphasis crosshatch
inscribe radiant-fill      --text "RADIANT" --emphasis fill
inscribe humble-outline    --text "HUMBLE" --emphasis outline
inscribe some-pig-fill     --text "SOME" --text "PIG" --emphasis fill
inscribe terrific-fill     --text "TERRIFIC" --emphasis fill
inscribe humble-fill       --text "HUMBLE" --emphasis fill
inscribe gaps              --gaps 40 --seed 3

# A logo-like target (three interlocking ellipse rings, mainly low-frequency
# content like the thesis' fig. 6.6), written as a PGM by our own code.
python3 - "$D/logo.pgm" <<'PY'
import math, sys
W, H = 520, 360
def ring(x, y, cx, cy, a, b, t):
    r = math.hypot((x - cx) / a, (y - cy) / b)
    return abs(r - 1) * min(a, b) < t
rows = []
for j in range(H):
    row = []
    for i in range(W):
        x, y = i - W / 2, j - H / 2
        ink = ring(x, y, 0, 0, 225, 145, 18) or ring(x, y, 0, -20, 80, 120, 16) or ring(x, y, 0, -62, 200, 60, 16)
        row.append("0" if ink else "255")
    rows.append(" ".join(row))
open(sys.argv[1], "w").write("P2\n# logo-like target made by demo/80-inscribe.sh\n%d %d\n255\n%s\n" % (W, H, "\n".join(rows)))
PY
inscribe logo-fill --image "$D/logo.pgm" --fit 0.95 --emphasis fill

# The inscribed web in wind, so the message sways with the web.
if "$SPN" animate --help >/dev/null 2>&1; then
    # Wind blows along z, so a camera from the side shows the sway; 20 ms
    # implicit steps keep the 10 000-thread fill affordable in a demo.
    if "$SPN" animate "$D/some-pig-fill.json" -o "$D/some-pig-wind.mp4" --duration 2 --fps 15 --substeps 3 \
        --wind air --wind-speed 3 --gust 0.5 --solver implicit --camera persp --yaw 35 --pitch 10 \
        --size 600x600 --quiet >"$D/wind.log" 2>&1; then
        echo "wind: $D/some-pig-wind.mp4"
    else
        echo "wind: animate failed (skipped): $(tail -1 "$D/wind.log")"
    fi
else
    echo "wind: no animate command in this build (skipped)"
fi

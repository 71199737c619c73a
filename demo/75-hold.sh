#!/usr/bin/env bash
# A slow prey caught and held (issue 5): a 0.2 g insect at 0.5 m/s strikes an
# Araneus web (built and settled as a species web, implicit solver with silk's
# hysteresis), is stopped, springs back with at most what the hysteresis
# leaves, and is held by the capture glue over its outline (legs, wings).
# Slow motion (100 frames a second played at 25), close on the prey, and the
# report's outcome, glue and energy balance printed.
# Env: SPN = the spinneret program, OUT = the output folder.
set -eu
: "${SPN:?}" "${OUT:?}"
P="$OUT/75-hold"
VID=mp4
command -v ffmpeg > /dev/null || VID=""   # without ffmpeg: a folder of PNG frames
MOVIE="$P-caught"; [ -n "$VID" ] && MOVIE="$P-caught.$VID"

"$SPN" build --species araneus --size 0.12 --settle -o "$P-web.json" 2> /dev/null
# The prey 24 mm right of and 6 mm below the hub, 6 mm in front of the web.
HUB=$(python3 - "$P-web.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))["particles"]
i = p["tag"].index(3)
print("%.6f,%.6f" % (p["position"][3 * i], p["position"][3 * i + 1]))
PY
)
X=$(python3 -c "print('%.6f' % (${HUB%,*} + 0.024))"); Y=$(python3 -c "print('%.6f' % (${HUB#*,} - 0.006))")
"$SPN" animate "$P-web.json" --solver implicit --duration 0.3 --fps 100 --playback-fps 25 --size 480x480 \
    --camera persp --eye "$(python3 -c "print('%.4f,%.4f,0.05' % ($X + 0.04, $Y + 0.02))")" --target "$X,$Y,0" --fov 35 \
    --quiet --impact "$X,$Y,0.006;0,0,-0.5;2e-4;0.004" --report "$P-report.json" -o "$MOVIE"
python3 - "$P-report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
e = r["energy"]
print("slow prey: %s, %d thread(s) broken; %d glue droplets holding it (%.1f mN), %.2g J of glue let go; "
      "energy balance within %.2g%%" % (r["prey"][0]["outcome"], r["broken_total"], e["glue_droplets_holding"],
      1e3 * e["glue_strength_holding"], e["glue"], 100 * e["balance_error_relative"]))
PY

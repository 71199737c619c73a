#!/usr/bin/env bash
# Orb-web builders: one web per species, in silk and in the thesis' threads; the physical thesis' spiral densities
# (fig. 5.28) and spoke counts (fig. 5.33); geometric webs with 3-6 anchors and
# contraction 10% and 40% (figs. 4.1-4.9 of the Japanese thesis); the frames of
# a web being built.
set -eu
D="$OUT/build"
mkdir -p "$D"
LOOK="--size 1000x1000 --glow 0.4 --sheen 0.6 --smooth --quiet"
# Silk webs settle with the implicit solver; builds without it show them as laid.
SETTLE=""
if "$SPN" build --species zilla --size 0.04 --settle --settle-time 0.05 -o "$D/probe.json" 2>/dev/null; then
  SETTLE="--settle --settle-time 1"
fi
rm -f "$D/probe.json"
for sp in generic araneus zilla argiope zygiella; do
  "$SPN" build --species $sp --seed 7 $SETTLE -o "$D/species-$sp.json"
  "$SPN" render "$D/species-$sp.json" -o "$D/species-$sp.png" $LOOK --dew --dew-spacing 0.004 --dew-radius 0.0004
done
# The same webs woven of the thesis' soft threads, laid at its own strains
# (spokes 133%): solved to rest in a tenth of a second each.
for sp in generic araneus zilla argiope zygiella; do
  "$SPN" build --species $sp --seed 7 --preset thesis --settle -o "$D/thesis-threads-$sp.json" 2>/dev/null
  "$SPN" render "$D/thesis-threads-$sp.json" -o "$D/thesis-threads-$sp.png" --size 800x800 --shade 0.86,0.88,0.87 --alpha 0.7 --quiet
done
SQ="-0.3,0.32;0.32,0.28;0.3,-0.34;-0.32,-0.28"
i=0
for pr in "0.007 0.003" "0.009 0.003" "0.011 0.005" "0.015 0.007"; do
  set -- $pr; i=$((i + 1))
  "$SPN" build --method physical --anchors "$SQ" --spoke-placement $1 --spoke-rest $2 --settle --settle-time 10 \
    -o "$D/thesis-spiral-$i.json"
  "$SPN" render "$D/thesis-spiral-$i.json" -o "$D/thesis-spiral-$i.png" --size 800x800 --shade 0.86,0.88,0.87 --alpha 0.7 --quiet
done
i=0
for pr in "0.020 0.015" "0.030 0.025" "0.040 0.035" "0.057 0.050"; do
  set -- $pr; i=$((i + 1))
  "$SPN" build --method physical --anchors "$SQ" --frame-placement $1 --frame-rest $2 --settle --settle-time 10 \
    -o "$D/thesis-spokes-$i.json"
  "$SPN" render "$D/thesis-spokes-$i.json" -o "$D/thesis-spokes-$i.png" --size 800x800 --shade 0.86,0.88,0.87 --alpha 0.7 --quiet
done
A3="0,0.5;-0.45,-0.3;0.45,-0.3"
A4="-0.4,0.42;-0.42,-0.38;0.4,-0.45;0.42,0.38"
A5="0,0.5;-0.47,0.15;-0.3,-0.42;0.3,-0.42;0.47,0.15"
A6="0,0.5;-0.45,0.25;-0.42,-0.27;0,-0.5;0.43,-0.24;0.45,0.26"
n=3
for a in "$A3" "$A4" "$A5" "$A6"; do
  "$SPN" build --method geometric --anchors "$a" --m 0.1 -o "$D/geometric-$n.json"
  "$SPN" render "$D/geometric-$n.json" -o "$D/geometric-$n.png" $LOOK
  n=$((n + 1))
done
"$SPN" build --method geometric --anchors "$A6" --m 0.4 -o "$D/geometric-6-m40.json"
"$SPN" render "$D/geometric-6-m40.json" -o "$D/geometric-6-m40.png" $LOOK
if command -v ffmpeg >/dev/null; then
  "$SPN" build --species araneus --seed 3 --frames "$D/building.gif" --frame-count 48 -o "$D/building.json"
else
  "$SPN" build --species araneus --seed 3 --frames "$D/building" --frame-count 48 -o "$D/building.json"
fi
if command -v montage >/dev/null; then
  montage "$D"/thesis-spiral-?.png -tile 4x1 -geometry 400x400+4+4 "$D/thesis-spirals.png"
  montage "$D"/thesis-spokes-?.png -tile 4x1 -geometry 400x400+4+4 "$D/thesis-spokes.png"
  montage "$D"/species-*.png -tile 5x1 -geometry 400x400+4+4 "$D/species.png"
  montage "$D"/thesis-threads-*.png -tile 5x1 -geometry 400x400+4+4 "$D/species-thesis-threads.png"
  montage "$D"/geometric-*.png -tile 5x1 -geometry 400x400+4+4 "$D/geometric.png"
fi

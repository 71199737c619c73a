#!/usr/bin/env bash
# Orb-web builders: one web per species; the physical thesis' spiral densities
# (fig. 5.28) and spoke counts (fig. 5.33); geometric webs with 3-6 anchors and
# contraction 10% and 40% (figs. 4.1-4.9 of the Japanese thesis); the frames of
# a web being built.
set -eu
D="$OUT/build"
mkdir -p "$D"
for sp in generic araneus zilla argiope zygiella; do
  "$SPN" build --species $sp --seed 7 -o "$D/species-$sp.json" --png "$D/species-$sp.png"
done
SQ="-0.4,0.42;0.42,0.38;0.4,-0.45;-0.42,-0.38"
i=0
for pr in "0.007 0.003" "0.009 0.003" "0.011 0.005" "0.015 0.007"; do
  set -- $pr; i=$((i + 1))
  "$SPN" build --method physical --anchors "$SQ" --spoke-placement $1 --spoke-rest $2 --settle --settle-time 10 \
    -o "$D/thesis-spiral-$i.json" --png "$D/thesis-spiral-$i.png"
done
i=0
for pr in "0.020 0.015" "0.030 0.025" "0.040 0.035" "0.057 0.050"; do
  set -- $pr; i=$((i + 1))
  "$SPN" build --method physical --anchors "$SQ" --frame-placement $1 --frame-rest $2 --settle --settle-time 10 \
    -o "$D/thesis-spokes-$i.json" --png "$D/thesis-spokes-$i.png"
done
A3="0,0.5;-0.45,-0.3;0.45,-0.3"
A4="-0.4,0.42;-0.42,-0.38;0.4,-0.45;0.42,0.38"
A5="0,0.5;-0.47,0.15;-0.3,-0.42;0.3,-0.42;0.47,0.15"
A6="0,0.5;-0.45,0.25;-0.42,-0.27;0,-0.5;0.43,-0.24;0.45,0.26"
n=3
for a in "$A3" "$A4" "$A5" "$A6"; do
  "$SPN" build --method geometric --anchors "$a" --m 0.1 -o "$D/geometric-$n.json" --png "$D/geometric-$n.png"
  n=$((n + 1))
done
"$SPN" build --method geometric --anchors "$A6" --m 0.4 -o "$D/geometric-6-m40.json" --png "$D/geometric-6-m40.png"
"$SPN" build --species araneus --seed 3 --keep-aux --frames "$D/building" --frame-count 48 -o "$D/building.json"
if command -v montage >/dev/null; then
  montage "$D"/thesis-spiral-?.png -tile 4x1 -geometry 400x400+4+4 "$D/thesis-spirals.png"
  montage "$D"/thesis-spokes-?.png -tile 4x1 -geometry 400x400+4+4 "$D/thesis-spokes.png"
  montage "$D"/species-*.png -tile 5x1 -geometry 400x400+4+4 "$D/species.png"
  montage "$D"/geometric-*.png -tile 5x1 -geometry 400x400+4+4 "$D/geometric.png"
fi

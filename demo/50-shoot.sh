#!/usr/bin/env bash
# Web shooting (docs/shooting.md): one shot through all four phases — THWIP
# (flight), THWAP (snap taut), WHOOSH (swing), ZIPP (release) — as a video and
# as JSON; then THWIP three ways side by side, so the value of each step shows:
# noise off (the bare ballistic arc) / noise on with the pure soft pull / noise
# with the velocity blend, all three seen by the same camera. Each is also kept as an onion skin (every 4th frame
# laid over one picture) for judging the motion at a glance.
set -eu
out="$OUT/shoot"
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

shot=(--from 0,1.5,0 --to 10,9,0 --speed 22 --seed 3)
"$SPN" shoot "${shot[@]}" --size 960x540 --quiet -o "$out/shot-all-phases.mp4"
"$SPN" shoot "${shot[@]}" -o "$out/shot-all-phases.json"
"$SPN" shoot "${shot[@]}" --size 640x360 --quiet -o "$tmp/all"
sheet=()
for f in 20 34 40 46 60 100 150 200 236 260 290 315; do sheet+=("$(printf '%s/all/frame_%05d.png' "$tmp" "$f")"); done
montage "${sheet[@]}" -tile 3x4 -geometry 480x270+2+2 -background black "$out/shot-all-phases-contact-sheet.png"

labels=("noise off" "noise, pure pull (blend 0)" "noise + velocity blend 0.6")
opts=("--noise 0" "--noise 0.08 --blend 0" "--noise 0.08 --blend 0.6")
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
for i in 0 1 2; do
  # shellcheck disable=SC2086
  "$SPN" shoot "${shot[@]}" ${opts[$i]} --phases thwip --size 480x400 --eye 7.5,7.5,15 --look-at 5,5.5,0 \
    --quiet -o "$tmp/v$i"
  frames=$(ls "$tmp/v$i"/frame_*.png | awk 'NR % 4 == 1')
  # shellcheck disable=SC2086
  convert $frames -background black -compose lighten -flatten "$tmp/onion$i.png"
done
montage -label "${labels[0]}" "$tmp/onion0.png" -label "${labels[1]}" "$tmp/onion1.png" \
  -label "${labels[2]}" "$tmp/onion2.png" -tile 3x1 -geometry +2+2 -background black -fill white \
  -font "$font" -pointsize 16 "$out/thwip-side-by-side-onion.png"
if command -v ffmpeg > /dev/null; then
  ffmpeg -loglevel error -y -framerate 30 -i "$tmp/v0/frame_%05d.png" -framerate 30 -i "$tmp/v1/frame_%05d.png" \
    -framerate 30 -i "$tmp/v2/frame_%05d.png" -filter_complex \
    "[0]drawtext=fontfile=$font:text='${labels[0]}':x=10:y=10:fontsize=18:fontcolor=white[a];\
[1]drawtext=fontfile=$font:text='${labels[1]}':x=10:y=10:fontsize=18:fontcolor=white[b];\
[2]drawtext=fontfile=$font:text='${labels[2]}':x=10:y=10:fontsize=18:fontcolor=white[c];\
[a][b][c]hstack=inputs=3,tpad=stop_mode=clone:stop_duration=1,format=yuv420p" \
    "$out/thwip-side-by-side-half-speed.mp4"
fi
echo "shoot: wrote $out"

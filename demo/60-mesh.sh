#!/usr/bin/env bash
# Meshes as spring systems: the documentation's bouncing ball (`drop`) and a
# POV film of a cloth falling on a table (`film`), both rendered by POV-Ray.
# Writes $OUT/mesh-ball/ and $OUT/mesh-cloth/ (frames, movie.mp4) and a contact
# sheet of each. Needs povray and ffmpeg; without them only the frames are written.
set -eu
: "${SPN:?}" "${OUT:?}"
render=()
if command -v povray >/dev/null && command -v ffmpeg >/dev/null; then render=(--render --size 320x240); fi

rm -rf "$OUT/mesh-ball" "$OUT/mesh-cloth"
echo "-- ball: assets/models/sphere.obj dropped with the documentation's parameters"
"$SPN" drop assets/models/sphere.obj -SS=1500 -BS=1500 -SD=4.0 -BD=3.0 -M=0.5 -V=0.30 -T=0.01 \
  -DT=0.08 -MINT=0.1 -MAXT=6 --pov "${render[@]}" ${render:+--movie "$OUT/mesh-ball/movie.mp4"} -o "$OUT/mesh-ball"
echo "-- cloth: assets/scenes/cloth_table.pov through the film maker"
"$SPN" film assets/scenes/cloth_table.pov --max-time 2.4 --fps 10 "${render[@]}" -o "$OUT/mesh-cloth"

# Six frames spread over each run, side by side.
sheet() {
  local dir=$1 frames n picks=()
  frames=("$dir"/frame_*.png)
  n=${#frames[@]}
  for k in 0 1 2 3 4 5; do picks+=("${frames[$((k * (n - 1) / 5))]}"); done
  montage "${picks[@]}" -tile 3x2 -geometry +2+2 "$2"
  echo "contact sheet: $2"
}
if [ ${#render[@]} -gt 0 ] && command -v montage >/dev/null; then
  sheet "$OUT/mesh-ball" "$OUT/mesh-ball-sheet.png"
  sheet "$OUT/mesh-cloth" "$OUT/mesh-cloth-sheet.png"
fi

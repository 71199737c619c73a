#!/usr/bin/env bash
# spinneret film: zero time gives back each shipped scene (numbers compared by
# value), a short film renders with povray into frames of the asked size and a
# movie (skipped, with the reason, without povray/ffmpeg), and malformed scenes
# fail with the line named and leave no output folder.
set -u
SPN=$1
SCENES=$SPN_SOURCE_DIR/assets/scenes
BAD=$SPN_TEST_DATA/bad
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# Numbers printed with %.9g, everything else kept: equal texts after normalising both.
normalise() { awk '{ out = ""; s = $0
  while (match(s, /[-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?/)) {
    out = out substr(s, 1, RSTART - 1) sprintf("%.9g", substr(s, RSTART, RLENGTH) + 0); s = substr(s, RSTART + RLENGTH) }
  print out s }' "$1"; }

for scene in "$SCENES"/*.pov; do
  name=$(basename "$scene" .pov)
  "$SPN" film "$scene" --max-time 0 -o "$tmp/$name" >/dev/null || fail "film $name --max-time 0"
  [ "$(ls "$tmp/$name")" = "frame_00000.pov" ] || fail "$name: expected one frame, got $(ls "$tmp/$name")"
  cmp -s <(normalise "$scene") <(normalise "$tmp/$name/frame_00000.pov") || fail "$name: round trip changed the scene"
done

# A short simulation moves the cloth down, and only vertex numbers change.
"$SPN" film "$SCENES/cloth_pinned2.pov" --max-time 0.2 --fps 10 -o "$tmp/pinned" >/dev/null || fail "film pinned"
[ -f "$tmp/pinned/frame_00002.pov" ] || fail "pinned: frame 2 missing"
diff <(grep -v '^ *<' "$SCENES/cloth_pinned2.pov") <(grep -v '^ *<' "$tmp/pinned/frame_00002.pov") >/dev/null \
  || fail "pinned: lines other than vectors changed"
cmp -s "$SCENES/cloth_pinned2.pov" "$tmp/pinned/frame_00002.pov" && fail "pinned: nothing moved"

# Rendering.
if command -v povray >/dev/null && command -v ffmpeg >/dev/null; then
  "$SPN" film "$SCENES/ball_floor.pov" --max-time 0.1 --fps 20 --render --size 64x48 -o "$tmp/ball" >/dev/null \
    || fail "film --render"
  for f in 0 1 2; do
    png=$tmp/ball/frame_0000$f.png
    [ -s "$png" ] || fail "render: $png missing"
    size=$(od -An -tu1 -j16 -N8 "$png" | awk '{ print $3 * 256 + $4 "x" $7 * 256 + $8 }')
    [ "$size" = "64x48" ] || fail "render: $png is $size, expected 64x48"
  done
  [ -s "$tmp/ball/movie.mp4" ] || fail "render: no movie"
else
  echo "skipped rendering: povray or ffmpeg not installed"
fi

# Without povray on the PATH, --render fails at once and writes nothing.
msg=$(env PATH=/nonexistent "$SPN" film "$SCENES/ball_floor.pov" --render -o "$tmp/nopov" 2>&1); rc=$?
[ $rc -eq 1 ] || fail "--render without povray: exit $rc"
echo "$msg" | grep -q "povray" || fail "--render without povray: message '$msg'"
[ -e "$tmp/nopov" ] && fail "--render without povray left a folder"

# Malformed scenes: exit 1, the file and line named, no folder left.
for pair in pov_missing_brace:3 pov_include:2 pov_nan:5 pov_bad_face:5 pov_quad:5 pov_sphere_simulated:3; do
  name=${pair%%:*}; line=${pair##*:}
  msg=$("$SPN" film "$BAD/$name.pov" -o "$tmp/bad" 2>&1 >/dev/null); rc=$?
  [ $rc -eq 1 ] || fail "$name: exit $rc, expected 1"
  echo "$msg" | grep -q "$name.pov:$line:" || fail "$name: message '$msg' does not name line $line"
  [ -e "$tmp/bad" ] && fail "$name: left $tmp/bad behind"
done
"$SPN" film "$SCENES/ball_floor.pov" --fps 0 -o "$tmp/x" 2>/dev/null; [ $? -eq 2 ] || fail "--fps 0 should be a usage error"
"$SPN" film --help | grep -q "spring_system_fixed" || fail "--help"
echo "film ok"

#!/usr/bin/env bash
# spinneret drop: the documentation's example command line (its -SS=... forms)
# runs to a stable ball resting on the ground, never below it; the same with
# separate values; OBJ and POV frames; bad models fail with the line named.
set -u
SPN=$1
MODELS=$SPN_SOURCE_DIR/assets/models
BAD=$SPN_TEST_DATA/bad
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$SPN" drop "$MODELS/sphere.obj" -SS=1500 -BS=1500 -SD=4.0 -BD=3.0 -M=0.5 -v=0.30 -t=0.01 -DT=0.03 \
      -MinT=0.1 -maxT=15.3 -o "$tmp/ball") || fail "drop with the documentation's options"
echo "$out" | grep -q "^stable at t = " || fail "ball did not become stable: $out"
low=$(echo "$out" | sed -n 's/^lowest point y = \([^ ]*\) m.*/\1/p')
awk -v y="$low" 'BEGIN { exit !(y >= -1e-9) }' || fail "ball went below the ground: $low"
n=$(ls "$tmp/ball" | grep -c '\.obj$')
[ "$n" -gt 10 ] || fail "expected frames, got $n"
# The last frame rests on the ground: every vertex within [0, 0.45] m.
awk '/^v / { if ($3 < -1e-9 || $3 > 0.45) bad = 1 } END { exit bad }' "$(ls -d "$tmp"/ball/*.obj | tail -1)" \
  || fail "last frame not resting on the ground"

out=$("$SPN" drop "$MODELS/torus.obj" -SS 800 -M 0.05 -V 0 --max-time 0.3 --pov -o "$tmp/torus") || fail "drop torus"
echo "$out" | grep -q "^max time reached at t = 0.3 s" || fail "torus report: $out"
[ -f "$tmp/torus/frame_00010.pov" ] || fail "torus: POV frames missing"
grep -q "mesh2" "$tmp/torus/frame_00010.pov" || fail "torus: no mesh2 in the POV frame"

if command -v ffmpeg >/dev/null; then
  "$SPN" drop "$MODELS/sphere.obj" --max-time 0.2 -DT 0.05 --size 64x48 --video "$tmp/ball.gif" -o "$tmp/v" >/dev/null \
    || fail "drop --video"
  [ -s "$tmp/ball.gif" ] || fail "--video wrote no gif"
  [ "$(ls "$tmp/v" | wc -l)" -eq 5 ] || fail "--video: expected 5 OBJ frames too"
else
  echo "skipped --video: ffmpeg not installed"
fi

for pair in mesh_bad_index.obj:4 mesh_nan.obj:2 mesh_quad.obj:6 mesh_missing_data.ply:11 mesh_quad.ply:14; do
  name=${pair%%:*}; line=${pair##*:}
  msg=$("$SPN" drop "$BAD/$name" -o "$tmp/bad" 2>&1 >/dev/null); rc=$?
  [ $rc -eq 1 ] || fail "$name: exit $rc, expected 1"
  echo "$msg" | grep -q "$name:$line:" || fail "$name: message '$msg' does not name line $line"
  [ -e "$tmp/bad" ] && fail "$name: left $tmp/bad behind"
done
"$SPN" drop "$MODELS/sphere.obj" -SS=abc -o "$tmp/x" 2>/dev/null; [ $? -eq 2 ] || fail "-SS=abc should be a usage error"
"$SPN" drop "$MODELS/sphere.obj" --fix 9999 -o "$tmp/x" 2>/dev/null; [ $? -eq 2 ] || fail "--fix out of range"
[ -e "$tmp/x" ] && fail "a usage error left $tmp/x"
"$SPN" drop --help | grep -q -- "-SS" || fail "--help"
echo "drop ok"

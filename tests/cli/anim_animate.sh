#!/usr/bin/env bash
# spinneret animate: --frame-range frames are the same bits as the whole run's,
# the impact report reads as JSON with the outcome, bad options are refused
# with the option named and nothing written, a frame that cannot be written
# fails the run, and an interrupt keeps finished frames and leaves no partial
# video.
. "$(dirname "$0")/lib/common.sh" "$@"
WEB=$SPN_TEST_DATA/anim/orb.json

common=(--wind thesis --thesis-gain 300 --duration 1 --fps 10 --size 160x160 --quiet --camera persp --eye 0.3,0.15,0.35)
"$SPN" animate "$WEB" -o "$T/whole" "${common[@]}" || fail "whole run"
[ "$(ls "$T/whole" | wc -l)" -eq 11 ] || fail "whole run should have 11 frames, has $(ls "$T/whole" | wc -l)"
"$SPN" animate "$WEB" -o "$T/part" "${common[@]}" --frame-range 6-8 || fail "frame range run"
[ "$(ls "$T/part" | wc -l)" -eq 3 ] || fail "range 6-8 should give 3 frames"
for f in 6 7 8; do
  n=$(printf 'frame_%05d.png' $f)
  cmp -s "$T/whole/$n" "$T/part/$n" || fail "$n differs between the whole run and the range"
done
# The frames really move: frame 8 differs from frame 0.
cmp -s "$T/whole/frame_00000.png" "$T/whole/frame_00008.png" && fail "the wind did not move the web"

# Air with the same seed twice gives the same states; states are web files.
"$SPN" animate "$WEB" -o "$T/air" --wind air --wind-speed 3 --duration 0.2 --fps 10 --size 64x64 --quiet \
  --save-states "$T/st" || fail "air run"
[ -f "$T/st/state_00002.json" ] || fail "--save-states wrote no state for frame 2"
"$SPN" info "$T/st/state_00002.json" > /dev/null || fail "a saved state is not a readable web file"

# A web of real silk on an explicit solver: the run says how many steps a
# frame that takes and what the implicit solver would take; not when quiet,
# nor on a web of soft threads.
"$SPN" build --species araneus -o "$T/silk.json" > /dev/null 2>&1 || fail "species build"
"$SPN" animate "$T/silk.json" -o "$T/silk" --duration 0 --size 64x64 2> "$T/hint" || fail "silk run"
grep -q -- "symplectic takes [0-9]* steps a frame.*--solver implicit takes 20$" "$T/hint" || fail "no solver hint: $(cat "$T/hint")"
"$SPN" animate "$T/silk.json" -o "$T/silk2" --duration 0 --size 64x64 --quiet 2> "$T/hint" || fail "quiet silk run"
[ -s "$T/hint" ] && fail "--quiet printed: $(cat "$T/hint")"
"$SPN" animate "$WEB" -o "$T/soft" --duration 0 --size 64x64 2> "$T/hint" || fail "soft run"
grep -q -- "--solver implicit" "$T/hint" && fail "a hint on a soft web: $(cat "$T/hint")"

# A prey report.
"$SPN" animate "$WEB" -o "$T/prey" --duration 0.1 --fps 50 --size 64x64 --quiet \
  --impact "0.012,0.007,0.01;0,0,-8;2e-4;0.005" --report "$T/r.json" || fail "impact run"
python3 - "$T/r.json" <<'PY' || fail "report"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["prey"][0]["outcome"] in ("held", "stopped", "passed_through", "bounced"), r["prey"]
assert r["energy"]["balance_error_relative"] < 0.02, r["energy"]
assert "radius" in r["threads"], r["threads"]
PY

# Bad inputs: exit 2 (usage) or 1 (failure), the option or file named, no output.
expect() { # code pattern args...
  local code=$1 pat=$2; shift 2
  "$SPN" animate "$@" 2> "$T/err" > /dev/null; local got=$?
  [ $got -eq "$code" ] || fail "animate $*: exit $got, expected $code"
  grep -q -- "$pat" "$T/err" || fail "animate $*: message lacks '$pat': $(cat "$T/err")"
}
expect 2 "--fps" "$WEB" -o "$T/bad1" --fps 0
expect 2 "--wind" "$WEB" -o "$T/bad2" --wind storm
expect 2 "--impact" "$WEB" -o "$T/bad3" --impact "1,2;3"
expect 2 "--impact" "$WEB" -o "$T/bad3" --impact "0,0,0.01;0,0,-1;-1;0.01"
expect 2 "--glue-outline" "$WEB" -o "$T/bad3" --glue-outline 0.5
expect 2 "--frame-range" "$WEB" -o "$T/bad4" --frame-range 5-2
expect 2 "--report" "$WEB" -o "$T/bad5" --report "$T/r2.json"
expect 2 "missing -o" "$WEB"
expect 2 "frame-range" "$WEB" -o "$T/bad6" --duration 1 --fps 10 --frame-range 3-50
expect 1 "nope.json" "$T/nope.json" -o "$T/bad7"
expect 1 "make_orb.c" "$SPN_TEST_DATA/anim/make_orb.c" -o "$T/bad8"
for b in bad1 bad2 bad3 bad4 bad5 bad6 bad7 bad8 r2.json; do
  [ -e "$T/$b" ] && fail "a refused run left $b behind"
done
[ -e "$T/bad6" ] && fail "frame-range failure left output"

# A frame that cannot be written (the file size limit here, as a full disk
# would) fails the run with the frame named, though frames are drawn and
# written on a thread of their own (tools/frame_pipe.c); no partial file.
( trap '' XFSZ; ulimit -f 16; "$SPN" animate "$WEB" -o "$T/full" --duration 1 --fps 10 --size 300x300 --quiet ) 2> "$T/err"
code=$?
[ $code -eq 1 ] || fail "a run whose frames cannot be written exited $code, expected 1"
grep -q "full/frame_0000[0-9].png: cannot write" "$T/err" || fail "write failure message: $(cat "$T/err")"
ls -a "$T/full" | grep -q tmp && fail "a failed frame left a temporary file"

# Frames are drawn on as many threads as OpenMP would use, each from its own
# copy of the world, and added in the order they were handed over: one
# thread and two give the same files. A frame that cannot be written (its
# name taken by a folder) ends the run there: the frames before it stay,
# none after it is written.
OMP_NUM_THREADS=1 "$SPN" animate "$WEB" -o "$T/one" "${common[@]}" --dew || fail "frames on one thread"
OMP_NUM_THREADS=2 "$SPN" animate "$WEB" -o "$T/two" "${common[@]}" --dew || fail "frames on two threads"
diff -r "$T/one" "$T/two" > /dev/null || fail "frames differ between one drawing thread and two"
mkdir -p "$T/gap/frame_00004.png"
OMP_NUM_THREADS=2 "$SPN" animate "$WEB" -o "$T/gap" "${common[@]}" 2> "$T/err"
code=$?
[ $code -eq 1 ] || fail "a run with an unwritable frame exited $code, expected 1"
grep -q "gap/frame_00004.png: cannot write" "$T/err" || fail "unwritable frame message: $(cat "$T/err")"
[ "$(ls "$T/gap" | tr '\n' ' ')" = "frame_00000.png frame_00001.png frame_00002.png frame_00003.png frame_00004.png " ] ||
  fail "after an unwritable frame the folder holds: $(ls "$T/gap")"

# Interrupt: finished frames stay (a shorter video), nothing partial.
if command -v ffmpeg > /dev/null; then
  "$SPN" animate "$WEB" -o "$T/v.mp4" --wind thesis --duration 60 --fps 25 --size 64x64 --quiet &
  pid=$!
  # Interrupt once ffmpeg has written part of the video (a fixed sleep is too
  # short under valgrind or on a loaded machine).
  for _ in $(seq 1 6000); do [ -n "$(find "$T" -name 'v.mp4*tmp*' -size +0 -o -name '*tmp*v.mp4' -size +0)" ] && break; sleep 0.05; done
  kill -INT $pid
  wait $pid; code=$?
  [ $code -eq 130 ] || fail "interrupted video run exited $code, expected 130"
  [ -s "$T/v.mp4" ] || fail "an interrupted video run kept no video of its finished frames"
  ls -a "$T" | grep -q 'tmp' && fail "an interrupted run left a temporary file"
fi
"$SPN" animate "$WEB" -o "$T/fr" --wind thesis --duration 60 --fps 25 --size 64x64 --quiet &
pid=$!
for _ in $(seq 1 6000); do ls "$T/fr" 2>/dev/null | grep -q '^frame_.*\.png$' && break; sleep 0.05; done
kill -TERM $pid
wait $pid; code=$?
[ $code -eq 130 ] || fail "interrupted frame run exited $code, expected 130"
n=$(ls "$T/fr" | grep -c '^frame_.*\.png$')
[ "$n" -ge 1 ] || fail "an interrupted frame run kept no frames"
ls "$T/fr" | grep -v '^frame_[0-9]*\.png$' && fail "an interrupted run left a partial file"
echo "anim_animate ok"

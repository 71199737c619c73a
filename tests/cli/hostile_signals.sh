#!/usr/bin/env bash
# SIGINT and SIGTERM during long commands: a frame loop stops between frames,
# keeps every complete frame (a folder of PNGs, or a shorter video) and says
# how far it got; a command caught mid-computation writes nothing, leaves no
# temporary file and does not touch an older output of the same name.
set -u
SPN=$1
fail() { echo "FAIL: $*"; exit 1; }
T=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$T"' EXIT

wait_for() { # file: poll until it exists (the command is slow to start under sanitizers)
  for _ in $(seq 1 1200); do [ -e "$1" ] && return 0; sleep 0.05; done
  fail "$1 never appeared: $(cat "$T/err" 2>/dev/null)"
}
no_temporaries() { ! find "$T" -name '*.tmp*' | grep -q . || fail "temporary left: $(find "$T" -name '*.tmp*')"; }

# 1. A turntable into a PNG folder, interrupted after its third frame.
"$SPN" render scene:orb:6x8 -o "$T/frames" --turntable 100000 --size 200x200 --quiet 2>"$T/err" &
pid=$!; pids+=("$pid")
wait_for "$T/frames/frame_00002.png"
kill -INT "$pid"
wait "$pid"; rc=$?
[ "$rc" -eq 130 ] || fail "render --turntable after SIGINT exited $rc (expected 130): $(cat "$T/err")"
done_frames=$(sed -n 's/.*interrupted (SIGINT) after \([0-9]*\) of 100000.*/\1/p' "$T/err")
[ -n "$done_frames" ] || fail "no 'interrupted (SIGINT) after N of 100000' in: $(cat "$T/err")"
n=$(find "$T/frames" -name 'frame_*.png' | wc -l)
[ "$n" -eq "$done_frames" ] || fail "message says $done_frames frames, folder holds $n"
for f in "$T"/frames/frame_*.png; do # complete PNGs: signature first, IEND chunk last
  [ "$(head -c 8 "$f" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "$f: not a PNG"
  tail -c 8 "$f" | grep -q IEND || fail "$f: truncated (no IEND at the end)"
done
no_temporaries

# 2. A video: SIGTERM after some frames; the video holds the complete frames.
if command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null; then
  "$SPN" render scene:orb:6x8 -o "$T/spin.mp4" --turntable 100000 --size 200x200 2>"$T/err" &
  pid=$!; pids+=("$pid")
  # ffmpeg has written some of the video (to its temporary) once it is non-empty
  for _ in $(seq 1 1200); do [ -n "$(find "$T" -name 'spin.mp4.tmp*' -o -name '*.tmp*spin.mp4' -size +0)" ] && break; sleep 0.05; done
  sleep 0.3
  kill -TERM "$pid"
  wait "$pid"; rc=$?
  [ "$rc" -eq 143 ] || fail "render to mp4 after SIGTERM exited $rc (expected 143): $(tail -c 300 "$T/err")"
  done_frames=$(sed -n 's/.*interrupted (SIGTERM) after \([0-9]*\) of 100000.*/\1/p' "$T/err")
  [ -n "$done_frames" ] || fail "no 'interrupted (SIGTERM) after N' in: $(tail -c 300 "$T/err")"
  frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
             -of default=nw=1:nk=1 "$T/spin.mp4")
  [ "$frames" = "$done_frames" ] || fail "video holds $frames frames, message says $done_frames"
  no_temporaries
fi

# 3. settle caught mid-computation: nothing written, the older output kept.
"$SPN" export scene:orb:10x16 -o "$T/web.json" || fail "export failed"
echo '{"older": "output"}' >"$T/settled.json"
"$SPN" settle "$T/web.json" -o "$T/settled.json" --dt 1e-6 --max-time 1e7 --tol 0 --max-kinetic 0 2>"$T/err" &
pid=$!; pids+=("$pid")
sleep 0.5
kill -TERM "$pid"
wait "$pid"; rc=$?
[ "$rc" -eq 143 ] || fail "settle after SIGTERM exited $rc (expected 143): $(cat "$T/err")"
grep -q 'settle: interrupted (SIGTERM)' "$T/err" || fail "settle's message: $(cat "$T/err")"
[ "$(cat "$T/settled.json")" = '{"older": "output"}' ] || fail "settle clobbered the older output"
no_temporaries
echo "signals: ok"

#!/usr/bin/env bash
# Soak: a long run of a 20,000-particle web (scene:orb:100x200, 20,001
# particles), watched as it goes. With `spinneret animate` (wind and prey):
# SOAK_DURATION simulated seconds (default 600, a 10-minute animation) in gusty
# air with two prey impacts, every frame's state saved, checked (no NaN, energy
# from `info --json`) and deleted; the RSS of the process sampled every 10 s.
# Without it: a chain of short implicit settles with a picture of each state.
# Prints JSON lines (samples) and a summary; fails on a NaN, a failed run,
# RSS growing past 1.2x its value after the first minute, or a non-finite or
# exploding energy. SOAK_SECONDS (default 600) bounds the wall time either way.
#   scripts/soak.sh BUILD_DIR
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR}" && pwd)
seconds=${SOAK_SECONDS:-600}
duration=${SOAK_DURATION:-600}
S=$build/spinneret
T=$(mktemp -d)
trap 'kill "${pid:-0}" 2>/dev/null; rm -rf "$T"' EXIT
"$S" export scene:orb:100x200 -o "$T/web.json" || exit 1
fail=0 start=$(date +%s) samples=0 rss_ref= max_rss=0 max_e=0 first_e=

check_state() { # file: no NaN, finite energy; records the largest total energy
  local f=$1 e
  if grep -qiwE 'nan|inf' "$f"; then echo "soak: $f holds a NaN"; fail=1; return; fi
  e=$("$S" info "$f" --json | sed -n 's/.*"total":[^0-9-]*\([-0-9.e+]*\).*/\1/p' | tail -1)
  first_e=${first_e:-$e}
  max_e=$(awk -v a="$max_e" -v b="${e:-nan}" 'BEGIN { if (b != b + 0) print "nan"; else print (b > a ? b : a) }')
}

sample() { # pid: RSS now, and the reference after the first minute
  local rss elapsed
  rss=$(awk '/VmRSS/ { print $2 }' "/proc/$1/status" 2>/dev/null) || return
  [ -n "$rss" ] || return
  elapsed=$(($(date +%s) - start))
  [ "$elapsed" -ge 60 ] && rss_ref=${rss_ref:-$rss}
  [ "$rss" -gt "$max_rss" ] && max_rss=$rss
  samples=$((samples + 1))
  printf '{"elapsed_s":%d,"rss_kb":%s,"states_checked":%d,"max_energy_j":%s}\n' "$elapsed" "$rss" "$checked" "$max_e"
}

checked=0
if "$S" animate --help >/dev/null 2>&1; then
  mode=animate
  mkdir -p "$T/states"
  "$S" animate "$T/web.json" -o "$T/frames" --duration "$duration" --fps 2 --size 320x320 --quiet --solver implicit --substeps 10 --solver-tol 1e-3 \
    --wind air --wind-speed 3 --gust 0.6 --turbulence 0.3 --save-states "$T/states" \
    --impact '0.01,0.02,-0.2;0,0,2;0.0002;0.004' --impact '-0.03,0.05,-0.4;0.1,-0.2,3;0.0005;0.006' \
    2>"$T/err" &
  pid=$!
  while kill -0 "$pid" 2>/dev/null && [ $(($(date +%s) - start)) -lt "$seconds" ]; do
    sleep 10
    sample "$pid"
    for f in $(ls "$T/states" 2>/dev/null | sort | head -n -1); do # the newest may be being written
      check_state "$T/states/$f"; rm -f "$T/states/$f" "$T/frames/frame_${f#state_}"; checked=$((checked + 1))
      rm -f "$T/frames/"*.png
    done
  done
  if kill -0 "$pid" 2>/dev/null; then kill -INT "$pid"; wait "$pid"; else wait "$pid" || { echo "soak: animate failed: $(tail -3 "$T/err")"; fail=1; }; fi
  for f in $(ls "$T/states" 2>/dev/null); do check_state "$T/states/$f"; checked=$((checked + 1)); done
else
  mode=settle
  while [ $(($(date +%s) - start)) -lt "$seconds" ]; do
    "$S" settle "$T/web.json" -o "$T/next.json" --solver implicit --dt 2e-3 --max-time 0.01 --tol 0 \
      --max-kinetic 0 2>"$T/err" & pid=$!
    while kill -0 "$pid" 2>/dev/null; do sleep 2; sample "$pid"; done
    wait "$pid" || { echo "soak: settle failed: $(tail -3 "$T/err")"; fail=1; break; }
    "$S" render "$T/next.json" -o "$T/frame.svg" --size 400x400 --colour-by tension 2>>"$T/err" || { fail=1; break; }
    grep -qiwE 'nan|inf' "$T/frame.svg" && { echo "soak: picture holds a NaN"; fail=1; break; }
    mv "$T/next.json" "$T/web.json"; check_state "$T/web.json"; checked=$((checked + 1))
  done
fi
rss_ref=${rss_ref:-$max_rss}
awk -v a="$rss_ref" -v b="$max_rss" 'BEGIN { exit !(b <= 1.2 * a) }' || { echo "soak: RSS grew from $rss_ref to $max_rss kB"; fail=1; }
awk -v e="$max_e" 'BEGIN { exit !(e == e + 0 && e < 1e3) }' || { echo "soak: energy not bounded: $max_e J"; fail=1; }
# frame 0 is the start: a soak that simulated nothing has not soaked
[ "$checked" -gt 1 ] || [ "$mode" = settle ] || { echo "soak: no simulated frame finished"; fail=1; }
[ "$checked" -gt 0 ] || { echo "soak: no state was checked"; fail=1; }
printf '{"soak":"%s","seconds":%d,"simulated_s":%s,"states_checked":%d,"rss_after_1min_kb":%s,"max_rss_kb":%s,"first_energy_j":%s,"max_energy_j":%s,"ok":%s}\n' \
  "$mode" $(($(date +%s) - start)) "$(awk -v n="$checked" 'BEGIN { print (n > 1 ? (n - 1) / 2 : 0) }')" "$checked" "${rss_ref:-0}" "$max_rss" "${first_e:-0}" "$max_e" \
  "$([ $fail -eq 0 ] && echo true || echo false)"
exit $fail

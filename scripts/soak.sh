#!/usr/bin/env bash
# Soak: a long run of a 20,000-particle web (scene:orb:100x200, 20,001
# particles), watched as it goes. With `spinneret animate` (wind and prey):
# SOAK_DURATION simulated seconds (default 600, a 10-minute animation) in gusty
# air (3 m/s, gust 0.6, turbulence 0.3) on the implicit solver at steps of
# 0.1 s (1 frame a second, 10 substeps, CG tolerance 1e-3), with two prey
# of 0.05 g that strike at once and bounce off: 0.5 m/s downwind into the
# billowing web from 16 and 26 mm upwind, 6 cm from the hub, with the glue
# at its weakest (`--glue 0 --glue-outline 1`: no droplet minimum, only the
# thread inside the body sticks), so both leave it; a prey held on the web
# costs ~100x the wind (docs/wind-and-prey.md);
# every frame's state saved, checked (no NaN; kinetic + elastic energy from
# `info --json`: prey fly without gravity, so their height is no energy) and
# deleted; the RSS of the process sampled every 10 s.
# Without `animate`: a chain of short implicit settles with a picture of each.
# Prints JSON lines (samples) and a summary; fails on a NaN, a failed run, no
# simulated frame, RSS growing past 1.2x its value after the first minute, or
# an energy that is not finite or exceeds twice the first frame's: the first
# frame holds the web's prestrain and the prey's launch energy, the most the
# prey can bring; the wind's work stored in the billowing web is a few
# percent of it, and an unstable step grows without bound. SOAK_SECONDS (default 600) bounds the
# wall time either way; the summary says how far the run got. One thread
# (SOAK_THREADS, default 1): on a shared machine OpenMP's spinning threads
# burnt 7x the CPU of one thread for the same frames (the bits do not
# depend on the thread count).
#   scripts/soak.sh BUILD_DIR
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR}" && pwd)
seconds=${SOAK_SECONDS:-600}
duration=${SOAK_DURATION:-600}
S=$build/spinneret
T=$(mktemp -d)
trap 'kill "${pid:-0}" 2>/dev/null; rm -rf "$T"' EXIT
export OMP_NUM_THREADS=${SOAK_THREADS:-1}
"$S" export scene:orb:100x200 -o "$T/web.json" || exit 1
ticks=$(getconf CLK_TCK) cpu=0
fail=0 start=$(date +%s) samples=0 rss_ref= max_rss=0 max_e=0 first_e= min_e= rss_first= rss_last=0

check_state() { # file: no NaN, finite energy; records the largest total energy
  local f=$1 e
  if grep -qiwE 'nan|inf' "$f"; then echo "soak: $f holds a NaN"; fail=1; return; fi
  e=$("$S" info "$f" --json | awk -F: '/"(kinetic|elastic)"/ { gsub(/[ \t,]/, "", $2); e += $2; n++ } END { if (n == 2) printf "%.9g", e }')
  first_e=${first_e:-$e}
  min_e=$(awk -v a="${min_e:-$e}" -v b="${e:-nan}" 'BEGIN { if (b != b + 0) print "nan"; else print (b < a ? b : a) }')
  max_e=$(awk -v a="$max_e" -v b="${e:-nan}" 'BEGIN { if (b != b + 0) print "nan"; else print (b > a ? b : a) }')
}

sample() { # pid: RSS now, and the reference after the first minute
  local rss elapsed
  rss=$(awk '/VmRSS/ { print $2 }' "/proc/$1/status" 2>/dev/null) || return
  [ -n "$rss" ] || return
  elapsed=$(($(date +%s) - start))
  [ "$elapsed" -ge 60 ] && rss_ref=${rss_ref:-$rss}
  [ "$rss" -gt "$max_rss" ] && max_rss=$rss
  rss_first=${rss_first:-$rss} rss_last=$rss
  cpu=$(awk -v t="$ticks" '{ print ($14 + $15) / t }' "/proc/$1/stat" 2>/dev/null || echo "${cpu:-0}")
  samples=$((samples + 1))
  printf '{"elapsed_s":%d,"cpu_s":%s,"rss_kb":%s,"states_checked":%d,"max_energy_j":%s}\n' "$elapsed" "$cpu" "$rss" "$checked" "$max_e"
}

checked=0
if "$S" animate --help >/dev/null 2>&1; then
  mode=animate
  mkdir -p "$T/states"
  "$S" animate "$T/web.json" -o "$T/frames" --duration "$duration" --fps 1 --size 320x320 --quiet --solver implicit --substeps 10 --solver-tol 1e-3 \
    --wind air --wind-speed 3 --gust 0.6 --turbulence 0.3 --save-states "$T/states" --glue 0 --glue-outline 1 \
    --impact '-0.03,0.05,0.02;0,0,-0.5;0.00005;0.004' --impact '0.03,0.05,0.03;0,0,-0.5;0.00005;0.004' \
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
awk -v e="$max_e" -v f="${first_e:-0}" 'BEGIN { exit !(e == e + 0 && e <= 2 * f) }' || { echo "soak: energy not bounded: $max_e J, more than twice the first frame's ${first_e:-?} J"; fail=1; }
# frame 0 is the start: a soak that simulated nothing has not soaked
[ "$checked" -gt 1 ] || [ "$mode" = settle ] || { echo "soak: no simulated frame finished"; fail=1; }
[ "$checked" -gt 0 ] || { echo "soak: no state was checked"; fail=1; }
printf '{"soak":"%s","seconds":%d,"simulated_s":%s,"states_checked":%d,"rss_first_kb":%s,"rss_after_1min_kb":%s,"rss_last_kb":%s,"max_rss_kb":%s,"first_energy_j":%s,"min_energy_j":%s,"max_energy_j":%s,"cpu_s":%s,"ok":%s}\n' \
  "$mode" $(($(date +%s) - start)) "$(awk -v n="$checked" 'BEGIN { print (n > 1 ? n - 1 : 0) }')" "$checked" "${rss_first:-0}" "${rss_ref:-0}" "$rss_last" "$max_rss" "${first_e:-0}" "${min_e:-0}" "$max_e" "${cpu:-0}" \
  "$([ $fail -eq 0 ] && echo true || echo false)"
exit $fail

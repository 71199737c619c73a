#!/usr/bin/env bash
# Soak: a long run of a 20,000-particle web, checked as it goes. Until
# `spinneret animate` (wind and prey) is in main, the run is a chain of
# settle steps (each continues from the last state, implicit solver) with a
# picture of every state: memory must stay flat (peak RSS per step), the
# energy bounded, and no output may hold a NaN. One JSON line per step, a
# summary at the end; fails on NaN, a failed step, energy growth or RSS growth.
#   scripts/soak.sh BUILD_DIR   (SOAK_SECONDS, default 600)
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR}" && pwd)
seconds=${SOAK_SECONDS:-600}
S=$build/spinneret
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$S" export scene:orb:100x200 -o "$T/web.json" || exit 1 # 20,001 particles
start=$(date +%s) step=0 fail=0 first_rss= max_rss=0 first_e= max_e=
while [ $(($(date +%s) - start)) -lt "$seconds" ]; do
  step=$((step + 1))
  /usr/bin/time -f '%M' -o "$T/rss" "$S" settle "$T/web.json" -o "$T/next.json" --solver implicit --dt 2e-3 \
    --max-time 0.01 --tol 0 --max-kinetic 0 2>"$T/err" || { echo "soak: step $step failed: $(tail -3 "$T/err")"; fail=1; break; }
  rss=$(tail -1 "$T/rss")
  energy=$(sed -n 's/.*final energy .* \([-0-9.e+]*\) J$/\1/p' "$T/err")
  "$S" render "$T/next.json" -o "$T/frame.svg" --size 400x400 --colour-by tension 2>>"$T/err" || { echo "soak: render failed"; fail=1; break; }
  if grep -qiwE 'nan|inf' "$T/next.json" "$T/frame.svg"; then echo "soak: step $step wrote a NaN"; fail=1; break; fi
  mv "$T/next.json" "$T/web.json"
  first_rss=${first_rss:-$rss}; first_e=${first_e:-$energy}
  [ "$rss" -gt "$max_rss" ] && max_rss=$rss
  max_e=$(awk -v a="${max_e:-$energy}" -v b="$energy" 'BEGIN { print (b > a ? b : a) }')
  printf '{"step":%d,"elapsed_s":%d,"peak_rss_kb":%s,"energy_j":%s}\n' "$step" $(($(date +%s) - start)) "$rss" "$energy"
done
# Flat memory: no step above 1.2x the first; bounded energy: never above the
# start by more than its own size (a settling web only loses energy).
awk -v a="$first_rss" -v b="$max_rss" 'BEGIN { exit !(b <= 1.2 * a) }' || { echo "soak: RSS grew from $first_rss to $max_rss kB"; fail=1; }
awk -v a="$first_e" -v b="$max_e" 'BEGIN { exit !(b <= a + (a < 0 ? -a : a) + 1e-12) }' || { echo "soak: energy grew from $first_e to $max_e J"; fail=1; }
printf '{"soak":"settle+render","steps":%d,"seconds":%d,"first_rss_kb":%s,"max_rss_kb":%s,"first_energy_j":%s,"max_energy_j":%s,"ok":%s}\n' \
  "$step" $(($(date +%s) - start)) "${first_rss:-0}" "$max_rss" "${first_e:-0}" "${max_e:-0}" "$([ $fail -eq 0 ] && echo true || echo false)"
exit $fail

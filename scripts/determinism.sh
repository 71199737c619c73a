#!/usr/bin/env bash
# Same command, same bytes: runs a set of commands with every build given
# (e.g. build build-asan) and with 1 and 2 OpenMP threads, and compares the
# web files (and other text outputs) they write. One JSON line per command;
# fails if any output differs. Used by `make determinism`; results and what
# may differ across compilers are in docs/determinism.md.
#   scripts/determinism.sh BUILD_DIR... (each holding a built `spinneret`)
set -u
[ $# -ge 1 ] || { echo "usage: $0 BUILD_DIR..." >&2; exit 2; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
first=$1/spinneret
# A web above the parallel threshold (32768 particles), so 2 threads really split the loops.
"$first" export scene:orb:200x200 -o "$T/big.json" || exit 1
"$first" export scene:orb:12x16 -o "$T/small.json" || exit 1
# A species web, whose implicit steps in wind, and struck by a prey, take the sparse factor
# (docs/physics-implicit-mg.md).
"$first" build --species araneus -o "$T/araneus.json" || exit 1
DATA=$(cd "$(dirname "$0")/.." && pwd)/tests/data

commands=(
  "settle $T/big.json -o OUT.json --solver symplectic --dt 1e-6 --max-time 1e-5"
  "settle $T/big.json -o OUT.json --solver rk4 --dt 1e-6 --max-time 1e-5"
  "settle $T/big.json -o OUT.json --solver implicit --dt 1e-4 --max-time 2e-4"
  "settle $T/big.json -o OUT.json --method equilibrium --load 0,0,1e-7"
  "settle $T/big.json -o OUT.json --method equilibrium --load 0,0,1e-7 --preconditioner multigrid"
  "settle $T/small.json -o OUT.json --solver adaptive --dt 1e-4 --max-time 0.01"
  "settle $T/small.json -o OUT.json --solver implicit --dt 1e-3 --max-time 0.2"
  "build --species araneus --seed 3 --settle --settle-time 0.5 -o OUT.json"
  "build --species zygiella --size 0.05 --settle -o OUT.json"
  "build --species zilla --seed 7 --settle -o OUT.json"
  "shoot --from 0,1.5,0 --to 3,3,0 -o OUT.json --max-time 1"
  "drop $DATA/hostile/tetra.obj -o OUT --max-time 0.3"
  "export $T/small.json -o OUT.obj --tubes 0.001 --dew"
  "animate $T/small.json -o OUTf --save-states OUT --wind air --wind-speed 3 --duration 0.2 --fps 10 --size 48x48 --quiet"
  "animate $T/small.json -o OUTf --save-states OUT --wind air --wind-speed 3 --duration 0.2 --fps 10 --size 48x48 --quiet --solver implicit"
  "animate $T/big.json -o OUTf --save-states OUT --wind air --wind-speed 3 --duration 0.02 --fps 100 --substeps 4 --size 48x48 --quiet --solver implicit"
  "animate $T/araneus.json -o OUTf --save-states OUT --wind air --duration 0.04 --fps 50 --size 48x48 --quiet --solver implicit"
  "animate $T/araneus.json -o OUTf --save-states OUT --duration 0.04 --fps 100 --size 48x48 --quiet --solver implicit --impact 0.03,0.02,0.01;0,0,-1;0.0002;0.006"
)

differ=0
for line in "${commands[@]}"; do
  sums=()
  for b in "$@"; do
    for threads in 1 2; do
      out=$T/out-$(basename "$b")-$threads
      rm -rf "$out" "$out".*
      args=()
      for w in $line; do case $w in OUT*) args+=("$out${w#OUT}") ;; *) args+=("$w") ;; esac; done
      OMP_NUM_THREADS=$threads "$b/spinneret" "${args[@]}" >/dev/null 2>"$T/err" ||
        { echo "determinism: '$line' failed with $b, $threads threads: $(tail -c 300 "$T/err")" >&2; differ=1; continue; }
      target=$(ls -d "$out"* | head -1)
      if [ -d "$target" ]; then sum=$(cd "$target" && cat $(ls) | sha256sum | cut -c1-16)
      else sum=$(sha256sum <"$target" | cut -c1-16); fi
      sums+=("$(basename "$b"):$threads=$sum")
    done
  done
  distinct=$(printf '%s\n' "${sums[@]}" | sed 's/.*=//' | sort -u | wc -l)
  [ "$distinct" -eq 1 ] || differ=1
  printf '{"command":"%s","runs":"%s","identical":%s}\n' "${line//$T\//}" "${sums[*]}" \
    "$([ "$distinct" -eq 1 ] && echo true || echo false)"
done
exit $differ

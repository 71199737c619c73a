#!/usr/bin/env bash
# Runs every benchmark program (build/bench_*), collects their JSON lines into
# bench/results/<machine>.json and prints them.
set -euo pipefail # a benchmark that fails fails the run, and leaves no results file
build=$1
# The machine is the host's name and its processor's family and model: a
# guest keeps its name when the host moves it to other hardware (this one's
# "vm" ran on Zen 4 with AVX-512, then on Zen 3 without), and figures from
# two processors must not overwrite each other. The vector extension the
# kernels' clones pick (AVX-512 or AVX2) is recorded beside it.
# (a field the processor does not have, ARM's "cpu family" say, is empty,
# not the end of the run under set -e)
cpuinfo() { { grep -m1 "^$1[[:space:]]*:" /proc/cpuinfo 2>/dev/null || true; } | cut -d: -f2 | sed 's/^ *//'; }
host=$(hostname -s 2>/dev/null || echo machine)
cpu=$(cpuinfo 'model name')
family=$(cpuinfo 'cpu family')
model=$(cpuinfo model)
flags=" $(cpuinfo flags) "
case "$flags" in
  *" avx512f "*) isa=avx512 ;;
  *" avx2 "*) isa=avx2 ;;
  *) isa=baseline ;;
esac
machine=$host${family:+-f$family}${model:+m$model}
mkdir -p bench/results
tmp=$(mktemp bench/results/.tmp.XXXXXX)
trap 'rm -f "$tmp"' EXIT
printf '{"machine":"%s","cpu":"%s","cpu_family":"%s","cpu_model":"%s","isa":"%s","cores":%s,"date":"%s"}\n' \
  "$machine" "${cpu:-unknown}" "$family" "$model" "$isa" "$(nproc)" "$(date -u +%F)" >"$tmp"
# Every figure from this one run: the programs that keep their large webs
# (1M particles, minutes) behind a flag get it here.
args_for() {
  case "$(basename "$1")" in
    bench_equilibrium | bench_mg_rates) echo --full ;;
  esac
}
for b in "$build"/bench_*; do
  [ -x "$b" ] || continue
  echo "== $b $(args_for "$b")" >&2
  # shellcheck disable=SC2046 # the flags split on purpose
  "$b" $(args_for "$b") | tee -a "$tmp"
done
mv "$tmp" "bench/results/$machine.json"
echo "written bench/results/$machine.json" >&2
# The README's speed tables come from this file (between its bench-table markers).
scripts/bench-table.py "bench/results/$machine.json" --readme README.md && echo "updated README.md" >&2

#!/usr/bin/env bash
# Runs every benchmark program (build/bench_*), collects their JSON lines into
# bench/results/<machine>.json and prints them.
set -euo pipefail # a benchmark that fails fails the run, and leaves no results file
build=$1
machine=$(hostname -s 2>/dev/null || echo machine)
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//' || echo unknown)
mkdir -p bench/results
tmp=$(mktemp bench/results/.tmp.XXXXXX)
trap 'rm -f "$tmp"' EXIT
printf '{"machine":"%s","cpu":"%s","cores":%s,"date":"%s"}\n' "$machine" "$cpu" "$(nproc)" "$(date -u +%F)" >"$tmp"
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

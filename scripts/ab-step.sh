#!/usr/bin/env bash
# Old against new on a shared machine: bench_step from two sides, run in
# turn N times, each figure's minimum and median per side.
#
#   scripts/ab-step.sh [-n N] SIDE_A SIDE_B [bench_step args...]
#   scripts/ab-step.sh HEAD~1 HEAD --size 1M --integrator rk4
#   scripts/ab-step.sh -n 8 HEAD,SPN_RK4_AVX2=0 HEAD,SPN_RK4_AVX2=1 --size 1M --integrator rk4
#
# A side is a git revision, built (Release, bench_step only) in a worktree
# under $TMPDIR and removed at the end, or "." for the working tree as it
# is (built in build-ab/); ",VAR=value" after it sets its environment. The
# sides alternate (A B A B ...), so a host that drifts slows both alike;
# the minimum is the figure least touched by neighbours, the median says
# how far to trust it. Prints one table row per bench_step line: CPU ns a
# spring-step (wall in parentheses), A then B, and B / A of the minima.
# Figures from this script are comparisons, not the README's: those come
# from one `make bench` run.
set -euo pipefail
runs=6
if [ "${1:-}" = "-n" ]; then
  runs=$2
  shift 2
fi
if [ $# -lt 2 ] || ! [[ $runs =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: scripts/ab-step.sh [-n N] SIDE_A SIDE_B [bench_step args...]" >&2
  exit 2
fi
side_a=$1 side_b=$2
shift 2
root=$(git rev-parse --show-toplevel)
work=$(mktemp -d "${TMPDIR:-/tmp}/spn-ab.XXXXXX")
cleanup() {
  for d in "$work"/tree-*; do
    [ -d "$d" ] && git -C "$root" worktree remove --force "$d" >/dev/null 2>&1
  done
  rm -rf "$work"
}
trap cleanup EXIT

# build SIDE NAME: the bench_step binary of SIDE's revision, path on stdout
build() {
  local rev=${1%%,*} name=$2 src dir
  if [ "$rev" = "." ]; then
    src=$root dir=$root/build-ab
  else
    src=$work/tree-$name dir=$work/build-$name
    git -C "$root" worktree add --detach "$src" "$rev" >/dev/null 2>&1 ||
      { echo "ab-step: '$rev' is not a revision of this repository" >&2; exit 2; }
  fi
  cmake -S "$src" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DSPN_VIEWER=OFF -DSPN_TESTS=OFF >/dev/null
  cmake --build "$dir" -j "$(nproc)" --target bench_step >/dev/null
  echo "$dir/bench_step"
}

# env_of SIDE: its VAR=value settings, one a line
env_of() {
  case $1 in *,*) tr ',' '\n' <<<"${1#*,}" ;; esac
}

echo "building $side_a and $side_b ..." >&2
bin_a=$(build "$side_a" a)
bin_b=$(build "$side_b" b)
for i in $(seq "$runs"); do
  for s in a b; do
    if [ $s = a ]; then side=$side_a bin=$bin_a; else side=$side_b bin=$bin_b; fi
    mapfile -t vars < <(env_of "$side")
    env ${vars[@]+"${vars[@]}"} "$bin" "$@" | sed "s/^/$s /" >>"$work/lines"
  done
  echo "round $i of $runs" >&2
done
python3 - "$work/lines" "$side_a" "$side_b" <<'EOF'
import json, statistics, sys
path, side_a, side_b = sys.argv[1:4]
rows = {}
for line in open(path):
    side, _, text = line.partition(" ")
    r = json.loads(text)
    key = (r["integrator"], r["particles"], r["threads"], r.get("path", ""), r.get("precision", ""))
    rows.setdefault(key, {"a": [], "b": []})[side].append((r["cpu_ns_per_spring_step"], r["ns_per_spring_step"]))

def fig(v):
    cpu, wall = [x[0] for x in v], [x[1] for x in v]
    return "%.2f (%.2f) / %.2f (%.2f)" % (min(cpu), min(wall), statistics.median(cpu), statistics.median(wall))

print("A = %s, B = %s; CPU ns a spring-step (wall), minimum / median of %d runs"
      % (side_a, side_b, max(len(v["a"]) for v in rows.values())))
print("| integrator | particles | threads | path | precision | A | B | B / A (min CPU) |")
print("|---|---:|---:|---|---|---:|---:|---:|")
for key, v in rows.items():
    if not v["a"] or not v["b"]:
        continue
    ratio = min(x[0] for x in v["b"]) / min(x[0] for x in v["a"])
    print("| %s | %d | %d | %s | %s | %s | %s | %.3f |" % (*key, fig(v["a"]), fig(v["b"]), ratio))
EOF

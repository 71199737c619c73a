#!/usr/bin/env bash
# Threads do not change results: settle a web above the parallel threshold
# (32768 particles, so 2 threads really split the loops) with 1 and 2 OpenMP
# threads; the written web files are byte-identical. (Across builds and
# solvers: scripts/determinism.sh, `make determinism`.)
. "$(dirname "$0")/lib/common.sh" "$@"
"$SPN" export scene:orb:190x180 -o "$T/web.json" || fail "export failed"
for solver in symplectic rk4; do
  for threads in 1 2; do
    OMP_NUM_THREADS=$threads "$SPN" settle "$T/web.json" -o "$T/$solver-$threads.json" --solver $solver \
      --dt 1e-6 --max-time 5e-6 2>"$T/err" || fail "$solver, $threads threads: $(cat "$T/err")"
  done
  cmp -s "$T/$solver-1.json" "$T/$solver-2.json" || fail "$solver: 1 and 2 threads wrote different web files"
  cmp -s "$T/web.json" "$T/$solver-1.json" && fail "$solver: the web did not move (the test would prove nothing)"
done
echo "determinism: ok"

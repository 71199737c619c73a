#!/usr/bin/env bash
# make bench's scripts on fake benchmark programs: scripts/bench.sh runs every
# build/bench_* (the equilibrium and rates programs with --full, so the 1M
# figures come from the same run), writes bench/results/<machine>.json and
# the README's generated tables; scripts/bench-table.py reads issue 10's
# targets off the run's own lines (the 1M equilibrium figure from the
# process's first solve, not the warm one; a target under the floor that
# bench_floor measures says so) and each lattice step's share of
# the triad on as many threads, with the cache a pass fits in (or where that
# is not known, as much as the machine gave: the L2 only). A failing
# program fails the run and leaves no results file and no scratch file
# behind. scripts/ab-step.sh refuses bad input (usage, a bad revision)
# before it builds anything, and leaves nothing behind.
. "$(dirname "$0")/lib/common.sh" "$@"
SRC=${SPN_SOURCE_DIR:?SPN_SOURCE_DIR must name the source tree}
# the results file is named for the host and its processor (family, model)
field() { awk -F: -v k="$1" '$1 ~ "^" k "[ \t]*$" { sub(/^ */, "", $2); print $2; exit }' /proc/cpuinfo 2>/dev/null; }
family=$(field "cpu family")
model=$(field model)
machine=$(hostname -s 2>/dev/null || echo machine)${family:+-f$family}${model:+m$model}

# A project folder with the scripts, a README with the markers and a build
# folder of fake programs (each prints JSON lines, as the real ones do).
project() {
    rm -rf "$T/p" && mkdir -p "$T/p/scripts" "$T/p/b"
    cp "$SRC/scripts/bench.sh" "$SRC/scripts/bench-table.py" "$T/p/scripts/"
    printf 'intro\n<!-- bench-table:begin -->\nold\n<!-- bench-table:end -->\nafter\n' >"$T/p/README.md"
    cat >"$T/p/b/bench_bandwidth" <<'EOF'
#!/bin/sh
echo '{"bench":"caches","l2_kib_per_core":1024,"l3_kib":32768}'
echo '{"bench":"bandwidth","kernel":"triad","threads":1,"gb_per_s":20.0}'
echo '{"bench":"bandwidth","kernel":"triad","threads":2,"gb_per_s":40.0}'
EOF
    cat >"$T/p/b/bench_equilibrium" <<'EOF'
#!/bin/sh
echo "$*" >"$(dirname "$0")/equilibrium.args"
echo '{"bench":"equilibrium","scene":"orb-1M","precond":"cyclic","threads":2,"tolerance":1e-06,"seconds":6.0,"cold":true}'
echo '{"bench":"equilibrium","scene":"orb-1M","precond":"cyclic","threads":2,"tolerance":1e-06,"seconds":4.0,"cold":false}'
echo '{"bench":"equilibrium","scene":"orb-1M","precond":"multigrid","threads":2,"tolerance":1e-06,"seconds":9.5,"cold":false}'
EOF
    cat >"$T/p/b/bench_mg_rates" <<'EOF'
#!/bin/sh
echo "$*" >"$(dirname "$0")/rates.args"
EOF
    cat >"$T/p/b/bench_floor" <<'EOF'
#!/bin/sh
echo '{"bench":"floor","kernel":"spring_step","integrator":"symplectic","ns_per_spring_step":0.9}'
echo '{"bench":"floor","kernel":"spring_step","integrator":"rk4","ns_per_spring_step":5.5}'
EOF
    cat >"$T/p/b/bench_step" <<'EOF'
#!/bin/sh
echo '{"bench":"step","integrator":"rk4","particles":5001,"threads":1,"path":"lattice","precision":"float64","ns_per_spring_step":20.0}'
echo '{"bench":"step","integrator":"symplectic","particles":5001,"threads":1,"path":"lattice","precision":"float64","ns_per_spring_step":1.0,"model_bytes_per_spring_step":80.0,"model_gb_per_s":10.0,"pass_mib":0.8}'
echo '{"bench":"step","integrator":"symplectic","particles":1000001,"threads":2,"path":"lattice","precision":"float64","ns_per_spring_step":4.0,"model_bytes_per_spring_step":20.0,"model_gb_per_s":10.0,"pass_mib":150.0}'
EOF
    chmod +x "$T/p/b/"bench_*
}

project
# another machine's earlier run, whose targets are set beside this run's
mkdir -p "$T/p/bench/results"
cat >"$T/p/bench/results/other-f1m2.json" <<'EOF'
{"machine":"other-f1m2","isa":"avx512","date":"2026-01-01"}
{"bench":"step","integrator":"symplectic","particles":5001,"threads":1,"path":"lattice","precision":"float64","ns_per_spring_step":2.5}
EOF
(cd "$T/p" && scripts/bench.sh b >"$T/out" 2>"$T/err") || fail "bench.sh exited $?: $(cat "$T/err")"
res="$T/p/bench/results/$machine.json"
[ -f "$res" ] || fail "no results file $res"
[ "$(cat "$T/p/b/equilibrium.args")" = "--full" ] || fail "bench_equilibrium not run with --full"
[ "$(cat "$T/p/b/rates.args")" = "--full" ] || fail "bench_mg_rates not run with --full"
[ "$(grep -c '"bench"' "$res")" -eq 11 ] || fail "results should hold the eleven lines: $(cat "$res")"
head -1 "$res" | grep -q "\"machine\":\"$machine\"" || fail "results should start with the machine: $(head -1 "$res")"
head -1 "$res" | grep -Eq '"isa":"(avx512|avx2|baseline)"' || fail "the machine line should name the vector extension"
grep -q "^Measured by .make bench. on .$machine.: .*cores" "$T/p/README.md" || fail "README should name the machine: $(cat "$T/p/README.md")"
ls -a "$T/p/bench/results" | grep -q '^\.tmp' && fail "scratch file left behind"
python3 - "$T/p/README.md" <<'PY' || fail "README tables: $(cat "$T/p/README.md")"
import re, sys
doc = open(sys.argv[1]).read()
assert doc.startswith("intro\n") and doc.endswith("after\n") and "old" not in doc.splitlines()
def row(prefix):  # in the run's own targets table, the first (the machines' table repeats the figures)
    rows = [l for l in doc.splitlines() if l.startswith("| " + prefix)]
    assert len(rows) in (1, 2), (prefix, rows)
    return [c.strip() for c in rows[0].strip("|").split("|")]
r = row("explicit (symplectic) step, 5k")
assert r[1] == "≤ 1.2" and r[2] == "1" and r[4] == "yes" and "floor (bench_floor) 0.9" in r[3], r
cross = [l for l in doc.splitlines() if l.startswith("| figure | target | `")]
assert len(cross) == 1 and "`other-f1m2` (AVX-512, 2026-01-01)" in cross[0], cross
rows = [l for l in doc.splitlines() if l.startswith("| explicit (symplectic) step, 5k")]
assert len(rows) == 2 and "2.5 (not met)" in rows[1] and "1 (met)" in rows[1], rows
r = row("RK4 step, 5k")   # a target under the machine's floor says so
assert r[2] == "20" and r[4] == "no, and the target is under this machine's floor", r
r = row("explicit step, 1M")
assert r[2] == "4" and r[4] == "no", r
r = row("static equilibrium, 1M")   # the cold cyclic solve; the warm one and the multigrid's beside it
assert r[2] == "6" and r[4] == "no" and "4" in r[3] and "multigrid" in r[3] and "9.5" in r[3], r
shares = [l for l in doc.splitlines() if l.startswith("| symplectic |") and l.endswith("% |")]
assert len(shares) == 2, shares
cells = [[c.strip() for c in l.strip("|").split("|")] for l in shares]
assert cells[0][5] == "L2" and cells[0][-1] == "50%", cells       # 0.8 MiB; 10 of 20 GB/s on one thread
assert cells[1][5] == "memory" and cells[1][-1] == "25%", cells   # 150 MiB; 10 of 40 on two
PY

# A machine that gives its L2 only (the Zen 5 guest: no sysfs cache
# directory, its L3 unknown) says where a pass is beyond the L2, not that
# it is in memory; one that gives neither decides nothing.
for sizes in '1024 0 L2 beyond L2' '0 0 ? ?'; do
    set -- $sizes
    project
    sed -i "s/\"l2_kib_per_core\":1024,\"l3_kib\":32768/\"l2_kib_per_core\":$1,\"l3_kib\":$2/" "$T/p/b/bench_bandwidth"
    (cd "$T/p" && scripts/bench.sh b >"$T/out" 2>"$T/err") || fail "bench.sh exited $?: $(cat "$T/err")"
    small=$(grep '^| symplectic | 5,001 |' "$T/p/README.md" | cut -d'|' -f7 | xargs)
    big=$(grep '^| symplectic | 1,000,001 |' "$T/p/README.md" | cut -d'|' -f7 | xargs)
    [ "$small" = "$3" ] && [ "$big" = "${*:4}" ] ||
        fail "caches $1 / $2 KiB: the passes fit in '$small' and '$big': $(grep '^| symplectic' "$T/p/README.md")"
done

# A program that fails: the run fails, the last results and the README stay.
project
mkdir -p "$T/p/bench/results" && echo keep >"$T/p/bench/results/$machine.json"
printf '#!/bin/sh\necho "{\\"bench\\":\\"x\\"}"\nexit 3\n' >"$T/p/b/bench_zz_broken" && chmod +x "$T/p/b/bench_zz_broken"
(cd "$T/p" && scripts/bench.sh b >"$T/out" 2>"$T/err") && fail "a failing benchmark should fail the run"
[ "$(cat "$T/p/bench/results/$machine.json")" = keep ] || fail "the last results were replaced"
grep -q '^old$' "$T/p/README.md" || fail "the README was rewritten after a failed run"
ls -a "$T/p/bench/results" | grep -q '^\.tmp' && fail "scratch file left behind after a failure"

# scripts/ab-step.sh refuses bad input before building anything: a usage
# line and exit 2 for a missing side or a bad run count; a side that is not
# a revision is named, and no worktree or scratch folder is left behind.
AB=$SRC/scripts/ab-step.sh
"$AB" HEAD >"$T/out" 2>"$T/err" && fail "ab-step with one side should fail"
[ $? -eq 2 ] || fail "ab-step with one side: exit 2 expected"
grep -q '^usage: scripts/ab-step.sh' "$T/err" || fail "ab-step should print its usage: $(cat "$T/err")"
"$AB" -n 0 HEAD HEAD >"$T/out" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q '^usage:' "$T/err" || fail "ab-step -n 0: exit 2 and usage expected (exit $rc)"
if git -C "$SRC" rev-parse --git-dir >/dev/null 2>&1; then
    before=$(git -C "$SRC" worktree list | wc -l)
    mkdir -p "$T/tmp"
    (cd "$SRC" && TMPDIR="$T/tmp" "$AB" no-such-revision HEAD >"$T/out" 2>"$T/err"); rc=$?
    [ $rc -eq 2 ] || fail "ab-step with a bad revision: exit 2 expected, not $rc"
    grep -q "'no-such-revision' is not a revision" "$T/err" || fail "ab-step should name the bad side: $(cat "$T/err")"
    [ "$(git -C "$SRC" worktree list | wc -l)" -eq "$before" ] || fail "ab-step left a worktree behind"
    [ -z "$(ls -A "$T/tmp")" ] || fail "ab-step left scratch behind: $(ls -A "$T/tmp")"
fi
exit 0

#!/usr/bin/env bash
# spinneret info: the numbers of a hand-made chain (tests/data/io/chain4.json)
# against values worked out by hand, the --json output, and bad invocations.
. "$(dirname "$0")/lib/common.sh" "$@"
WEB=$DATA/io/chain4.json

"$SPN" info "$WEB" >"$T/out" 2>"$T/err" || fail "info exited $?: $(cat "$T/err")"
for line in 'particles: 4' 'springs: 3' 'fixed_particles: 2' 'broken_springs: 0' 'total_mass: 0.002 kg' \
            'anchor: 2' 'capture: 1' 'integrator: symplectic'; do
    grep -qF "$line" "$T/out" || fail "info text lacks '$line'"
done

"$SPN" info --json "$WEB" >"$T/info.json" || fail "info --json exited $?"
# By hand: springs 0 and 2 are 0.065 m long, under their 0.066 m rest length,
# so slack (tension-only); spring 1 is 0.07 m: elastic 1/2 * 20 * 0.004^2 J.
# Particle 1 feels 20 * 0.004 N along +x and its weight 0.001 * 9.81 N down.
python3 - "$T/info.json" <<'PY' || fail "info --json values"
import json, math, sys
d = json.load(open(sys.argv[1]))
def near(a, b, tol=1e-9): return abs(a - b) <= tol * max(1.0, abs(b))
assert d["particles"] == 4 and d["springs"] == 3, d
assert d["fixed_particles"] == 2 and d["broken_springs"] == 0, d
assert near(d["total_mass"], 0.002)
assert d["bounding_box"]["min"] == [-0.1, 0, 0] and d["bounding_box"]["max"] == [0.1, 0, 0]
assert near(d["energy"]["elastic"], 0.5 * 20 * 0.004 ** 2), d["energy"]
assert d["energy"]["kinetic"] == 0 and d["energy"]["gravitational"] == 0
assert near(d["max_residual"]["force"], math.hypot(20 * 0.004, 0.001 * 9.81)), d["max_residual"]
assert d["max_residual"]["particle"] in (1, 2)
assert d["springs_by_kind"] == {"anchor": 2, "capture": 1}, d["springs_by_kind"]
assert d["metadata"]["builder"] == "hand-written"
# Stable step: particles 1 and 2 (m 0.001) each hold two springs of k 20,
# kd 0.02, and drag is 2/s: omega^2 = 2 * 40 / m, c = 2 * 0.04 / m + 2,
# dt = 2 / (c/2 + sqrt(c^2/4 + omega^2)) = 6.11997e-3 s.
om2, c = 2 * 40 / 0.001, 2 * 0.04 / 0.001 + 2
assert near(d["world"]["stable_step"], 2 / (c / 2 + math.sqrt(c * c / 4 + om2))), d["world"]
PY
grep -qF 'stable_step: 0.00611997 s' "$T/out" || fail "info text lacks the stable step: $(grep stable "$T/out")"

"$SPN" info --help | grep -q 'usage: spinneret info' || fail "--help"

"$SPN" info "$T/nope.json" 2>"$T/err"; [ $? -eq 1 ] || fail "missing file should exit 1"
grep -q "nope.json: cannot open" "$T/err" || fail "missing file not named: $(cat "$T/err")"
"$SPN" info "$DATA/bad/spring_to_missing.json" 2>"$T/err"; [ $? -eq 1 ] || fail "bad file should exit 1"
grep -q 'springs.b\[1\]: particle 7 does not exist' "$T/err" || fail "bad file message: $(cat "$T/err")"
"$SPN" info 2>"$T/err"; [ $? -eq 2 ] || fail "no FILE should exit 2"
grep -q 'missing FILE' "$T/err" || fail "no FILE message"
"$SPN" info --frob "$WEB" 2>"$T/err"; [ $? -eq 2 ] || fail "unknown option should exit 2"
grep -q -- "--frob" "$T/err" || fail "unknown option not named"
"$SPN" info "$WEB" extra 2>"$T/err"; [ $? -eq 2 ] || fail "extra argument should exit 2"
echo "io_info ok"

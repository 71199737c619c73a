#!/usr/bin/env bash
# spinneret settle --method equilibrium: the hand-made chain solved directly
# is statically balanced (checked here from the written positions) and agrees
# with the dynamic settle; a load moves it; bad options exit 2 naming the
# option and write nothing.
. "$(dirname "$0")/lib/common.sh" "$@"
WEB=$DATA/io/chain4.json

"$SPN" settle "$WEB" -o "$T/static.json" --method equilibrium --rel-tol 1e-10 2>"$T/err" \
    || fail "equilibrium settle exited $?: $(cat "$T/err")"
grep -q 'static equilibrium after' "$T/err" || fail "report: $(cat "$T/err")"
"$SPN" settle "$WEB" -o "$T/dynamic.json" --tol 1e-9 2>/dev/null || fail "dynamic settle"
"$SPN" settle "$WEB" -o "$T/loaded.json" --method static --load 0,0,0.005 --tol 1e-12 2>"$T/err" \
    || fail "loaded settle exited $?: $(cat "$T/err")"

# Net force on each free particle from the written file: springs (tension
# only when stretched), weight, and the load.
python3 - "$T/static.json" "$T/dynamic.json" "$T/loaded.json" <<'PY' || fail "not in equilibrium"
import json, math, sys
def load(path):
    d = json.load(open(path))
    p = d["particles"]
    return d, [p["position"][3 * i:3 * i + 3] for i in range(p["count"])]
def net(d, x, extra):
    p, s = d["particles"], d["springs"]
    f = [[0.0, -9.81 * p["mass"][i], 0.0] for i in range(p["count"])]
    for i in range(p["count"]):
        for c in range(3): f[i][c] += extra[c]
    for j in range(s["count"]):
        a, b, k, r = s["a"][j], s["b"][j], s["k"][j], s["rest"][j]
        l = [x[a][c] - x[b][c] for c in range(3)]
        n = math.sqrt(sum(c * c for c in l))
        t = k * (n - r)
        if t < 0 and s["tension_only"][j]: continue
        for c in range(3):
            f[a][c] -= t * l[c] / n
            f[b][c] += t * l[c] / n
    return max(math.sqrt(sum(c * c for c in f[i])) for i in range(p["count"]) if not p["fixed"][i])
d, xs = load(sys.argv[1])
assert net(d, xs, [0, 0, 0]) < 1e-10, net(d, xs, [0, 0, 0])
_, xd = load(sys.argv[2])
assert max(abs(xs[i][c] - xd[i][c]) for i in range(4) for c in range(3)) < 1e-6, (xs, xd)
d, xl = load(sys.argv[3])
assert net(d, xl, [0, 0, 0.005]) < 1e-11, net(d, xl, [0, 0, 0.005])
assert xl[1][2] > 0.005 and abs(xl[1][2] - xl[2][2]) < 1e-9, xl
v = d["particles"]["velocity"]
assert all(c == 0 for c in v), v
PY

mkdir "$T/bad"
O=$T/bad/out.json
check_usage() {
    local name=$1; shift
    "$SPN" settle "$@" 2>"$T/err"; local rc=$?
    [ $rc -eq 2 ] || fail "settle $* exited $rc, expected 2"
    grep -q -- "$name" "$T/err" || fail "settle $*: message does not name $name: $(cat "$T/err")"
    [ -z "$(ls -A "$T/bad")" ] || fail "settle $* left a file"
}
check_usage --method "$WEB" -o "$O" --method newton
check_usage --rel-tol "$WEB" -o "$O" --method equilibrium --rel-tol 2
check_usage --rel-tol "$WEB" -o "$O" --method equilibrium --rel-tol -1e-3
check_usage --load "$WEB" -o "$O" --method equilibrium --load 1,2
check_usage --load "$WEB" -o "$O" --method equilibrium --load 0,nan,0
check_usage --preconditioner "$WEB" -o "$O" --method equilibrium --preconditioner cholesky
# The cyclic preconditioner: taken by auto on a rings x radials web, refused
# by name on one that is not (exit 1, nothing written).
"$SPN" export scene:orb:12x24 -o "$T/orb.json" 2>/dev/null || fail "export orb"
"$SPN" settle "$T/orb.json" -o "$T/orb-rest.json" --method equilibrium --load 0,0,1e-6 2>"$T/err" \
    || fail "orb settle exited $?: $(cat "$T/err")"
grep -q 'CG iterations, cyclic)' "$T/err" || fail "auto should take cyclic on the orb web: $(cat "$T/err")"
"$SPN" settle "$WEB" -o "$O" --method equilibrium --preconditioner cyclic 2>"$T/err"; rc=$?
[ $rc -eq 1 ] || fail "cyclic on a chain exited $rc, expected 1"
grep -q 'cyclic preconditioner needs a hub + rings x radials web' "$T/err" || fail "message: $(cat "$T/err")"
[ -z "$(ls -A "$T/bad")" ] || fail "cyclic on a chain left a file"
echo "equil_settle ok"

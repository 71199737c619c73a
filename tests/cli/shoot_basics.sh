#!/usr/bin/env bash
# spinneret shoot: JSON output checked against the path (the head reaches the
# target at the contact time, every frame has the strand), thwip-only ends at
# contact, a PNG-frame folder is written, and every bad input exits non-zero
# with a one-line message naming the option and leaves no output behind.
set -u
SPN=$1
fail() { echo "FAIL: $*"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$SPN" shoot --help | grep -q -- '--auto-speed' || fail "--help lists --auto-speed"
"$SPN" shoot --help | grep -q -- '--blend .*in \[0, 0.95\]' || fail "--help gives ranges"

"$SPN" shoot --from 0,1.5,0 --to 10,9,0 --speed 30 --points 24 -o "$tmp/a.json" 2> "$tmp/err" || fail "json run: $(cat "$tmp/err")"
python3 - "$tmp/a.json" <<'PY' || fail "json content"
import json, math, sys
d = json.load(open(sys.argv[1]))
assert d["format"] == "spinneret-shot" and d["points"] == 24
F = d["frames"]
phases = [f["phase"] for f in F]
for p in ("thwip", "thwap", "whoosh", "zipp", "done"):
    assert p in phases, p
# phases come in order
order = ["thwip", "thwap", "whoosh", "zipp", "done"]
assert [order.index(p) for p in phases] == sorted(order.index(p) for p in phases)
tc = d["contact_time"]
for f in F:
    if f["phase"] == "done":
        assert f["strand"] == []
        continue
    assert len(f["strand"]) == 24
    head = f["strand"][-1]
    if f["t"] >= tc:   # attached: the head is the target
        assert math.dist(head, d["target"]) < 1e-6, (f["t"], head)
    else:
        assert math.dist(head, d["target"]) > 1e-6
    assert f["strand"][0] == f["character"] or f["phase"] == "zipp"
print("json ok")
PY

"$SPN" shoot --from 0,0,0 --to 8,3,2 --phases thwip -o "$tmp/b.json" 2>/dev/null || fail "thwip run"
python3 -c "
import json,sys; d=json.load(open('$tmp/b.json')); ph=[f['phase'] for f in d['frames']]
assert set(ph) <= {'thwip','done'} and ph[-1]=='done', ph" || fail "--phases thwip ends at contact"

OMP_NUM_THREADS=2 "$SPN" shoot --from 0,0,0 --to 8,3,0 --phases thwip --size 64x48 --eye 4,2,12 --look-at 4,1.5,0 --quiet -o "$tmp/frames" 2>/dev/null || fail "frames run"
n=$(ls "$tmp/frames" | grep -c '^frame_.*\.png$')
[ "$n" -gt 5 ] || fail "expected PNG frames, got $n"
# Frames are drawn on as many threads as OpenMP would use (each thread its
# own strand and scenery worlds) and added in order: the same files on one.
OMP_NUM_THREADS=1 "$SPN" shoot --from 0,0,0 --to 8,3,0 --phases thwip --size 64x48 --eye 4,2,12 --look-at 4,1.5,0 \
    --quiet -o "$tmp/frames1" 2>/dev/null || fail "frames run on one thread"
diff -r "$tmp/frames" "$tmp/frames1" >/dev/null || fail "shoot frames differ between one thread and several"

# Unreachable: a clear error naming the speed needed; --auto-speed fixes it.
"$SPN" shoot --from 0,0,0 --to 100,0,0 --speed 10 -o "$tmp/c.json" 2> "$tmp/err"
[ $? -ne 0 ] || fail "unreachable target should fail"
grep -q "out of reach" "$tmp/err" || fail "unreachable message: $(cat "$tmp/err")"
[ ! -e "$tmp/c.json" ] || fail "no output on failure"
"$SPN" shoot --from 0,0,0 --to 100,0,0 --speed 10 --auto-speed --phases thwip -o "$tmp/c.json" 2>/dev/null \
  || fail "--auto-speed should reach"

bad() { # expected-text args...
  local want=$1; shift
  "$SPN" shoot "$@" 2> "$tmp/err"
  local rc=$?
  [ $rc -ne 0 ] || fail "'$*' should fail"
  grep -q -- "$want" "$tmp/err" || fail "'$*': expected '$want' in: $(cat "$tmp/err")"
  [ "$(grep -c . "$tmp/err")" -le 2 ] || fail "'$*': message should be short"
  [ ! -e "$tmp/bad.json" ] || fail "'$*' left an output"
}
bad "--from" --to 1,1,1 -o "$tmp/bad.json"
bad "--to" --from 1,1,1 -o "$tmp/bad.json"
bad "output" --from 0,0,0 --to 1,1,1
bad "--blend" --from 0,0,0 --to 5,1,0 --blend 2 -o "$tmp/bad.json"
bad "--points" --from 0,0,0 --to 5,1,0 --points 3 -o "$tmp/bad.json"
bad "--points" --from 0,0,0 --to 5,1,0 --points 10.5 -o "$tmp/bad.json"
bad "--phases" --from 0,0,0 --to 5,1,0 --phases most -o "$tmp/bad.json"
bad "--from" --from 0,nan,0 --to 5,1,0 -o "$tmp/bad.json"
bad "target" --from 1,1,1 --to 1,1,1 -o "$tmp/bad.json"
bad ".json, .mp4, .gif" --from 0,0,0 --to 5,1,0 -o "$tmp/bad.txt"
bad "--look-at" --from 0,0,0 --to 5,1,0 --eye 1,2,3 --look-at 1,2,3 -o "$tmp/bad.json"
bad "--eye" --from 0,0,0 --to 5,1,0 --eye 1,2 -o "$tmp/bad.json"
bad "unknown option" --from 0,0,0 --to 5,1,0 --frobnicate -o "$tmp/bad.json"
[ ! -e "$tmp/bad.txt" ] || fail "bad extension left an output"
"$SPN" shoot --from 0,0,0 --to 5,1,0 -o "$tmp/no/such/dir/x.json" 2>/dev/null
[ $? -eq 1 ] || fail "unwritable output should exit 1"
echo "shoot basics ok"

#!/usr/bin/env bash
# spinneret build: species and methods write web files that info reads back
# with web measures; the same seed gives the same file; bad anchors and
# out-of-range options fail with a message naming them and leave no file.
. "$(dirname "$0")/lib/common.sh" "$@"

"$SPN" build --species zygiella --seed 4 -o "$T/a.json" || fail "species build"
"$SPN" build --species zygiella --seed 4 -o "$T/b.json" || fail "species build again"
cmp -s "$T/a.json" "$T/b.json" || fail "same seed should give the same file"
"$SPN" build --species zygiella --seed 5 -o "$T/c.json" || fail "species build seed 5"
cmp -s "$T/a.json" "$T/c.json" && fail "another seed should give another web"
"$SPN" info --json "$T/a.json" | grep -q '"radii"' || fail "info --json should carry the web measures"
"$SPN" info "$T/a.json" | grep -q 'turns_below' || fail "info text should carry the web measures"

"$SPN" build --method geometric --anchors "0,0.5;-0.45,0.2;-0.4,-0.3;0.4,-0.3;0.45,0.2" --k 20 --m 0.4 \
    -o "$T/g.json" || fail "geometric build"
"$SPN" build --method physical --anchors "-0.2,0.2;0.2,0.2;0.2,-0.2;-0.2,-0.2" --move-outer 0.03 \
    --frame-placement 0.04 --frame-rest 0.035 -o "$T/p.json" || fail "physical build"
grep -q '"builder": *"physical"' "$T/p.json" || grep -q 'physical' "$T/p.json" || fail "metadata names the builder"

# A building animation: N frames, the web file without the auxiliary spiral.
OMP_NUM_THREADS=2 "$SPN" build --species araneus --seed 2 --frames "$T/frames" --frame-count 6 -o "$T/f.json" || fail "build --frames"
[ "$(ls "$T/frames" | grep -c '\.png$')" -eq 6 ] || fail "6 frames expected, got $(ls "$T/frames")"
OMP_NUM_THREADS=1 "$SPN" build --species araneus --seed 2 --frames "$T/frames1" --frame-count 6 -o "$T/f1.json" ||
    fail "build --frames on one thread"
diff -r "$T/frames" "$T/frames1" >/dev/null && cmp -s "$T/f.json" "$T/f1.json" ||
    fail "build --frames: one thread and several differ"
"$SPN" info --json "$T/f.json" | grep -Eq '"aux-spiral":[[:space:]]*[0-9]' && fail "the auxiliary spiral should be gone from the file"
# Frames grow: the last frame has more ink than the first (bigger PNG of the same size).
first=$(stat -c %s "$T/frames/$(ls "$T/frames" | head -1)")
last=$(stat -c %s "$T/frames/$(ls "$T/frames" | tail -1)")
[ "$last" -gt "$first" ] || fail "the last frame ($last bytes) should hold more web than the first ($first)"

# The material preset brings its strains: the thesis' soft threads laid at
# its own over-extensions (spokes 133%), which an option still overrides, and
# the web hangs taut: solved, not stepped for seconds.
"$SPN" build --species araneus --preset thesis --settle -o "$T/t.json" 2>"$T/err" || fail "thesis build"
grep -q "static equilibrium" "$T/err" || fail "the thesis-preset web should be solved: $(cat "$T/err")"
grep -Eq '"prestrain": *1\.333' "$T/t.json" || fail "thesis strains expected in the metadata"
"$SPN" build --species araneus --preset=thesis --frame-prestrain 0.25 -o "$T/t2.json" || fail "thesis build with a strain"
grep -Eq '"frame_prestrain": *0\.25[,}]' "$T/t2.json" || fail "--frame-prestrain should override the preset's"
grep -Eq '"prestrain": *1\.333' "$T/t2.json" || fail "the preset's other strains should stay"
"$SPN" build --species araneus -o "$T/s.json" || fail "silk build"
grep -Eq '"anchor_prestrain": *0\.2[,}]' "$T/s.json" || fail "silk strains expected in the metadata"

# Woven webs are form-found (built at rest) unless --as-designed: then the
# metadata says so and the web differs; the physical builder has no such step.
"$SPN" build --species zilla --seed 2 --as-designed -o "$T/d.json" || fail "build --as-designed"
grep -Eq '"form_find": *(0|false)' "$T/d.json" || fail "--as-designed should be in the metadata"
grep -Eq '"form_find": *(1|true)' "$T/s.json" || fail "form finding should be on by default"
"$SPN" build --species zilla --seed 2 -o "$T/z.json" || fail "zilla build"
grep -Eq '"form_found": *1' "$T/z.json" || fail "the web found should say so in its metadata"
grep -Eq '"form_found": *0' "$T/d.json" || fail "the web as designed should say it was not form-found"
cmp -s "$T/d.json" "$T/z.json" && fail "--as-designed should give another web"
"$SPN" build --method geometric --anchors "0,0.5;-0.45,-0.3;0.45,-0.3" --as-designed -o "$T/gd.json" ||
    fail "geometric --as-designed"
grep -Eq '"form_find": *(0|false)' "$T/gd.json" || fail "geometric --as-designed should be in the metadata"

check_bad() { # expected-text args...
    local want=$1; shift
    "$SPN" build "$@" -o "$T/bad.json" 2>"$T/err" && fail "should fail: $*"
    grep -q "$want" "$T/err" || fail "message for '$*' should mention '$want': $(cat "$T/err")"
    [ -e "$T/bad.json" ] && fail "no file after a failure: $*"
    return 0
}
check_bad "at least 3" --method geometric --anchors "0,0;1,0"
check_bad "same point" --method geometric --anchors "0,0;1,0;1,0"
check_bad "one line" --method geometric --anchors "0,0;1,1;2,2"
check_bad "anchor 2" --method geometric --anchors "0,0;nan,1;1,0"
check_bad "crosses" --method geometric --anchors "0,0;1,1;1,0;0,1"
check_bad "\-\-m" --method geometric --anchors "0,0;1,0;0,1" --m 0.7
check_bad "\-\-k" --method geometric --anchors "0,0;1,0;0,1" --k 46
check_bad "\-\-t" --method geometric --anchors "0,0;1,0;0,1" --t 0.3
check_bad "species" --species spidey
check_bad "\-\-as-designed" --method physical --anchors "0,0;1,0;0,1" --as-designed
check_bad "\-\-as-designed" --anchors "0,0;1,0;0,1" --as-designed
check_bad "\-\-anchor-prestrain" --species zilla --anchor-prestrain 5
echo "web build ok"

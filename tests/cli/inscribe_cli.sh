#!/usr/bin/env bash
# spinneret inscribe end to end on the standard orb web: a text and an image
# inscribed (web file, render and overlay written, fewer capture threads,
# inscription threads added), and every bad input refused with a one-line
# message, a non-zero exit and no output file.
. "$(dirname "$0")/lib/common.sh" "$@"
WEB=$DATA/inscribe/orb.json
SETTLE=(--solver implicit --dt 1e-3 --max-time 5)

count_kind() { # file kind-number: springs carrying that tag
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(sum(1 for t in d['springs']['tag'] if t==int(sys.argv[2])))" "$1" "$2"
}

"$SPN" inscribe --help | grep -q 'usage: spinneret inscribe' || fail "--help"

"$SPN" inscribe "$WEB" --text "PIG" --fit 0.5 --emphasis fill "${SETTLE[@]}" -o "$T/pig.json" \
    --render "$T/pig.png" --overlay "$T/pig_overlay.png" 2>"$T/log" || { cat "$T/log"; fail "fill run"; }
for f in pig.json pig.png pig_overlay.png; do [ -s "$T/$f" ] || fail "$f not written"; done
grep -Eq 'settled: (converged|solved)' "$T/log" || fail "not settled: $(cat "$T/log")"
added=$(count_kind "$T/pig.json" 7)
[ "$added" -gt 100 ] || fail "fill added only $added inscription threads"
"$SPN" info "$T/pig.json" >/dev/null || fail "result does not load"

# Two lines, repeated --text and "\n" alike; the plain method adds nothing.
"$SPN" inscribe "$WEB" --text 'SOME\nPIG' --no-settle -o "$T/two.json" 2>/dev/null || fail "two lines"
[ "$(count_kind "$T/two.json" 7)" -eq 0 ] || fail "emphasis none added threads"
before=$(count_kind "$WEB" 6); after=$(count_kind "$T/two.json" 6)
[ "$after" -lt $((before - 20)) ] || fail "capture threads $before -> $after: too few taken out"

# An image target (PBM), cross-hatched, with gaps.
"$SPN" inscribe "$WEB" --image "$DATA/inscribe/plus.pbm" --fit 0.6 --emphasis crosshatch --gaps 4 --no-settle \
    -o "$T/plus.json" 2>"$T/log" || { cat "$T/log"; fail "image run"; }
grep -q 'random gaps 4' "$T/log" || fail "gaps not reported"

# Bad input: exit code, one line naming the problem, no file.
expect_fail() { # code needle args...
    local code=$1 needle=$2; shift 2
    rm -f "$T/bad.json"
    "$SPN" inscribe "$@" -o "$T/bad.json" 2>"$T/err"
    local got=$?
    [ $got -eq "$code" ] || fail "$* exited $got, want $code ($(cat "$T/err"))"
    grep -q -- "$needle" "$T/err" || fail "$*: message '$(cat "$T/err")' lacks '$needle'"
    [ ! -e "$T/bad.json" ] || fail "$*: left an output file"
    ls "$T" | grep -q '\.tmp' && fail "$*: left a temporary file"
    return 0
}
expect_fail 1 "not installed" "$WEB" --text PIG --font "Nonexistent Sans Bold" --no-settle
expect_fail 1 "empty" "$WEB" --text "   " --no-settle
expect_fail 1 "does not fit" "$WEB" --text TERRIFIC --text-height 0.2 --no-settle
expect_fail 1 "cannot read" "$WEB" --image "$T/none.png" --no-settle
expect_fail 1 "0x0" "$WEB" --image "$DATA/bad/inscribe_zero.pgm" --no-settle
expect_fail 1 "inscribe_token.pgm:5" "$WEB" --image "$DATA/bad/inscribe_token.pgm" --no-settle
expect_fail 1 "not a PNG, PBM or PGM" "$WEB" --image "$DATA/bad/inscribe_text.png" --no-settle
expect_fail 2 "emphasis" "$WEB" --text PIG --emphasis sparkle
expect_fail 2 "threshold" "$WEB" --text PIG --threshold 11
expect_fail 2 "give --text or --image" "$WEB"
expect_fail 2 "not both" "$WEB" --text PIG --image "$DATA/inscribe/plus.pbm"
expect_fail 1 "$T/missing.json" "$T/missing.json" --text PIG
echo "inscribe ok"

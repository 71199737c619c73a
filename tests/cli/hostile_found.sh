#!/usr/bin/env bash
# Replays the command lines fuzz_cli found (tests/data/bad/hostile_cli/*.txt,
# in the harness's format: the subcommand on the first line, one argument a
# line, the arguments fuzz_cli's table appends written out) in a folder
# holding the harness's fixtures. Each must exit 0, 1 or 2
# without a sanitizer report (the ASan build turns undefined behaviour into
# "runtime error" lines, which fail the test).
set -u
SPN=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
DATA=${SPN_TEST_DATA:?}
fail() { echo "FAIL: $*"; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1
"$SPN" export scene:orb:3x5 -o web.json && "$SPN" render web.json -o bg.png --size 8x8 || fail "fixtures"
cp "$DATA/hostile/tetra.obj" m.obj && cp "$DATA/hostile/tetra.pov" s.pov
n=0
for f in "$DATA"/bad/hostile_cli/*.txt; do
  mapfile -t args <"$f"
  timeout -k 5 120 "$SPN" "${args[@]}" >/dev/null 2>err; rc=$?
  [ "$rc" -le 2 ] || fail "$(basename "$f"): exit $rc: $(tail -3 err)"
  grep -q 'runtime error\|AddressSanitizer' err && fail "$(basename "$f"): $(grep -m1 'runtime error\|Sanitizer' err)"
  n=$((n + 1))
done
echo "found inputs: $n replayed"

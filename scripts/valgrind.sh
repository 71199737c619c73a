#!/usr/bin/env bash
# The test suite under valgrind's memcheck: every unit test program, and every
# CLI test with the program wrapped in valgrind. Any memcheck error or leak
# ("definitely" or "indirectly" lost) fails the run (exit code 99 from
# valgrind). Prints one JSON line per test and the total time, which decides
# whether it fits CI's budget (see docs/hostile-input.md).
#   scripts/valgrind.sh BUILD_DIR [REGEX]   (a normal, non-sanitizer build)
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR [REGEX]}" && pwd)
only=${2:-.}
src=$(cd "$(dirname "$0")/.." && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
supp=$src/scripts/valgrind.supp
vg=(valgrind --quiet --keep-debuginfo=yes --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect
    --show-leak-kinds=definite,indirect --track-fds=no --suppressions="$supp")
# The program, wrapped: CLI tests call it as their $1.
# Absolute paths: some CLI tests empty PATH to check a missing ffmpeg/povray.
cat >"$T/spinneret" <<WRAP
#!$(command -v bash)
exec $(command -v valgrind) ${vg[*]:1} --log-file=$T/vg-%p.log "$build/spinneret" "\$@"
WRAP
chmod +x "$T/spinneret"
failed=0 start=$(date +%s)
report() { printf '{"test":"%s","seconds":%s,"ok":%s}\n' "$1" "$2" "$3"; }
for t in "$build"/tests/test_*; do
  [ -x "$t" ] || continue
  name=$(basename "$t"); [[ $name =~ $only ]] || continue
  # It re-executes itself through /proc/self/exe, which under valgrind is
  # valgrind's own tool binary: nothing to learn there about our memory.
  [ "$name" = test_physics_determinism ] && continue
  s=$(date +%s)
  (cd "$build" && SPN_TEST_DATA=$src/tests/data "${vg[@]}" "$t" >"$T/out" 2>&1); rc=$?
  report "$name" $(($(date +%s) - s)) "$([ $rc -eq 0 ] && echo true || echo false)"
  [ $rc -eq 0 ] || { failed=1; grep -E '==[0-9]+==' "$T/out" | head -20; }
done
for script in "$src"/tests/cli/*.sh; do
  name=cli_$(basename "$script" .sh); [[ $name =~ $only ]] || continue
  # signal timing is meaningless under valgrind; io_install needs the program
  # inside its CMake build folder (it installs that folder), not the wrapper.
  case $name in cli_hostile_signals | cli_io_install) continue ;; esac
  rm -f "$T"/vg-*.log
  s=$(date +%s)
  SPN_SOURCE_DIR=$src SPN_TEST_DATA=$src/tests/data SPN_HOSTILE_TIMEOUT=600 bash "$script" "$T/spinneret" >"$T/out" 2>&1; rc=$?
  # Errors count even where a test only checks the exit code of a refusal.
  if grep -lE 'ERROR SUMMARY: [1-9]|definitely lost|indirectly lost|Invalid (read|write)|uninitialised' "$T"/vg-*.log >/dev/null 2>&1; then
    rc=1; grep -hE -A8 'Invalid|uninitialised|lost' "$T"/vg-*.log | head -30
  fi
  report "$name" $(($(date +%s) - s)) "$([ $rc -eq 0 ] && echo true || echo false)"
  [ $rc -eq 0 ] || { failed=1; tail -5 "$T/out"; }
done
echo "valgrind: $(($(date +%s) - start)) s in all"
exit $failed

#!/usr/bin/env bash
# Runs every libFuzzer harness in BUILD/fuzz for FUZZ_SECONDS each (default 60),
# its corpus seeded from the globs in fuzz/seeds/<harness>. Prints one JSON line
# per harness (executions, corpus size, crashes) and fails if any crashed;
# crashing inputs are kept in BUILD/fuzz-crashes/ (make each one a test in
# tests/data/bad/ before fixing it). FUZZ_ONLY=fuzz_cli runs one harness;
# FUZZ_TIMEOUT (default 25 s) is the slowest input allowed.
set -u
seconds=${FUZZ_SECONDS:-60}
# Absolute: a harness may work in a folder of its own (fuzz_cli does).
build=$(cd "$1" && pwd) || exit 2
cd "$(dirname "$0")/.."
crashed=0
for h in "$build"/fuzz/${FUZZ_ONLY:-fuzz_*}; do
  [ -x "$h" ] || continue
  name=$(basename "$h")
  corpus="$build/fuzz-corpus/$name"
  crashes="$build/fuzz-crashes"
  mkdir -p "$corpus" "$crashes"
  # Inputs from an earlier run were reported then; keep them aside, count only new ones.
  mkdir -p "$crashes/earlier"
  mv "$crashes/$name-"* "$crashes/earlier/" 2>/dev/null
  if [ -f "fuzz/seeds/$name" ]; then
    while read -r glob; do
      case "$glob" in ''|'#'*) continue ;; esac
      for f in $glob; do [ -f "$f" ] && cp "$f" "$corpus/" 2>/dev/null; done
    done < "fuzz/seeds/$name"
  fi
  # A dictionary: fuzz/<harness>.dict if there is one; for the command-line
  # harness also every subcommand's name and the options its --help names.
  dict="$build/fuzz-$name.dict"
  : >"$dict"
  [ -f "fuzz/$name.dict" ] && cat "fuzz/$name.dict" >>"$dict"
  if [ "$name" = fuzz_cli ] && [ -x "$build/spinneret" ]; then
    for cmd in $("$build/spinneret" --help | awk '/^commands:/{on=1;next} on&&NF{print $1}'); do
      printf '"%s\\x0a"\n' "$cmd" >>"$dict"
      "$build/spinneret" "$cmd" --help 2>/dev/null | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u |
        sed 's/.*/"\\x0a&\\x0a"/' >>"$dict"
    done
    sort -u -o "$dict" "$dict"
  fi
  dictarg=()
  [ -s "$dict" ] && dictarg=(-dict="$dict")
  log="$build/fuzz-$name.log"
  "$h" "${dictarg[@]}" -max_total_time="$seconds" -timeout="${FUZZ_TIMEOUT:-25}" -report_slow_units="${FUZZ_TIMEOUT:-25}" -rss_limit_mb=2048 -malloc_limit_mb=1024 \
       -print_final_stats=1 -artifact_prefix="$crashes/$name-" "$corpus" >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 | grep -o '[0-9]*')
  files=$(ls "$corpus" | wc -l)
  found=$(ls "$crashes" | grep -c "^$name-" || true)
  printf '{"harness":"%s","seconds":%s,"executions":%s,"corpus":%s,"crashes":%s,"exit":%s}\n' \
    "$name" "$seconds" "${runs:-0}" "$files" "$found" "$rc"
  if [ "$rc" -ne 0 ] || [ "$found" -gt 0 ]; then
    crashed=1
    echo "fuzz: $name failed; see $log and $crashes/" >&2
    grep -m5 -E 'ERROR|SUMMARY' "$log" >&2
  fi
done
exit $crashed

#!/usr/bin/env bash
# Usage: hostile_options.sh SPINNERET [COMMAND[/K/N]]  (run by tests/cli/hostile_options_*.sh,
# one per subcommand, so each test stays short; COMMAND/K/N takes every N-th of
# its rows from the K-th, to split a long command; without COMMAND, every row).
# Extreme and hostile option values, driven by tests/data/options.tsv: every
# numeric option of every subcommand gets 0, -1, 1e-300, 1e300, nan, inf,
# -inf, junk and values just outside its documented range. Each run must
# either succeed with a finite output (no nan/inf in the written text) or be
# refused with exit 2, a message naming the option, and no output — never a
# crash, a hang (timeout), or a non-finite number in a file.
set -u
SPN=$1
ONLY=${2:-}
PART=0 PARTS=1
if [[ $ONLY == */*/* ]]; then IFS=/ read -r ONLY PART PARTS <<<"$ONLY"; fi
DATA=${SPN_TEST_DATA:?}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
IN=$DATA/io/chain4.json
LIMIT=${SPN_HOSTILE_TIMEOUT:-60}   # generous: a hang, not a slow machine, must trip it
failures=0 runs=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Just outside [lo, hi] for a real option.
below() { awk -v x="$1" 'BEGIN { if (x == 0) print "-1e-9"; else if (x > 0) printf "%.17g\n", x * 0.999; else printf "%.17g\n", x * 1.001 }'; }
above() { awk -v x="$1" 'BEGIN { if (x == 0) print "1e-9"; else if (x > 0) printf "%.17g\n", x * 1.001; else printf "%.17g\n", x * 0.999 }'; }

values() { # kind lo hi -> one value a line
  local kind=$1 lo=$2 hi=$3
  case $kind in
  real) printf '%s\n' 0 -1 1e-300 1e300 nan -inf abc "$(below "$lo")" "$(above "$hi")" ;;
  int) printf '%s\n' 0 -1 1e300 nan 2.5 99999999999999999999 "$((lo - 1))" "$((hi + 1))" ;;
  u64) printf '%s\n' 0 -1 1e300 nan 18446744073709551616 abc 18446744073709551615 ;;
  size) printf '%s\n' 0x0 -1x5 1e300x1 nanx5 5x x5 "1x$((hi + 1))" "$((hi + 1))x1" "${hi}x${hi}" ;;
  vec) printf '%s\n' 0,0,0 nan,0,0 inf,0,0 1e300,1e300,1e300 -1e300,0,0 1e-300,1e-300,1e-300 1,2 ;;
  rgb) printf '%s\n' 0,0,0 -1,0,0 nan,0,0 inf,0,0 1e300,0,0 1e-300,0,0 "$(above "$hi"),0,0" 1,1 ;;
  anchors) printf '%s\n' '0,0;0,0;0,0' 'nan,0;1,0;0,1' '1e300,0;0,1e300;-1e300,0' '0,0;1,0' '' ';;;' \
             '1e-300,0;0,1e-300;-1e-300,0' '0,0;1,0;2,0' '-1,-1;1,-1;1,1;-1,1' \
             "$(for i in $(seq 0 64); do printf '%s,%s;' "$i" "$((i % 2))"; done)" ;;
  prey) printf '%s\n' '0,0,-0.1;0,0,1;0;0.004' '0,0,-0.1;0,0,1;-1;0.004' '0,0,-0.1;0,0,1;0.0002;0' \
          'nan,0,0;0,0,1;0.0002;0.004' '1e300,0,0;0,0,1e300;1e300;1e300' '0,0,-0.1;0,0,1;1e-300;1e-300' \
          '0,0,-0.1;0,0,1;0.0002' '' ;;
  scene) printf '%s\n' 0x5 -1x5 1e300x5 nanx3 "$((hi + 1))x1" 1x1 2x3 "x" ;;
  esac
}

# Text outputs must not hold a non-finite number (PNG frames are not text).
finite_output() {
  local out=$1
  [ -e "$out" ] || return 1
  # A folder of frames: every text frame in it (PNG frames are skipped).
  ! grep -rIlaiwE 'nan|-nan|inf|-inf|infinity' "$out" | grep -q .
}

check() { # row-description option value args...
  local what=$1 opt=$2 value=$3; shift 3
  local out=$T/out args=() a
  rm -rf "$T"/out*
  for a in "$@"; do
    case $a in
    IN) args+=("$IN") ;;
    DATA/*) args+=("$DATA/${a#DATA/}") ;;
    OUT*) out=$T/out${a#OUT}; args+=("$out") ;;
    *) args+=("$a") ;;
    esac
  done
  if [ "$opt" = IN ]; then
    args=("scene:orb:$value" "${args[@]}")
    opt=scene:orb
  else
    args+=("$opt" "$value")
  fi
  runs=$((runs + 1))
  timeout -k 5 "$LIMIT" "$SPN" "${args[@]}" >"$T/stdout" 2>"$T/err"
  local rc=$?
  case $rc in
  0) finite_output "$out" || fail "$what $opt '$value': exit 0 but output missing or not finite" ;;
  2) grep -qF -- "$opt" "$T/err" || fail "$what $opt '$value': refused without naming the option: $(head -c 300 "$T/err")"
     grep -qE '\[|expected|between|range|must' "$T/err" || fail "$what $opt '$value': refused without a range: $(head -c 300 "$T/err")"
     [ -e "$out" ] && fail "$what $opt '$value': refused but left $out" ;;
  124) fail "$what $opt '$value': hung (killed after ${LIMIT}s)" ;;
  *) fail "$what $opt '$value': exit $rc: $(head -c 300 "$T/err")" ;;
  esac
  ls -a "$T" | grep -q '\.tmp' && fail "$what $opt '$value': left a temporary file: $(ls -a "$T")"
  return 0
}

rows=0
while IFS=$'\t' read -r cmd opt kind lo hi rest; do
  case $cmd in ''|'#'*) continue ;; esac
  [ -n "$ONLY" ] && [ "$cmd" != "$ONLY" ] && continue
  seen=$((${seen:-0} + 1))
  [ $(((seen - 1) % PARTS)) -eq "$PART" ] || continue
  rows=$((rows + 1))
  read -r -a extra <<<"$rest"
  while IFS= read -r v; do
    check "$cmd" "$opt" "$v" "$cmd" "${extra[@]}"
  done < <(values "$kind" "$lo" "$hi")
done <"$DATA/options.tsv"
[ "$rows" -gt 0 ] || fail "options.tsv: no rows for '$ONLY'"
echo "hostile options: $runs runs over $rows options, $failures failures"
[ "$failures" -eq 0 ]

#!/usr/bin/env bash
# The binary web file (.spnw) through the CLI: build and settle write it by
# the output's extension, every command reads it by its content; an
# independent reader of the documented layout (Python's struct) sees the same
# web as the JSON file; a damaged file exits 1 naming the file and what is
# wrong, and writes nothing.
. "$(dirname "$0")/lib/common.sh" "$@"

"$SPN" build --species araneus -o "$T/web.spnw" 2>"$T/err" || fail "build .spnw exited $?: $(cat "$T/err")"
"$SPN" build --species araneus -o "$T/web.json" 2>"$T/err" || fail "build .json exited $?: $(cat "$T/err")"
head -c 8 "$T/web.spnw" | od -An -c | grep -q 'S   P   N   W   E   B' || fail "no magic"
"$SPN" export "$T/web.spnw" -o "$T/back.json" || fail "export .spnw -> .json"
cmp -s "$T/web.json" "$T/back.json" || fail "the binary file's web differs from the JSON file's"
"$SPN" export "$T/web.json" -o "$T/again.spnw" || fail "export .json -> .spnw"
cmp -s "$T/web.spnw" "$T/again.spnw" || fail "export wrote other bytes than build"
"$SPN" info "$T/web.spnw" >"$T/info" || fail "info .spnw"
grep -q '^particles: ' "$T/info" || fail "info: $(cat "$T/info")"

python3 - "$T/web.spnw" "$T/web.json" <<'PY' || fail "the documented layout does not read back the JSON file's web"
import json, struct, sys
data = open(sys.argv[1], "rb").read()
ref = json.load(open(sys.argv[2]))
assert data[:8] == b"\x89SPNWEB\n", data[:8]
layout, hlen = struct.unpack_from("<II", data, 8)
assert layout == 1, layout
header = json.loads(data[16:16 + hlen])
np, ns = header["particles"]["count"], header["springs"]["count"]
assert header["particles"] == {"count": np} and header["springs"] == {"count": ns}, header
assert header["world"] == ref["world"] and header["metadata"] == ref["metadata"]
at = (16 + hlen + 7) // 8 * 8
def take(fmt, n):
    global at
    vals = list(struct.unpack_from("<%d%s" % (n, fmt), data, at))
    at += n * struct.calcsize(fmt)
    return vals
p, s = ref["particles"], ref["springs"]
assert take("d", 3 * np) == p["position"] and take("d", 3 * np) == p["velocity"]
assert take("d", np) == p["mass"]
for key in ("k", "kd", "rest", "break_min"): assert take("d", ns) == s[key], key
assert take("d", ns) == [float("inf") if v is None else v for v in s["break_max"]]
assert take("I", np) == p["tag"]
for key in ("a", "b", "tag", "stage", "order"): assert take("I", ns) == s[key], key
assert take("B", np) == p["fixed"]
for key in ("tension_only", "broken"): assert take("B", ns) == s[key], key
assert at == len(data), (at, len(data))
PY

"$SPN" settle "$T/web.spnw" -o "$T/settled.spnw" --method equilibrium 2>"$T/err" \
    || fail "settle .spnw exited $?: $(cat "$T/err")"
"$SPN" info "$T/settled.spnw" >/dev/null || fail "settled .spnw unreadable"

# Damaged files: cut short, and a flag that is neither 0 nor 1.
size=$(stat -c %s "$T/web.spnw")
head -c $((size - 5)) "$T/web.spnw" >"$T/cut.spnw"
"$SPN" settle "$T/cut.spnw" -o "$T/out.spnw" 2>"$T/err"; code=$?
[ "$code" = 1 ] || fail "cut file: exit $code, expected 1"
grep -q "cut.spnw: the columns take" "$T/err" || fail "cut file message: $(cat "$T/err")"
cp "$T/web.spnw" "$T/flag.spnw"
printf '\002' | dd of="$T/flag.spnw" bs=1 seek=$((size - 1)) conv=notrunc status=none
"$SPN" info "$T/flag.spnw" >/dev/null 2>"$T/err"; code=$?
[ "$code" = 1 ] || fail "bad flag: exit $code, expected 1"
grep -q "flag.spnw: springs.broken\[[0-9]*\]: expected 0 or 1, got 2" "$T/err" || fail "flag message: $(cat "$T/err")"
[ ! -e "$T/out.spnw" ] || fail "an output was written for a bad input"
ls -A "$T" | grep -q "^\.tmp" && fail "a temporary file was left: $(ls -A "$T")"
exit 0

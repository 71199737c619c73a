#!/usr/bin/env bash
# Output paths that cannot be written: a missing folder, a path under a
# regular file, a read-only folder, a full disk. Each command that writes a
# file must exit 1 with "cannot write" (or "write failed") and the path, leave no file or
# temporary, and never clobber an existing good output.
#
# Root (as in CI containers) ignores permission bits, so a chmod'ed folder is
# tested only when not root; as root a read-only tmpfs mount is used when the
# container allows mounting, and skipped (said so) otherwise. The full disk is
# RLIMIT_FSIZE (ulimit -f, SIGXFSZ ignored: writes fail with EFBIG), which needs
# no privilege, plus a small tmpfs filled up (ENOSPC) when mounting is allowed.
set -u
SPN=$1
DATA=${SPN_TEST_DATA:?}
T=$(mktemp -d)
mounted=()
cleanup() { for m in "${mounted[@]}"; do umount "$m" 2>/dev/null; done; rm -rf "$T"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$SPN" export scene:orb -o "$T/web.json" || fail "export of the input failed"

# One command line per writer; OUT.ext is replaced by the output path.
writers=(
  "render $T/web.json -o OUT.png"
  "render $T/web.json -o OUT.svg"
  "render $T/web.json -o OUT.pdf"
  "export $T/web.json -o OUT.obj"
  "export $T/web.json -o OUT.ply --tubes 0.001"
  "export $T/web.json -o OUT.pov"
  "export $T/web.json -o OUT.json"
  "settle $T/web.json -o OUT.json --max-time 0.001"
  "shoot --from 0,1.5,0 --to 3,3,0 -o OUT.json"
  "build --species araneus -o OUT.json"
  "inscribe $DATA/inscribe/orb.json --image $DATA/inscribe/plus.pbm --raster 64 --no-settle -o OUT.json"
)

run_to() { # writer-line output-base -> runs it, sets rc, err in $T/err
  local line=$1 base=$2 args=() w
  for w in $line; do
    case $w in OUT.*) args+=("$base.${w#OUT.}") ;; *) args+=("$w") ;; esac
  done
  "$SPN" "${args[@]}" >"$T/out" 2>"$T/err"
  rc=$?
}

expect_refused() { # what writer-line base
  local what=$1 line=$2 base=$3
  run_to "$line" "$base"
  [ "$rc" -eq 1 ] || fail "$what: '$line' exited $rc (expected 1): $(cat "$T/err")"
  grep -qE "cannot write|write failed" "$T/err" || fail "$what: '$line': message lacks 'cannot write': $(cat "$T/err")"
  grep -qF "$(dirname "$base")" "$T/err" || fail "$what: '$line': message does not name the path: $(cat "$T/err")"
  ! ls -a "$(dirname "$base")" 2>/dev/null | grep -q '\.tmp' || fail "$what: '$line' left a temporary"
}

good_output_kept() { # what writer-line base: an older good file survives a failed write
  local what=$1 line=$2 base=$3 ext
  ext=$(grep -o 'OUT\.[a-z]*' <<<"$line"); ext=${ext#OUT.}
  printf 'an older good output\n' >"$base.$ext"
  # On a small file system, fill what is left so that any new byte fails.
  [ -n "${FILL:-}" ] && { dd if=/dev/zero of="$FILL" bs=1k 2>/dev/null; true; }
  run_to "$line" "$base"
  [ -n "${FILL:-}" ] && rm -f "$FILL"
  [ "$rc" -eq 1 ] || fail "$what: '$line' exited $rc (expected 1): $(cat "$T/err")"
  [ "$(cat "$base.$ext")" = "an older good output" ] || fail "$what: '$line' clobbered the older output"
  ! ls -a "$(dirname "$base")" | grep -q '\.tmp' || fail "$what: '$line' left a temporary"
  rm -f "$base.$ext"
}

touch "$T/a-file"
for line in "${writers[@]}"; do
  expect_refused "missing folder" "$line" "$T/missing/out"
  expect_refused "path under a file" "$line" "$T/a-file/out"
done

# Full disk, without privileges: a file size limit of 2 KiB.
mkdir -p "$T/limited"
for line in "${writers[@]}"; do
  (trap '' XFSZ; ulimit -f 2; good_output_kept "file size limit" "$line" "$T/limited/out") || exit 1
  (trap '' XFSZ; ulimit -f 2; expect_refused "file size limit" "$line" "$T/limited/new") || exit 1
done

# Read-only folder.
if [ "$(id -u)" -ne 0 ]; then
  mkdir -p "$T/ro" && chmod 555 "$T/ro"
  for line in "${writers[@]}"; do expect_refused "read-only folder" "$line" "$T/ro/out"; done
  chmod 755 "$T/ro"
elif mkdir -p "$T/ro" && mount -t tmpfs -o ro,size=64k tmpfs "$T/ro" 2>/dev/null; then
  mounted+=("$T/ro")
  for line in "${writers[@]}"; do expect_refused "read-only mount" "$line" "$T/ro/out"; done
else
  echo "note: root without mount: read-only folders not tested (root ignores permission bits)"
fi

# A real full disk (ENOSPC): a small tmpfs filled up, when mounting is allowed.
if [ "$(id -u)" -eq 0 ] && mkdir -p "$T/full" && mount -t tmpfs -o size=16k tmpfs "$T/full" 2>/dev/null; then
  mounted+=("$T/full")
  for line in "${writers[@]}"; do FILL=$T/full/filler good_output_kept "full disk" "$line" "$T/full/out"; done
else
  echo "note: no tmpfs mount: a full disk is tested by the file size limit only"
fi
echo "outputs: ok"

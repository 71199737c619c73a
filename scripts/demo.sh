#!/usr/bin/env bash
# The showcase: runs every demo/NN-*.sh in order with the program and the output
# folder, so each part of Spinneret adds its own pictures without touching the others.
set -eu
prog=$(realpath "$1")
out=$2
mkdir -p "$out"
out=$(realpath "$out")
cd "$(dirname "$0")/.."
for part in demo/*.sh; do
  [ -e "$part" ] || continue
  echo "== $part"
  SPN="$prog" OUT="$out" bash "$part"
done
echo "showcase written to $out"

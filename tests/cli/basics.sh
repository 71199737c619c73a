#!/usr/bin/env bash
# The program's front door: help, version, unknown commands.
set -u
SPN=$1
fail() { echo "FAIL: $*"; exit 1; }
"$SPN" --version | grep -q '^spinneret [0-9]' || fail "--version"
"$SPN" --help | grep -q 'usage: spinneret' || fail "--help"
"$SPN" frobnicate 2>/dev/null; [ $? -eq 2 ] || fail "unknown command should exit 2"
"$SPN" 2>/dev/null; [ $? -eq 2 ] || fail "no command should exit 2"
echo "basics ok"

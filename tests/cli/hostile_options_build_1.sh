#!/usr/bin/env bash
# Part 1 of 3 of the rows of tests/data/options.tsv for `spinneret build` (see lib/hostile_options.sh).
exec bash "$(dirname "$0")/lib/hostile_options.sh" "$1" build/0/3

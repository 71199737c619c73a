#!/usr/bin/env bash
# Part 2 of 2 of the rows of tests/data/options.tsv for `spinneret animate` (see lib/hostile_options.sh).
exec bash "$(dirname "$0")/lib/hostile_options.sh" "$1" animate/1/2

#!/usr/bin/env bash
# The rows of tests/data/options.tsv for `spinneret inscribe` (see lib/hostile_options.sh).
exec bash "$(dirname "$0")/lib/hostile_options.sh" "$1" inscribe

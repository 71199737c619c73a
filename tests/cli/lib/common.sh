# The preamble of the CLI tests, sourced first by each:
#   . "$(dirname "$0")/lib/common.sh" "$@"
# SPN is the program under test (the test's first argument), DATA the test
# data folder, fail() ends the test with a FAIL line, T a scratch folder
# removed on exit (a test that needs more on exit sets its own trap).
set -u
SPN=${1:?usage: $0 SPINNERET}
DATA=${SPN_TEST_DATA:?SPN_TEST_DATA must name tests/data}
fail() { echo "FAIL: $*"; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

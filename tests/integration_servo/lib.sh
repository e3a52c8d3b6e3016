# Helpers for the servo graph tests: fail with a message, read a YAML report value, a port
# of our own (from the test's DDS domain), and the graph runner.
fail() { echo "FAIL: $*" >&2; exit 1; }
value() { grep "^$2:" "$1" | awk '{print $2}'; }
# Tests run in parallel: each leases a DDS domain (AVS_DOMAIN_ID) and a Modbus port of its own.
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"
port=$AVS_TEST_PORT
graph="$src/tests/integration_servo/data/head.yaml"
# run_head DIR [name:=value ...]: runs the head graph with reports in DIR.
run_head() {
  local dir=$1; shift
  mkdir -p "$dir"
  "$avs" launch "$graph" port:=$port report_dir:="$dir" "$@" 2>"$dir/stderr.txt" ||
    { cat "$dir/stderr.txt" >&2; fail "avs launch $* failed"; }
}
# column FILE NAME: index (1-based) of column NAME in the CSV header of FILE.
column() { head -1 "$1" | tr ',' '\n' | grep -nx "$2" | cut -d: -f1; }

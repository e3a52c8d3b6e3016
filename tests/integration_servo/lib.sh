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
# start_live DIR [name:=value ...]: launches the head graph in realtime sim time in the
# background (launch_pid, live_log); stop_live ends it. Waits only bound the tests: nothing
# depends on how fast the machine is. At 0.2 x real time: the 1 kHz loop of four components
# on one thread fell behind on a loaded 2-core CI machine at 1 x (timers at 880-940 Hz), and
# the drives' 2 ms watchdogs latched faults the test did not inject (CI, 2026-12-06).
launch_pid=
start_live() {
  local dir=$1; shift
  mkdir -p "$dir"
  live_log="$dir/stderr.txt"
  "$avs" launch "$graph" port:=$port report_dir:="$dir" clock_mode:=realtime \
    real_time_factor:=0.2 "$@" 2>"$live_log" &
  launch_pid=$!
}
stop_live() { kill -TERM "$launch_pid"; wait "$launch_pid" || true; launch_pid=; }
# start_lockstep DIR GRAPH [name:=value ...]: launches GRAPH in the background as the file says
# (lockstep), our Modbus port given, its log in DIR/stderr.txt (launch_pid, live_log for
# wait_for); the EXIT trap stops it and removes the caller's temporary folder `out`.
start_lockstep() {
  local dir=$1 file=$2; shift 2
  trap '[ -n "$launch_pid" ] && kill -INT "$launch_pid" 2>/dev/null; rm -rf "$out"' EXIT
  mkdir -p "$dir"
  live_log="$dir/stderr.txt"
  "$avs" launch "$file" port:=$port "$@" 2>"$live_log" &
  launch_pid=$!
}
# stop_lockstep: Ctrl-C to the graph of start_lockstep, which must end cleanly.
stop_lockstep() {
  kill -INT "$launch_pid"
  wait "$launch_pid" || { cat "$live_log" >&2; fail "the graph failed"; }
  launch_pid=
}
# wait_for PATTERN: until the live launch's log has it (at most 60 s).
wait_for() {
  for _ in $(seq 600); do
    grep -q "$1" "$live_log" && return 0
    kill -0 "$launch_pid" 2>/dev/null || { cat "$live_log" >&2; fail "the graph ended"; }
    sleep 0.1
  done
  cat "$live_log" >&2; fail "no '$1' in the log"
}

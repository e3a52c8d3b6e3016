#!/usr/bin/env bash
# avs graph: components from /diagnostics, topic rates, and a QoS mismatch named plainly (and none
# between a publisher and a subscriber of one container).
# Two graphs started separately: a best-effort talker at 50 Hz and a reliable listener.
# Usage: graph_live.sh AVS SOURCE_DIR
set -u
AVS=${1:?avs binary}
SRC=${2:?source dir}
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"  # AVS_DOMAIN_ID of its own
OUT=$(mktemp /tmp/avs_graph_live.XXXXXX)
PIDS=()
cleanup() { kill -TERM "${PIDS[@]}" 2>/dev/null; wait 2>/dev/null; rm -f "$OUT"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; cat "$OUT"; exit 1; }

"$AVS" launch "$SRC/tests/deploy/data/qos_publisher.yaml" >/dev/null 2>&1 &
PIDS+=($!)
"$AVS" launch "$SRC/tests/deploy/data/qos_subscriber.yaml" >/dev/null 2>&1 &
PIDS+=($!)
sleep 2
"$AVS" graph --duration 4 >"$OUT" 2>&1
rc=$?
cat "$OUT"
((rc == 3)) || fail "expected exit status 3 (a QoS mismatch), got $rc"
grep -q "sensor_side/talker *test_talker *OK" "$OUT" || fail "the talker's diagnostics are missing"
grep -q "reliable_side/listener *test_listener *OK" "$OUT" || fail "the listener's diagnostics are missing"
grep -q "/chatter: publisher 'sensor_side' and subscriber 'reliable_side' will never match: the subscriber requires RELIABLE, the publisher offers BEST_EFFORT" "$OUT" ||
  fail "the mismatch is not named"
rate=$(awk '$1 == "/chatter" {print $2}' "$OUT")
awk -v r="$rate" 'BEGIN {exit !(r > 40 && r < 60)}' || fail "/chatter rate $rate Hz, expected about 50"
echo "PASS: avs graph names components, the 50 Hz rate ($rate Hz) and the QoS mismatch"

# The same two QoS in one container: delivered in process, no mismatch (issue 18 section 4).
kill -TERM "${PIDS[@]}" 2>/dev/null; wait 2>/dev/null
PIDS=()
"$AVS" launch "$SRC/tests/deploy/data/qos_one_container.yaml" >/dev/null 2>&1 &
PIDS+=($!)
sleep 2
"$AVS" graph --duration 2 --no-rates >"$OUT" 2>&1
rc=$?
cat "$OUT"
((rc == 0)) || fail "expected exit status 0 (no mismatch inside one container), got $rc"
grep -q "together/listener *test_listener *OK" "$OUT" || fail "the listener's diagnostics are missing"
if grep -q "rq/\|rr/" "$OUT"; then fail "avs graph lists the parameter services as topics"; fi
echo "PASS: no QoS mismatch reported inside one container"

#!/usr/bin/env bash
# `avs topic list/echo/hz` from another process against a running graph, then Ctrl-C
# (SIGINT) to `avs launch` must stop every container cleanly.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
out=$(mktemp -d)
"$avs" launch "$src/tests/support/graphs/talker_listener.yaml" rate_hz:=100 report_dir:="$out" 2> "$out/log" &
launcher=$!
trap 'kill $launcher 2>/dev/null || true; rm -rf "$out"' EXIT

"$avs" topic list -v --wait 3 > "$out/list"
cat "$out/list"
grep -q "^rt/chatter .*std_msgs/msg/String .*1 pub, 2 sub" "$out/list" || fail "topic list lacks rt/chatter"
grep -q "DDS type: std_msgs::msg::dds_::String_" "$out/list" || fail "topic list -v lacks the DDS type"
grep -q "publisher:  reliable, volatile, keep_last 10" "$out/list" || fail "topic list -v lacks QoS"

"$avs" topic echo /chatter -n 3 > "$out/echo"
cat "$out/echo"
[ "$(grep -c '^data: [0-9]* 0x' "$out/echo")" -eq 3 ] || fail "echo did not print 3 samples"

"$avs" topic hz chatter --duration 3 > "$out/hz"
cat "$out/hz"
rate=$(grep "average rate" "$out/hz" | tail -1 | awk '{print $3}')
# The talker runs on wall time: only a loose plausibility bound, not a speed check.
awk -v r="$rate" 'BEGIN { exit !(r > 20 && r < 500) }' || fail "implausible rate $rate"

kill -INT $launcher
wait $launcher || fail "avs launch exited with $? after SIGINT"
cat "$out/log"
grep -q "stopping containers" "$out/log" || fail "SIGINT not forwarded"
[ -f "$out/local_listener.yaml" ] || fail "local listener did not shut down cleanly"
[ -f "$out/remote_listener.yaml" ] || fail "remote listener did not shut down cleanly"
echo PASS

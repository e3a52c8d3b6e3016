#!/usr/bin/env bash
# `avs topic list/info/type/echo/hz` from another process against a running graph, then Ctrl-C
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
grep -q "^/chatter .*std_msgs/msg/String .*1 pub, 2 sub" "$out/list" || fail "topic list lacks /chatter"
grep -q "DDS topic: rt/chatter" "$out/list" || fail "topic list -v lacks the DDS topic name"
if grep -q "^r[qr]/" "$out/list"; then fail "topic list shows the parameter services"; fi
grep -q "DDS type: std_msgs::msg::dds_::String_" "$out/list" || fail "topic list -v lacks the DDS type"
grep -q "publisher:  reliable, volatile, keep_last 10" "$out/list" || fail "topic list -v lacks QoS"

# topic type / info (issue 18 section 2), ROS names as `ros2 topic` prints them.
[ "$("$avs" topic type /chatter)" = "std_msgs/msg/String" ] || fail "topic type /chatter"
"$avs" topic info chatter -v > "$out/info"
cat "$out/info"
grep -q "^Type: std_msgs/msg/String$" "$out/info" || fail "topic info lacks the type"
grep -q "^Publisher count: 1$" "$out/info" || fail "topic info: publisher count"
grep -q "^Subscription count: 2$" "$out/info" || fail "topic info: subscription count"
grep -q "^  QoS: reliable, volatile, keep_last 10$" "$out/info" || fail "topic info -v lacks QoS"
# As ros2 topic info -v: each endpoint's node (from ros_discovery_info), endpoint type, GID.
grep -q "^  Node name: talker$" "$out/info" || fail "topic info -v lacks the publisher's node"
grep -q "^  Node name: local_listener$" "$out/info" || fail "topic info -v lacks a subscriber's node"
grep -q "^  Node namespace: /$" "$out/info" || fail "topic info -v lacks the node namespace"
grep -q "^  Endpoint type: PUBLISHER$" "$out/info" || fail "topic info -v lacks the endpoint type"
grep -Eq "^  GID: [0-9a-f]{2}(\.[0-9a-f]{2}){15}$" "$out/info" || fail "topic info -v lacks the GID"
"$avs" --version | grep -q "^avs [0-9]*\.[0-9]*\.[0-9]*$" || fail "avs --version"
# avs components: ROS type names, the DDS names only with -v (issue 18 section 4).
"$avs" components decode > "$out/components"
grep -q "^  publishes depth -> /depth/image \[sensor_msgs/msg/Image\]$" "$out/components" ||
  fail "avs components: no ROS type name"
! grep -q "dds_" "$out/components" || fail "avs components: a DDS name without -v"
"$avs" components -v decode | grep -q "\[sensor_msgs/msg/Image, DDS sensor_msgs::msg::dds_::Image_\]$" ||
  fail "avs components -v: no DDS name"

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

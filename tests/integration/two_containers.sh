#!/usr/bin/env bash
# Two containers (two processes): inside `talkers` the listener must get the talker's own
# buffers (same address: no copy); in `remote` every sample arrives over DDS.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

"$avs" launch "$src/tests/support/graphs/talker_listener.yaml" duration_s:=3 rate_hz:=200 report_dir:="$out" 2> "$out/log" \
  || { cat "$out/log"; fail "avs launch exited with $?"; }
cat "$out/log"
local_rx=$(value "$out/local_listener.yaml" received)
local_same=$(value "$out/local_listener.yaml" same_buffer)
remote_rx=$(value "$out/remote_listener.yaml" received)
remote_same=$(value "$out/remote_listener.yaml" same_buffer)
echo "local: $local_rx received, $local_same same buffer; remote: $remote_rx received, $remote_same same buffer"
[ "$local_rx" -gt 100 ] || fail "local listener received only $local_rx"
[ "$local_same" -eq "$local_rx" ] || fail "local listener got $((local_rx - local_same)) copies"
[ "$remote_rx" -gt 100 ] || fail "remote listener received only $remote_rx"
[ "$remote_same" -eq 0 ] || fail "remote listener cannot share the publisher's buffer"
grep -q "container 'talkers' exited with status 0" "$out/log" || fail "talkers did not exit cleanly"
grep -q "container 'remote' exited with status 0" "$out/log" || fail "remote did not exit cleanly"
echo PASS

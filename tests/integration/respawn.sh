#!/usr/bin/env bash
# A failing component takes its container down with a clear error; `avs launch` reports the
# exit status, restarts the container per its respawn policy, stops at the limit and
# returns non-zero.
set -uo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
log=$(mktemp); trap 'rm -f "$log"' EXIT
timeout 60 "$avs" launch "$src/tests/integration/data/respawn.yaml" 2> "$log"; status=$?
cat "$log"
[ $status -eq 1 ] || fail "expected exit status 1, got $status"
[ "$(grep -c "container 'flaky' exited with status 1" "$log")" -eq 3 ] || fail "expected 3 failed runs"
[ "$(grep -c "restarting 'flaky'" "$log")" -eq 2 ] || fail "expected 2 restarts"
grep -q "reached its restart limit" "$log" || fail "no restart-limit message"
grep -q "component 'talker' (test_talker): callback failed: failing on purpose after 5 messages" "$log" \
  || fail "the component's error is not reported with its name and type"
echo PASS

#!/usr/bin/env bash
# Multi-host test: three "hosts" A, B, C as network namespaces joined by veth pairs to a bridge
# in a fourth ("switch") namespace (netns_lib.sh). Each host runs `avs launch DEPLOYMENT --host X`
# exactly as a real machine would.
#   1. delivery across hosts (the topics in DELIVERY, read on the host named there);
#   2. A's processes are killed (SIGKILL, as a crashed machine): B and C keep running, their
#      launchers report the lost publishers (participant lease), and the servo drive on C
#      commands zero torque (its command timeout);
#   3. A is started again: delivery and torque come back without restarting B or C.
# Usage: multihost.sh AVS SOURCE_DIR multicast|unicast|secure [DEPLOYMENT]
# (secure: the multicast deployment with DDS security on, identities from `avs security init`)
# Exit 77 (CTest SKIP_RETURN_CODE) when network namespaces cannot be created.
# The graph is a file the deployment names: swapping in the vision graph (capture+decode on A,
# matching on B, tracking+servo on C) changes DEPLOYMENT and the topic lists below, nothing else.
set -u
AVS=${1:?avs binary}
SRC=${2:?source dir}
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"  # AVS_DOMAIN_ID of its own
MODE=${3:-multicast}
if [[ $MODE == unicast ]]; then
  DEPLOY=${4:-$SRC/tests/support/graphs/deploy/three_hosts_unicast.yaml}
else
  DEPLOY=${4:-$SRC/tests/support/graphs/deploy/three_hosts.yaml}
fi
# host:topic read there, published on A.
DELIVERY=${DELIVERY:-"B:/chatter C:/head/torque_command"}
# host:topic whose loss the host's launcher must report when A dies.
LOST=${LOST:-"B:/chatter C:/head/torque_command"}
# 1: the torque command source is on A, so C's drive must command zero torque while A is down.
TORQUE_CHECK=${TORQUE_CHECK:-1}

. "$(dirname "${BASH_SOURCE[0]}")/netns_lib.sh"
make_network

if [[ $MODE == secure ]]; then
  # The same deployment with security on: a CA, identities and permissions made from it.
  sed -e "s|^graph: *\(.*\)|graph: $(dirname "$DEPLOY")/\1|" "$DEPLOY" >"$WORK/secure.yaml"
  echo "security: {enabled: true, dir: sec}" >>"$WORK/secure.yaml"
  DEPLOY=$WORK/secure.yaml
  "$AVS" security init "$WORK/sec" --deployment "$DEPLOY" >"$WORK/security_init.log" 2>&1 ||
    { cat "$WORK/security_init.log"; fail "avs security init"; }
fi
"$AVS" deploy check "$DEPLOY" || fail "avs deploy check $DEPLOY"


# --- 1. start C, B, A; delivery ------------------------------------------------------------------
start_host C
start_host B
start_host A
sleep 2
for h in A B C; do
  kill -0 "${LAUNCHER[$h]}" 2>/dev/null || fail "avs launch on host $h ended early"
done
check_delivery 1
check_torque 1 nonzero
for item in $LOST; do
  h=${item%%:*} topic=${item#*:}
  wait_log "$WORK/$h.1.log" "publisher of $topic alive" 10 || fail "host $h did not report $topic's publisher"
done
echo "ok: B and C report A's publishers alive"

# --- 2. kill host A (every process in its namespace, SIGKILL) -------------------------------------
pids=$(ip netns pids "${NS[A]}")
kill -KILL $pids
wait "${LAUNCHER[A]}" 2>/dev/null
echo "killed host A's processes: $(echo $pids)"
for item in $LOST; do
  h=${item%%:*} topic=${item#*:}
  wait_log "$WORK/$h.1.log" "LOST publisher of $topic" 15 || fail "host $h did not report the loss of $topic"
  echo "ok: host $h reports: $(grep -m1 "LOST publisher of $topic" "$WORK/$h.1.log")"
done
check_torque 2 zero
for h in B C; do
  kill -0 "${LAUNCHER[$h]}" 2>/dev/null || fail "host $h's avs launch ended after A died"
  if grep -q "container '.*' \(exited\|killed\)" "$WORK/$h.1.log"; then fail "a container on $h ended after A died"; fi
done
echo "ok: B and C still running"

# --- 3. restart A: recovery without restarting B or C ---------------------------------------------
start_host A 2
for item in $LOST; do
  h=${item%%:*} topic=${item#*:}
  wait_log "$WORK/$h.1.log" "publisher of $topic alive" 20 2 || fail "host $h did not see $topic come back"
done
echo "ok: B and C report A's publishers back"
check_delivery 3
check_torque 3 nonzero
for h in B C; do
  kill -0 "${LAUNCHER[$h]}" 2>/dev/null || fail "host $h's avs launch ended"
  if grep -q "restarted container" "$WORK/$h.1.log"; then fail "a container on $h was restarted"; fi
done
echo "PASS: multi-host deployment ($MODE, $(basename "$DEPLOY")): delivery, loss reported,$( ((TORQUE_CHECK)) && echo " zero torque,") recovery"
exit 0

#!/usr/bin/env bash
# Multi-host test: three "hosts" A, B, C as network namespaces joined by veth pairs to a bridge
# in a fourth ("switch") namespace, private addresses 10.231.0.1-3 that exist only there. Each
# host runs `avs launch DEPLOYMENT --host X` exactly as a real machine would.
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

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; dump_logs; exit 1; }

if [[ $(id -u) -ne 0 ]]; then skip "needs root to create network namespaces (ip netns); CI runs as root"; fi
command -v ip >/dev/null || skip "the 'ip' command (iproute2) is not installed"

TAG=avs$$
SW=${TAG}sw
declare -A NS=([A]=${TAG}A [B]=${TAG}B [C]=${TAG}C)
declare -A ADDR=([A]=10.231.0.1 [B]=10.231.0.2 [C]=10.231.0.3)
declare -A LAUNCHER
WORK=$(mktemp -d /tmp/avs_multihost.XXXXXX)

dump_logs() {
  for h in A B C; do
    for f in "$WORK"/$h*.log; do
      [[ -f $f ]] || continue
      echo "----- $(basename "$f") (last 30 lines)"
      tail -n 30 "$f"
    done
  done
}

cleanup() {
  for h in A B C; do
    local pids
    pids=$(ip netns pids "${NS[$h]}" 2>/dev/null)
    [[ -n $pids ]] && kill -TERM $pids 2>/dev/null
  done
  sleep 1
  for h in A B C; do
    local pids
    pids=$(ip netns pids "${NS[$h]}" 2>/dev/null)
    [[ -n $pids ]] && kill -KILL $pids 2>/dev/null
  done
  for n in "${NS[@]}" "$SW"; do ip netns del "$n" 2>/dev/null; done
  [[ -n ${KEEP_WORK:-} ]] && echo "logs kept in $WORK" || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# --- the network: bridge in the switch namespace, one veth pair per host ----------------------
ip netns add "$SW" 2>"$WORK/netns.err" || skip "cannot create a network namespace: $(cat "$WORK/netns.err")"
ip -n "$SW" link add br0 type bridge || skip "cannot create a bridge in a namespace"
ip -n "$SW" link set br0 type bridge mcast_snooping 0 2>/dev/null  # flood multicast to every port
ip -n "$SW" link set br0 up
for h in A B C; do
  ip netns add "${NS[$h]}" || fail "ip netns add ${NS[$h]}"
  ip link add eth0 netns "${NS[$h]}" type veth peer name "port$h" netns "$SW" || fail "veth for $h"
  ip -n "${NS[$h]}" addr add "${ADDR[$h]}/24" dev eth0
  ip -n "${NS[$h]}" link set eth0 up
  ip -n "${NS[$h]}" link set lo up
  ip -n "$SW" link set "port$h" master br0 up
  # Unicast mode: no multicast on the hosts' links at all, so discovery must use the peers.
  [[ $MODE == unicast ]] && ip -n "${NS[$h]}" link set eth0 multicast off
done
# (no ping on minimal systems: delivery below proves connectivity)

if [[ $MODE == secure ]]; then
  # The same deployment with security on: a CA, identities and permissions made from it.
  sed -e "s|^graph: *\(.*\)|graph: $(dirname "$DEPLOY")/\1|" "$DEPLOY" >"$WORK/secure.yaml"
  echo "security: {enabled: true, dir: sec}" >>"$WORK/secure.yaml"
  DEPLOY=$WORK/secure.yaml
  "$AVS" security init "$WORK/sec" --deployment "$DEPLOY" >"$WORK/security_init.log" 2>&1 ||
    { cat "$WORK/security_init.log"; fail "avs security init"; }
fi
"$AVS" deploy check "$DEPLOY" || fail "avs deploy check $DEPLOY"

# --- helpers -------------------------------------------------------------------------------------
start_host() {  # start_host H: avs launch DEPLOY --host H in H's namespace
  local h=$1 n=${2:-1}
  ip netns exec "${NS[$h]}" "$AVS" launch "$DEPLOY" --host "$h" >"$WORK/$h.$n.log" 2>&1 &
  LAUNCHER[$h]=$!
}

in_host() {  # in_host H CMD...: a tool on host H with the deployment's DDS settings
  local h=$1
  shift
  ip netns exec "${NS[$h]}" bash -c "eval \"\$('$AVS' deploy env '$DEPLOY' --host $h)\" && exec \"\$@\"" _ "$@"
}

wait_log() {  # wait_log FILE PATTERN SECONDS [COUNT]: PATTERN occurs COUNT times in FILE
  local file=$1 pattern=$2 secs=$3 count=${4:-1}
  local deadline=$((SECONDS + secs))
  while ((SECONDS < deadline)); do
    (($(grep -c -- "$pattern" "$file" 2>/dev/null) >= count)) && return 0
    sleep 0.2
  done
  return 1
}

torque_of_drive() {  # prints the commanded torques in one /head/drive_status sample on C
  in_host C "$AVS" topic echo /head/drive_status -n 1 --wait 10 2>&1 |
    awk '/commanded_torque_nm/ {printf "%s ", $2}'
}

check_delivery() {  # check_delivery ROUND
  for item in $DELIVERY; do
    local h=${item%%:*} topic=${item#*:}
    in_host "$h" "$AVS" topic echo "$topic" -n 1 --wait 20 >"$WORK/${h}_echo.out" 2>&1 ||
      fail "round $1: no sample of $topic on host $h: $(tail -n 3 "$WORK/${h}_echo.out")"
    echo "ok: round $1: $topic arrives on host $h"
  done
}

check_torque() {  # check_torque ROUND nonzero|zero: up to 5 drive_status samples agree
  local torques nonzero
  ((TORQUE_CHECK)) || return 0
  for attempt in 1 2 3 4 5; do
    torques=$(torque_of_drive)
    [[ -n $torques ]] || fail "round $1: no /head/drive_status from the drive on C"
    nonzero=0
    for t in $torques; do
      awk -v t="$t" 'BEGIN {exit !(t != 0)}' && nonzero=1
    done
    if [[ $2 == nonzero && $nonzero -eq 1 ]] || [[ $2 == zero && $nonzero -eq 0 ]]; then
      echo "ok: round $1: drive on C commands torque [$torques] ($2, sample $attempt)"
      return 0
    fi
    sleep 0.3
  done
  fail "round $1: drive torque is [$torques], expected $2"
}

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

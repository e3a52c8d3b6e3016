# Sourced by the multi-host scripts (multihost.sh, netfaults.sh): three "hosts" A, B, C as
# network namespaces joined by links to a bridge in a fourth ("switch") namespace, private
# addresses 10.231.0.1-3 that exist only there, and the helpers that run and observe
# `avs launch DEPLOYMENT --host X` on them. The caller sets AVS, DEPLOY, MODE (multicast |
# unicast | secure), DELIVERY and TORQUE_CHECK (see multihost.sh) before calling make_network.
# Exit 77 (CTest SKIP_RETURN_CODE) when network namespaces cannot be created.

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; dump_logs; exit 1; }

if [[ $(id -u) -ne 0 ]]; then skip "needs root to create network namespaces (ip netns); CI runs as root"; fi
command -v ip >/dev/null || skip "the 'ip' command (iproute2) is not installed"

TAG=avs$$
SW=${TAG}sw
declare -A NS=([A]=${TAG}A [B]=${TAG}B [C]=${TAG}C)
declare -A ADDR=([A]=10.231.0.1 [B]=10.231.0.2 [C]=10.231.0.3)
declare -A LAUNCHER
declare -A LINK_PID  # host -> pid of its impaired_link.py (hosts made with make_network's list)
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
  for h in "${!LINK_PID[@]}"; do kill -TERM "${LINK_PID[$h]}" 2>/dev/null; done
  for n in "${NS[@]}" "$SW"; do ip netns del "$n" 2>/dev/null; done
  [[ -n ${KEEP_WORK:-} ]] && echo "logs kept in $WORK" || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# make_network [HOST...]: the bridge in the switch namespace and one link per host: a veth pair,
# or, for the HOSTs named, an impaired link (impaired_link.py: loss and delay set at run time
# with set_link H LOSS DELAY_MS).
make_network() {
  local impaired=" $* "
  ip netns add "$SW" 2>"$WORK/netns.err" || skip "cannot create a network namespace: $(cat "$WORK/netns.err")"
  ip -n "$SW" link add br0 type bridge || skip "cannot create a bridge in a namespace"
  ip -n "$SW" link set br0 type bridge mcast_snooping 0 2>/dev/null  # flood multicast to every port
  ip -n "$SW" link set br0 up
  for h in A B C; do
    ip netns add "${NS[$h]}" || fail "ip netns add ${NS[$h]}"
    if [[ $impaired == *" $h "* ]]; then
      # Two TAP devices held by the forwarder (made here, in the caller's namespace, then moved).
      [[ -c /dev/net/tun ]] || skip "no /dev/net/tun for the impaired link"
      python3 "$(dirname "${BASH_SOURCE[0]}")/impaired_link.py" "${TAG}h$h" "${TAG}s$h" \
        "$WORK/link$h.control" "$WORK/link$h.stats" >"$WORK/link$h.log" 2>&1 &
      LINK_PID[$h]=$!
      local deadline=$((SECONDS + 10))
      until ip link show "${TAG}s$h" >/dev/null 2>&1 && ip link show "${TAG}h$h" >/dev/null 2>&1; do
        kill -0 "${LINK_PID[$h]}" 2>/dev/null || fail "impaired link for $h: $(cat "$WORK/link$h.log")"
        ((SECONDS < deadline)) || fail "impaired link for $h: no TAP devices after 10 s"
        sleep 0.1
      done
      ip link set "${TAG}h$h" netns "${NS[$h]}" name eth0 || fail "moving ${TAG}h$h to ${NS[$h]}"
      ip link set "${TAG}s$h" netns "$SW" name "port$h" || fail "moving ${TAG}s$h to the switch"
    else
      ip link add eth0 netns "${NS[$h]}" type veth peer name "port$h" netns "$SW" || fail "veth for $h"
    fi
    ip -n "${NS[$h]}" addr add "${ADDR[$h]}/24" dev eth0
    ip -n "${NS[$h]}" link set eth0 up
    ip -n "${NS[$h]}" link set lo up
    ip -n "$SW" link set "port$h" master br0 up
    # Unicast mode: no multicast on the hosts' links at all, so discovery must use the peers.
    if [[ $MODE == unicast ]]; then ip -n "${NS[$h]}" link set eth0 multicast off; fi
  done
  # (no ping on minimal systems: delivery below proves connectivity)
}

set_link() {  # set_link H LOSS DELAY_MS: the impairment of H's link from now on
  echo "loss=$2 delay_ms=$3" >"$WORK/link$1.control.tmp" && mv "$WORK/link$1.control.tmp" "$WORK/link$1.control"
}

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


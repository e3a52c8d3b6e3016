#!/usr/bin/env bash
# The e-stop from the shell while the whole closed loop runs (issue 18 section 2): the paper's
# loop of launch_config/closed_loop.yaml (renderer, decode, tracking, servo drive over Modbus,
# matching) in sim-time lockstep; `avs topic pub /head/estop std_msgs/msg/Bool '{data: true}'
# --once` from another process. The drive cycle that sees it and every one after it until the
# release writes zero torque (within one drive period, 1 ms); '{data: false}' releases it and
# tracking's commands are applied again within 10 ms of sim time. Only sim-time figures are
# checked: how many cycles pass between the shell's commands depends on the machine.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
start_lockstep "$out/drive" "$src/launch_config/closed_loop.yaml" run_dir:="$out/run" \
  drive_report_dir:="$out/drive" duration_s:=0
pub() {
  "$avs" topic pub /head/estop std_msgs/msg/Bool "$1" --once --wait 60 >"$out/pub.txt" 2>&1 ||
    { cat "$out/pub.txt" "$live_log" >&2; fail "avs topic pub $1"; }
  cat "$out/pub.txt"
}
wait_for "connected: tcp"
# Tracking drives the head before the e-stop: 20 target observations (40 ms of sim time) first.
"$avs" topic echo /target -n 20 --wait 120 >"$out/target.txt" 2>&1 ||
  { cat "$out/target.txt" "$live_log" >&2; fail "no /target from the closed loop"; }
pub '{data: true}'
grep -q "with reliable, transient_local, keep_last 1 (what the subscribers need)" "$out/pub.txt" ||
  fail "avs topic pub did not choose transient_local for /head/estop"
wait_for "e-stop engaged"
sleep 2
pub '{data: false}'
wait_for "e-stop released"
sleep 3  # cycles after the release (at least 10 ms of sim time even under a sanitizer)
stop_lockstep
csv="$out/drive/drive.csv"
[ -s "$csv" ] || { cat "$live_log" >&2; fail "no drive report"; }
pan=$(column "$csv" pan_cmd_nm); tilt=$(column "$csv" tilt_cmd_nm)
on=$(awk -F, 'NR>1 && $4==1 {print $1; exit}' "$csv")
off=$(awk -F, 'NR>1 && $4==1 {t=$1} END {print t}' "$csv")
[ -n "$on" ] || fail "the drive never saw the e-stop"
echo "e-stop seen by the drive from t = $on s to $off s (sim time)"
# Tracking drove the head before the e-stop (else zero torque would prove nothing).
awk -F, -v on="$on" -v p="$pan" -v t="$tilt" \
  'NR>1 && $1<on && ($p!=0 || $t!=0) {n++} END {exit !(n>0)}' "$csv" ||
  fail "no torque applied before the e-stop: tracking never commanded the head"
# The cycle that sees the e-stop and every cycle while it is engaged: zero torque.
awk -F, -v p="$pan" -v t="$tilt" 'NR>1 && $4==1 && ($p!=0 || $t!=0) {
  print "FAIL: torque during e-stop: " $0; bad=1; exit} END {exit bad}' "$csv"
back=$(awk -F, -v off="$off" -v p="$pan" -v t="$tilt" \
  'NR>1 && $1>off && ($p!=0 || $t!=0) {print $1; exit}' "$csv")
[ -n "$back" ] || fail "tracking's commands not applied after the release"
echo "torque again at t = $back s after the release (last e-stop cycle $off s)"
awk -v t="$back" -v off="$off" 'BEGIN {exit !(t <= off + 0.01)}' || fail "re-enable took too long: $back"
echo PASS

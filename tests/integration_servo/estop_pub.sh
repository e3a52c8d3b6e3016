#!/usr/bin/env bash
# The e-stop from the shell (issue 18 section 2): while the lockstep head graph runs, `avs topic
# pub /head/estop std_msgs/msg/Bool '{data: true}' --once` from another process, with the QoS
# the drive's transient-local subscriber needs (chosen by avs topic pub, not given). Every drive
# cycle from the one that sees it has zero commanded torque; '{data: false}' releases it and the
# commands are followed again within 10 ms of sim time.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
launch=
trap '[ -n "$launch" ] && kill -INT "$launch" 2>/dev/null; rm -rf "$out"' EXIT
mkdir -p "$out/a"
"$avs" launch "$graph" port:=$port report_dir:="$out/a" duration_s:=0 "torque_nm:=[0.05, 0.01]" \
  step_at_s:=0.05 step_until_s:=1000000 2>"$out/a/stderr.txt" &
launch=$!
pub() {
  "$avs" topic pub /head/estop std_msgs/msg/Bool "$1" --once --wait 30 >"$out/pub.txt" 2>&1 ||
    { cat "$out/pub.txt" "$out/a/stderr.txt" >&2; fail "avs topic pub $1"; }
  cat "$out/pub.txt"
}
sleep 1
pub '{data: true}'
grep -q "with reliable, transient_local, keep_last 1 (what the subscribers need)" "$out/pub.txt" ||
  fail "avs topic pub did not choose transient_local for /head/estop"
sleep 1
pub '{data: false}'
sleep 1
kill -INT "$launch"
wait "$launch" || { cat "$out/a/stderr.txt" >&2; fail "the head graph failed"; }
launch=
csv="$out/a/drive.csv"
on=$(awk -F, 'NR>1 && $4==1 {print $1; exit}' "$csv")
off=$(awk -F, 'NR>1 && $4==1 {t=$1} END {print t}' "$csv")
[ -n "$on" ] || fail "the drive never saw the e-stop"
echo "e-stop seen by the drive from t = $on s to $off s (sim time)"
awk -F, -v on="$on" 'NR>1 && $1>=on-0.01 && $1<on && ($5!=0.05 || $10!=0.01) {print "FAIL: no torque before the e-stop: " $0; exit 1}' "$csv"
# The cycle that sees the e-stop and every cycle while it is engaged: zero torque.
awk -F, 'NR>1 && $4==1 && ($5!=0 || $10!=0) {print "FAIL: torque during e-stop: " $0; exit 1}' "$csv"
back=$(awk -F, -v off="$off" 'NR>1 && $1>off && $5==0.05 && $10==0.01 {print $1; exit}' "$csv")
[ -n "$back" ] || fail "commands not followed after the release"
echo "torque again at t = $back s after the release (last e-stop cycle $off s)"
awk -v t="$back" -v off="$off" 'BEGIN {exit !(t <= off + 0.01)}' || fail "re-enable took too long: $back"
echo PASS

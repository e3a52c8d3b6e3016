#!/usr/bin/env bash
# E-stop (/head/estop true at 0.2 s, false at 0.3 s, from test_torque_step): zero commanded
# torque from the next control cycle (within one period), zero applied torque at the plant
# from the next plant step, commands followed again after the release.
# Then live (realtime sim time): the e-stop engaged and released by `avs head estop on|off`
# from another process, with the port's QoS (transient local).
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap '[ -n "$launch_pid" ] && kill "$launch_pid" 2>/dev/null; rm -rf "$out"' EXIT
run_head "$out/a" duration_s:=0.4 "torque_nm:=[0.05, 0.01]" step_at_s:=0.05 step_until_s:=10 \
  estop_at_s:=0.2 estop_release_s:=0.3
csv="$out/a/drive.csv"
awk -F, 'NR>1 && $1>=0.15 && $1<=0.2 && ($5!=0.05 || $10!=0.01) {print "FAIL: no torque before the e-stop: " $0; exit 1}' "$csv"
# The first cycle after the e-stop (0.201 s) and every cycle while it is engaged: torque 0.
awk -F, 'NR>1 && $1>0.2 && $1<=0.3005 && ($4!=1 || $5!=0 || $10!=0) {print "FAIL: torque during e-stop: " $0; exit 1}' "$csv"
awk -F, 'NR>1 && $1>0.2015 && $1<=0.3015 && ($4!=0 || $7!=0) {print "FAIL: plant torque during e-stop: " $0; exit 1}' "$out/a/recorder_sim.csv"
back=$(awk -F, 'NR>1 && $1>0.3 && $5==0.05 && $10==0.01 {print $1; exit}' "$csv")
[ -n "$back" ] || fail "commands not followed after the release"
echo "torque again at t = $back s after the release at 0.3 s"
awk -v t="$back" 'BEGIN {exit !(t <= 0.31)}' || fail "re-enable took too long: $back"

start_live "$out/live" duration_s:=120 "torque_nm:=[0.05, 0.01]" step_at_s:=0.05 step_until_s:=1000
"$avs" head estop on --wait 20 || fail "avs head estop on failed"
wait_for "e-stop engaged"
"$avs" head estop off --wait 20 || fail "avs head estop off failed"
wait_for "e-stop released"
sleep 0.5  # a few hundred cycles of torque after the release, for the check below
stop_live
csv="$out/live/drive.csv"
[ -s "$csv" ] || fail "no report from the live run"
engaged=$(awk -F, 'NR>1 && $4==1 {print $1; exit}' "$csv")
[ -n "$engaged" ] || fail "live run: the e-stop never shows in $csv"
awk -F, 'NR>1 && $4==1 && ($5!=0 || $10!=0) {print "FAIL: torque during live e-stop: " $0; exit 1}' "$csv"
last=$(awk -F, 'NR>1 && $4==1 {t=$1} END {print t}' "$csv")
back=$(awk -F, -v l="$last" 'NR>1 && $1>l && $5==0.05 {print $1; exit}' "$csv")
[ -n "$back" ] || fail "live run: no torque after avs head estop off"
echo "live: e-stop from t = $engaged s to $last s, torque again at t = $back s"
echo PASS

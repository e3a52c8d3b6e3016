#!/usr/bin/env bash
# The amplifiers stop answering at t = 0.2 s (sim_amplifier's silent_from_s) and answer again
# at 0.25 s. servo_drive must report a link fault with zero commanded torque within two
# control periods, keep torque at zero while the link is down (the drive's own watchdog
# removes the applied torque within its 2 ms timeout), reconnect, reset the watchdog fault
# (auto_fault_reset) and follow commands again. The run is repeated: identical reports.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# Small torques (below Coulomb friction: the head stays still), on for the whole run.
args=(duration_s:=0.6 "torque_nm:=[0.05, 0.01]" step_at_s:=0.05 step_until_s:=10
      silent_from_s:=0.2 silent_until_s:=0.25)
run_head "$out/a" "${args[@]}"
run_head "$out/b" "${args[@]}"
for f in drive.csv drive.yaml recorder_sim.csv; do
  cmp -s "$out/a/$f" "$out/b/$f" || fail "$f differs between runs"
done
cat "$out/a/drive.yaml"
csv="$out/a/drive.csv"
# 1. Healthy and commanding torque just before the silence.
awk -F, 'NR>1 && $1>=0.15 && $1<0.2 && ($2!=1 || $3!=0 || $5!=0.05 || $10!=0.01) {print "FAIL: not healthy before the silence: " $0; exit 1}' "$csv"
# 2. Fault reported with zero torque within two periods (cycles at 0.200 or 0.201).
first=$(awk -F, 'NR>1 && $3==1 {print $1; exit}' "$csv")
echo "first fault at t = $first s (silent from 0.2 s)"
awk -v t="$first" 'BEGIN {exit !(t >= 0.2 && t <= 0.2015)}' || fail "fault not reported within 2 periods: $first"
# 3. While faulted, every commanded torque is zero.
awk -F, 'NR>1 && $3==1 && ($5!=0 || $10!=0) {print "FAIL: torque commanded during a fault: " $0; exit 1}' "$csv"
# 4. The drive side removes the applied torque (watchdog) within 2 ms + one plant step.
awk -F, 'NR>1 && $1>=0.2035 && $1<0.25 && ($4!=0 || $7!=0) {print "FAIL: torque still applied while silent: " $0; exit 1}' "$out/a/recorder_sim.csv"
# 5. Recovery: healthy again and following the command before the end, and it stays so.
back=$(awk -F, 'NR>1 && $1>0.25 && $2==1 && $3==0 && $5==0.05 {print $1; exit}' "$csv")
[ -n "$back" ] || fail "no recovery after the silence"
echo "following commands again at t = $back s"
awk -F, -v t="$back" 'NR>1 && $1>=t && ($3!=0 || $5!=0.05) {print "FAIL: relapse after recovery: " $0; exit 1}' "$csv"
[ "$(value "$out/a/drive.yaml" timeouts)" -ge 1 ] || fail "no timeout counted"
[ "$(value "$out/a/drive.yaml" reconnects)" -ge 1 ] || fail "no reconnect counted"
grep -q "0x8130" "$out/a/stderr.txt" || fail "the drive's watchdog fault was not reported"
echo PASS

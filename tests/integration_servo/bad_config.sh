#!/usr/bin/env bash
# A bad register map (unknown register name, bad word order value, or a word order that the
# drive's probe register contradicts) must stop servo_drive from loading: exactly one error
# line naming the problem, and a non-zero exit status.
set -uo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
check() {  # file, expected text
  local f="$src/tests/integration_servo/data/bad/$1"
  err=$("$avs" launch "$graph" port:=$port duration_s:=0.05 register_map:="$f" 2>&1 >/dev/null); status=$?
  [ $status -ne 0 ] || fail "$1: exit status 0"
  errors=$(printf '%s\n' "$err" | grep -c '\[ERROR\]')
  [ "$errors" -eq 1 ] || fail "$1: expected one error line, got $errors: $err"
  line=$(printf '%s\n' "$err" | grep '\[ERROR\]')
  printf '%s\n' "$line" | grep -q -- "$2" || fail "$1: error does not say '$2': $line"
  echo "ok  $1: $line"
}
check unknown_register.yaml "unknown_register.yaml:7:3: unknown register 'torque_demand'"
check bad_word_order.yaml "bad_word_order.yaml:8:70: register velocity_actual: bad word_order 'middle'"
check word_order_mismatch.yaml "word_order_probe reads 0x56781234, expected 0x12345678"
echo PASS

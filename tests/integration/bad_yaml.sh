#!/usr/bin/env bash
# Every bad graph in tests/integration/data/bad/ must give exactly one `file:line:column: error:`
# line from `avs launch`, a non-zero exit status, and start nothing.
set -uo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
shopt -s nullglob
files=("$src"/tests/integration/data/bad/*.yaml)
[ ${#files[@]} -gt 0 ] || fail "no bad YAML files found"
for f in "${files[@]}"; do
  err=$("$avs" launch "$f" 2>&1 >/dev/null); status=$?
  lines=$(printf '%s\n' "$err" | grep -c .)
  [ $status -ne 0 ] || fail "$f: exit status 0"
  [ "$lines" -eq 1 ] || fail "$f: expected one line, got $lines: $err"
  printf '%s\n' "$err" | grep -Eq '^[^:]+\.yaml:[0-9]+:[0-9]+: error: ' || fail "$f: not file:line:column: $err"
  printf '%s\n' "$err" | grep -q "started container" && fail "$f: something was started"
  echo "ok  $(basename "$f"): $err"
done
echo PASS

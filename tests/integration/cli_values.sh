#!/usr/bin/env bash
# Issue 20 section 2, command line: an unknown command is named with the list of commands; NaN,
# infinite and out-of-range numbers are refused with the option's name (they used to wait or
# spin forever); Ctrl-C ends a topic command while it waits for a publisher.
set -uo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
refused() {  # refused "what the error must say" ARGS...: exit status 2..109 and the message
  local want=$1; shift
  local err status
  err=$(timeout 10 "$avs" "$@" 2>&1 >/dev/null); status=$?
  ((status != 0 && status != 124)) || fail "avs $* was accepted (status $status)"
  ((status < 128)) || fail "avs $* died of signal $((status - 128)) instead of refusing"
  grep -qF -- "$want" <<<"$err" || fail "avs $*: expected '$want' in: $err"
  echo "ok: avs $* -> $(head -n 1 <<<"$err")"
}
refused "unknown command 'nosuchcmd'; commands: demo" nosuchcmd
# A bad AVS_DOMAIN_ID is read while the commands are built: it used to abort (status 134).
AVS_DOMAIN_ID=999 refused "avs: AVS_DOMAIN_ID must be a domain id in [0, 232], got '999'" topic list
refused "--wait: a finite number is needed, got nan" topic echo /chatter --wait nan
refused "--wait: Value -1 not in range" topic hz /chatter --wait -1
refused "--rate: a finite number is needed, got inf" bag play none.mcap --rate inf
refused "--domain: Value 300 not in range" topic list --domain 300
refused "--width: Value 100000 not in range" patterns --width 100000 --out /nonexistent
refused "--seconds: a finite number is needed, got inf" demo --seconds inf
refused "--max-gap: Value 0 not in range" bag play none.mcap --max-gap 0
# Counts, windows, levels and durations that were accepted (an audit of issue 20, 2026-12-06).
refused "--count: Value -5 not in range" topic echo /chatter -n -5
refused "--window: Value 0 not in range" topic hz /chatter --window 0
refused "--compression-level: Value 99999 not in range" bag record /chatter -o /tmp/x.mcap --compression-level 99999
refused "--duration: Value -1 not in range" view --duration -1
refused "--queue-depth: Value 0 not in range" view --queue-depth 0
refused "--view-port: Value 70000 not in range" demo --view --view-port 70000
refused "--bits: Value 40 not in range" patterns --bits 40 --out /nonexistent
refused "--first-row: Value -3 not in range" patterns --first-row -3 --out /nonexistent
if "$avs" calib --help 2>/dev/null | grep -q capture; then
  refused "--generate: Value 0 not in range" calib capture --generate 0 --out /nonexistent
  refused "--near: Value -1 not in range" calib capture --generate 4 --near -1 --out /nonexistent
  refused "--noise: Value 1e6 not in range" calib bench --noise 1e6
  refused "--min-coverage: Value 2 not in range" calib solve /nonexistent --out x.yaml --min-coverage 2
fi
# Every numeric option of every command and subcommand shows its range in --help (CLI11's
# type name becomes "INT in [a, b]" with check_range): none is accepted unchecked.
unranged=
for c in $("$avs" --help | awk '/^Subcommands:/{f=1; next} f && NF {print $1}'); do
  subs=$("$avs" "$c" --help 2>/dev/null | awk '/^Subcommands:/{f=1; next} f && NF {print $1}')
  for s in ${subs:-""}; do
    # shellcheck disable=SC2086
    lines=$("$avs" "$c" $s --help 2>/dev/null | grep -E ' (INT|UINT|FLOAT)( |=|$)' | grep -v ' in \[') || true
    [ -n "$lines" ] && unranged+="avs $c $s:"$'\n'"$lines"$'\n'
  done
done
[ -z "$unranged" ] || fail "numeric options without a range:"$'\n'"$unranged"
echo "ok: every numeric option of every command has a range"
# The benchmarks' own options (bench::Options): the benchmark, option and range, never "stod".
if "$avs" bench 2>/dev/null | grep -q '^servo'; then
  refused "avs bench servo: --rate wants a number in [1, 100000], got 'abc'" bench servo --rate abc
  refused "avs bench sim: --frames wants an integer in [10, 1000000], got '2.5'" bench sim --frames=2.5
  refused "avs bench matching: --poses wants an integer in [1, 100000], got 'nan'" bench matching --poses nan
  refused "avs bench bag: --duration wants a number in [0.1, 3600], got '-1'" bench bag --duration=-1
  refused "avs bench servo: unknown option --sconds" bench servo --sconds=3
  refused "avs bench servo: --sched-fifo wants an integer in [0, 99], got '100'" bench servo --sched-fifo 100
  # The policy the servo bench ran under is the one reported: SCHED_FIFO where this process may
  # set it, else one line saying it was refused and the figures are SCHED_OTHER's.
  err=$(mktemp)
  json=$(timeout 30 "$avs" bench servo --seconds 0.1 --sched-fifo 10 --json 2>"$err") ||
    fail "avs bench servo --sched-fifo 10 failed: $(cat "$err")"
  if chrt -f 10 true 2>/dev/null; then
    grep -qF '"sched_fifo_priority": 10' <<<"$json" || fail "--sched-fifo 10 not in force: $json"
  else
    grep -qF '"sched_fifo_priority": 0' <<<"$json" || fail "--sched-fifo refused yet: $json"
    grep -q "not permitted" "$err" || fail "--sched-fifo refused without a word: $(cat "$err")"
  fi
  rm -f "$err"
  echo "ok: avs bench servo --sched-fifo reports the policy in force"
  # `avs bench NAME --help` is the benchmark's help, not `avs bench`'s, and runs nothing.
  help=$(timeout 10 "$avs" bench servo --help) || fail "avs bench servo --help failed"
  grep -qF -- "--seconds N                 a number in [0.1, 3600] (default 3)" <<<"$help" ||
    fail "avs bench servo --help: $help"
  help=$(timeout 10 "$avs" bench decode -h) || fail "avs bench decode -h failed"
  grep -qF -- "--updates N" <<<"$help" || fail "avs bench decode -h: $help"
  echo "ok: avs bench NAME --help lists the benchmark's options"
fi

"$avs" topic echo /no_such_topic --wait 60 >/dev/null 2>&1 &
pid=$!
sleep 1
kill -INT "$pid"
for _ in $(seq 30); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$pid" 2>/dev/null; then kill -9 "$pid"; fail "Ctrl-C did not end 'topic echo --wait 60' within 3 s"; fi
echo "ok: Ctrl-C ends the wait for a publisher"
echo PASS

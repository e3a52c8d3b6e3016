#!/usr/bin/env bash
# Security test (issue 8 item 3), on loopback with DDS Security on from the deployment:
#   1. `avs security init` makes a CA, identities and signed documents from the deployment;
#   2. the authorised reader ("observer") receives the torque commands;
#   3. a participant without security, and one whose identity comes from another CA, read
#      nothing;
#   4. an authenticated identity without a publish grant cannot write torque commands (its
#      writer is refused), and neither a writer without security nor one whose identity comes
#      from another CA reaches a secure reader;
#   5. on the wire: a known plaintext marker in every command is in the UDP payloads of a
#      plain run and in none of a secure one.
# Usage: security.sh AVS SOURCE_DIR.  Exit 77 when Cyclone's security plugins are missing.
set -u
AVS=${1:?avs binary}
SRC=${2:?source dir}
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"  # AVS_DOMAIN_ID of its own
DOMAIN=${AVS_DOMAIN_ID:-173}
MARKER=avsPlainMarker7
W=$(mktemp -d /tmp/avs_security.XXXXXX)
PIDS=()

fail() { echo "FAIL: $*"; for f in "$W"/*.log; do echo "----- $f"; tail -n 20 "$f"; done; exit 1; }
cleanup() {
  for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done
  sleep 0.5
  for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done
  rm -rf "$W"
}
trap cleanup EXIT

plugins=$(ls /usr/lib/*/libddsc0debian/libdds_security_auth.so 2>/dev/null)
[[ -n $plugins ]] || { echo "SKIPPED: Cyclone's DDS security plugins (libdds_security_*.so) are not installed"; exit 77; }
command -v openssl >/dev/null || { echo "SKIPPED: openssl is not installed"; exit 77; }

deployment() {  # deployment FILE SECURITY_DIR|none
  {
    echo "graph: $SRC/tests/deploy/data/secure_graph.yaml"
    echo "domain_id: $DOMAIN"
    echo "discovery: {multicast: false, lease_duration_s: 2}"
    [[ $2 != none ]] && echo "security: {enabled: true, dir: $2}"
    echo "hosts:"
    echo "  - {name: local, interface: lo, address: 127.0.0.1, containers: [commands]}"
  } >"$1"
}
deployment "$W/secure.yaml" "$W/sec"
deployment "$W/plain.yaml" none
deployment "$W/intruder.yaml" "$W/intruder"

echo_with() {  # echo_with DEPLOYMENT PARTICIPANT WAIT_S: one torque command, as YAML
  bash -c "eval \"\$('$AVS' deploy env '$1' --host local --participant $2)\" &&
           exec '$AVS' topic echo /head/torque_command -n 1 --wait $3" 2>&1
}

# 1. security init from the deployment
"$AVS" security init "$W/sec" --deployment "$W/secure.yaml" >"$W/init.log" 2>&1 || fail "avs security init"
for f in ca_cert.pem governance.p7s permissions.p7s identities/commands/cert.pem identities/observer/key.pem; do
  [[ -s $W/sec/$f ]] || fail "avs security init made no $f"
done
grep -q "commands: publish.*rt/head/torque_command" "$W/init.log" || fail "commands may not publish torque"
grep -q "observer: publish (nothing)" "$W/init.log" || fail "observer may publish"
openssl smime -verify -in "$W/sec/permissions.p7s" -CAfile "$W/sec/ca_cert.pem" >/dev/null 2>&1 ||
  fail "permissions.p7s does not verify against the CA"
"$AVS" security init "$W/intruder" --deployment "$W/secure.yaml" >/dev/null 2>&1 || fail "second CA"
echo "ok: CA, identities, signed governance and permissions"

# 2. secure source; the authorised reader gets commands (and the wire shows no marker)
"$AVS" launch "$W/secure.yaml" --host local >"$W/secure_launch.log" 2>&1 &
PIDS+=($!)
out=$(echo_with "$W/secure.yaml" observer 20)
grep -q "$MARKER" <<<"$out" || fail "the authorised reader got no torque command: $out"
echo "ok: authorised reader (observer) receives /head/torque_command"

bash -c "eval \"\$('$AVS' deploy env '$W/secure.yaml' --host local)\" &&
         exec '$AVS' topic echo /head/torque_command --duration 6 --wait 10" >"$W/secure_reader.log" 2>&1 &
PIDS+=($!)
sleep 2
secure=$(python3 "$SRC/tests/deploy/sniff.py" lo 3 "$MARKER")
echo "secure run on lo: $secure"

# 3. no security, or another CA: nothing to read
out=$(echo_with "$W/plain.yaml" observer 8) && fail "a participant without security read torque commands: $out"
grep -q "$MARKER" <<<"$out" && fail "a participant without security saw the marker"
echo "ok: participant without security reads nothing ($(tail -n 1 <<<"$out"))"
out=$(echo_with "$W/intruder.yaml" observer 8) && fail "an identity from another CA read torque commands: $out"
echo "ok: identity from another CA reads nothing ($(tail -n 1 <<<"$out"))"

# 4. writers: an authenticated identity without a publish grant, and a plain participant
kill -TERM "${PIDS[0]}"
wait "${PIDS[0]}" 2>/dev/null
timeout 20 bash -c "eval \"\$('$AVS' deploy env '$W/secure.yaml' --host local --participant observer)\" &&
  exec '$AVS' container '$SRC/tests/deploy/data/secure_graph.yaml' --name commands" >"$W/rogue.log" 2>&1
rc=$?
((rc != 0 && rc != 124)) || fail "the observer identity ran a torque source (status $rc)"
grep -qi "torque_command" "$W/rogue.log" || fail "the refused writer is not named: $(tail -n 3 "$W/rogue.log")"
echo "ok: identity without a publish grant cannot create a torque writer: $(grep -i -m1 "torque_command" "$W/rogue.log")"

bash -c "eval \"\$('$AVS' deploy env '$W/plain.yaml' --host local)\" &&
  exec '$AVS' container '$SRC/tests/deploy/data/secure_graph.yaml' --name commands marker:=avsRogue9" >"$W/plain_writer.log" 2>&1 &
PIDS+=($!)
sleep 1
out=$(echo_with "$W/secure.yaml" observer 8) && fail "a plain writer reached the secure reader: $out"
grep -q avsRogue9 <<<"$out" && fail "a plain writer's command reached the secure reader"
echo "ok: a writer without security does not reach the secure reader"
kill -TERM "${PIDS[-1]}" 2>/dev/null

bash -c "eval \"\$('$AVS' deploy env '$W/intruder.yaml' --host local --participant commands)\" &&
  exec '$AVS' container '$SRC/tests/deploy/data/secure_graph.yaml' --name commands marker:=avsIntruder3" >"$W/intruder_writer.log" 2>&1 &
PIDS+=($!)
sleep 1
out=$(echo_with "$W/secure.yaml" observer 8) && fail "a writer with another CA's identity reached the secure reader: $out"
grep -q avsIntruder3 <<<"$out" && fail "a writer with another CA's identity reached the secure reader"
echo "ok: a writer with an identity from another CA (and its own valid grant) does not reach the secure reader"

# 5. the same traffic without security: the marker is on the wire
kill -TERM "${PIDS[@]}" 2>/dev/null
sleep 1
"$AVS" launch "$W/plain.yaml" --host local >"$W/plain_launch.log" 2>&1 &
PIDS+=($!)
bash -c "eval \"\$('$AVS' deploy env '$W/plain.yaml' --host local)\" &&
         exec '$AVS' topic echo /head/torque_command --duration 8 --wait 10" >"$W/plain_reader.log" 2>&1 &
PIDS+=($!)
sleep 3
plain=$(python3 "$SRC/tests/deploy/sniff.py" lo 3 "$MARKER")
echo "plain run on lo: $plain"
udp_s=${secure#udp=}; udp_s=${udp_s%% *}; hits_s=${secure##*marker=}
udp_p=${plain#udp=}; udp_p=${udp_p%% *}; hits_p=${plain##*marker=}
((udp_p > 100 && hits_p > 100)) || fail "plain run: expected the marker in >100 datagrams, got $plain"
((udp_s > 100)) || fail "secure run: too little traffic captured ($secure)"
((hits_s == 0)) || fail "secure run: the plaintext marker is on the wire ($secure)"
echo "ok: marker in $hits_p of $udp_p plain datagrams, in $hits_s of $udp_s secure ones"
echo "PASS: DDS security"
exit 0

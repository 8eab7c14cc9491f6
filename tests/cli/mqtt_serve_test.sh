#!/usr/bin/env bash
# serve --mqtt against a real broker (mosquitto on loopback, its own config and port): the
# retained online and status topics, commands answered on the reply topic with their id, a
# malformed command refused, a command on another machine's topic never acted on, the last
# will after kill -9, and a broker with passwords that refuses a server without one.
#   mqtt_serve_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && chmod 755 "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
machine="$src/examples/machines/pen_plotter.json"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2> /dev/null; done; wait 2> /dev/null; }
trap cleanup EXIT

. "$src/tests/cli/mosquitto_broker.sh"
sub() { timeout -s KILL 12 mosquitto_sub -p "$port" "$@" < /dev/null; }
# Waits (up to 10 s) until the retained message on a topic matches a pattern: each look
# subscribes anew and gets the retained message at once.
until_retained() {
  local pattern=$1; shift
  for _ in $(seq 50); do
    timeout -s KILL 3 mosquitto_sub -p "$port" "$@" -C 1 -W 2 < /dev/null | grep -q "$pattern" && return 0
    sleep 0.2
  done
  return 1
}

start_broker "allow_anonymous true" || exit 1
"$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --time-scale 10 --exit-after 120 > "$work/device.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
  target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log"); [ -n "$target" ] && break; sleep 0.05
done
"$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 --mqtt "mqtt://127.0.0.1:$port" --name plotter-1 \
  > "$work/serve.log" 2>&1 &
serve_pid=$!
pids+=($serve_pid)
online=$(sub -t pathstream/plotter-1/online -C 1 -W 10)
[[ "$online" == *'"online":true'* && "$online" == *'"name":"plotter-1"'* && "$online" == *'"axes":["x","y"]'* ]] &&
  ok || fail "online: $online ($(cat "$work/serve.log"))"
status=$(sub -t pathstream/plotter-1/status -C 1 -W 10)
[[ "$status" == *'"event":"device"'* && "$status" == *'"state":"idle"'* ]] && ok || fail "status: $status"
grep -q "mqtt          mqtt://127.0.0.1:$port as pathstream/plotter-1/" "$work/serve.log" && ok || fail "serve names the broker: $(cat "$work/serve.log")"

# Commands: subscribe to the replies first, then ask.
sub -t pathstream/plotter-1/reply -C 3 -W 15 > "$work/replies.txt" &
reader=$!
sleep 0.5
mosquitto_pub -p "$port" -t pathstream/plotter-1/command -m '{"id": 7, "verb": "hold"}'
mosquitto_pub -p "$port" -t pathstream/plotter-1/command -m 'not json'
mosquitto_pub -p "$port" -t pathstream/plotter-1/command -m '{"id": "p", "verb": "pen", "down": true}'
# Another machine's topic: nothing may come of it (the reader takes exactly three replies).
mosquitto_pub -p "$port" -t pathstream/plotter-2/command -m '{"id": 99, "verb": "pen", "down": false}'
wait "$reader"
/usr/bin/python3 - "$work/replies.txt" <<'PY' && ok || fail "replies (above): $(cat "$work/replies.txt")"
import json, sys
replies = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
by_id = {r.get("id"): r for r in replies}
bad = []
if len(replies) != 3: bad.append(f"{len(replies)} replies")
h = by_id.get(7, {})
if not (h.get("status") == 422 and h.get("ok") is False and "not allowed in this state" in h.get("error", "")):
    bad.append(f"hold while idle: {h}")
m = by_id.get(None, {})
if not (m.get("status") == 400 and "a command is JSON" in m.get("error", "")): bad.append(f"malformed: {m}")
p = by_id.get("p", {})
if not (p.get("status") == 200 and p.get("ok") is True): bad.append(f"pen down: {p}")
if 99 in by_id: bad.append("a command on plotter-2's topic was answered")
for b in bad: print(b)
sys.exit(1 if bad else 0)
PY
# The status follows at the poller's next read of the device (10 a second): wait for it.
until_retained '"pen_down":true' -t pathstream/plotter-1/status &&
  ok || fail "the pen command never showed in the status"

# The last will: killed without a word, the machine is marked offline by the broker.
kill -9 "$serve_pid"; wait "$serve_pid" 2> /dev/null
# The retained "true" may come first, until the broker notices the closed connection.
until_retained '"online":false' -t pathstream/plotter-1/online &&
  ok || fail "no will (online false) after kill -9"

# A headless machine: stream --mqtt publishes the job's events on its own topics and answers
# commands while it streams; offline once the job has ended.
"$bin" ctl -m "$machine" -- "$target" pen up > /dev/null 2>&1
sub -t pathstream/plotter-h/events -C 400 -W 60 > "$work/stream_events.txt" &
events_reader=$!
sub -t pathstream/plotter-h/reply -C 1 -W 30 > "$work/stream_reply.txt" &
reply_reader=$!
# Every online state as it comes: the stream may be over before a look at the retained one.
sub -t pathstream/plotter-h/online -C 2 -W 30 > "$work/stream_online.txt" &
online_reader=$!
sleep 0.5
"$bin" stream "$src/examples/rose.json" -m "$machine" -t "$target" --no-journal \
  --mqtt "mqtt://127.0.0.1:$port" --name plotter-h > "$work/stream.log" 2>&1 &
stream_pid=$!
# The command goes out until it is answered: those sent before the stream subscribed are
# nobody's, and how soon that is depends on the machine's load.
while kill -0 "$stream_pid" 2> /dev/null && [ ! -s "$work/stream_reply.txt" ]; do
  mosquitto_pub -p "$port" -t pathstream/plotter-h/command -m '{"id": "s1", "verb": "jog", "axis": "q", "distance_mm": 1}'
  sleep 0.1
done
wait "$stream_pid"; rc=$?
[ $rc -eq 0 ] && ok || fail "stream --mqtt: exit $rc $(cat "$work/stream.log")"
wait "$reply_reader"
reply=$(cat "$work/stream_reply.txt")
[[ "$reply" == *'"id":"s1"'* && "$reply" == *"the machine has no axis 'q'"* && "$reply" == *'"status":400'* ]] && ok ||
  fail "a command to the streaming machine: $(cat "$work/stream_reply.txt")"
wait "$online_reader"
[[ "$(head -1 "$work/stream_online.txt")" == *'"online":true'* ]] && ok ||
  fail "stream online: $(cat "$work/stream_online.txt") $(cat "$work/stream.log")"
until_retained '"outcome":"finished"' -t pathstream/plotter-h/job && ok || fail "the job's end on the job topic"
until_retained '"online":false' -t pathstream/plotter-h/online && ok || fail "stream offline after its job"
kill "$events_reader" 2> /dev/null; wait "$events_reader" 2> /dev/null
grep -q '"event":"job_start"' "$work/stream_events.txt" && grep -q '"event":"progress"' "$work/stream_events.txt" &&
  ok || fail "stream events on the broker: $(head -3 "$work/stream_events.txt")"
kill -9 "$broker_pid"; wait "$broker_pid" 2> /dev/null

# A broker with passwords: a server without one is refused, one with a password file let in.
mosquitto_passwd -b -c "$work/passwd" ann s3cret > /dev/null 2>&1 && chmod 644 "$work/passwd"
start_broker "allow_anonymous false
password_file $work/passwd" || exit 1
out=$("$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 --mqtt "mqtt://127.0.0.1:$port" --name p1 2>&1); rc=$?
[ $rc -eq 3 ] && [[ "$out" == *"refused the connection"* ]] && ok || fail "no password: $rc $out"
printf 's3cret\n' > "$work/pw"
"$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 \
  --mqtt "mqtt://ann@127.0.0.1:$port?password_file=$work/pw" --name p1 > "$work/serve2.log" 2>&1 &
pids+=($!)
online=$(sub -u ann -P s3cret -t pathstream/p1/online -C 1 -W 10)
[[ "$online" == *'"online":true'* ]] && ok || fail "with the password file: $online $(cat "$work/serve2.log")"
kill -INT "${pids[-1]}"; wait "${pids[-1]}" 2> /dev/null
until_retained '"online":false' -u ann -P s3cret -t pathstream/p1/online &&
  ok || fail "not offline after a clean stop"
kill -9 "$broker_pid"; wait "$broker_pid" 2> /dev/null

# TLS: a broker with a certificate from a CA of the test's own; mqtts:// with that CA as cafile
# connects, with the system's CAs (which never signed it) it is refused, exit 3.
(cd "$work" &&
  openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=test-ca -keyout ca.key -out ca.pem &&
  openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1 -keyout broker.key -out broker.csr &&
  printf 'subjectAltName=IP:127.0.0.1\n' > san.txt &&
  openssl x509 -req -in broker.csr -CA ca.pem -CAkey ca.key -CAcreateserial -days 2 \
    -extfile san.txt -out broker.pem && chmod 644 ca.pem broker.pem broker.key) > "$work/openssl.log" 2>&1 ||
  fail "openssl: $(tail -3 "$work/openssl.log")"
start_broker "allow_anonymous true
cafile $work/ca.pem
certfile $work/broker.pem
keyfile $work/broker.key" || exit 1
"$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 \
  --mqtt "mqtts://127.0.0.1:$port?cafile=$work/ca.pem" --name tls-1 > "$work/serve_tls.log" 2>&1 &
pids+=($!)
online=$(timeout -s KILL 12 mosquitto_sub -h 127.0.0.1 -p "$port" --cafile "$work/ca.pem" -t pathstream/tls-1/online -C 1 -W 10 < /dev/null)
[[ "$online" == *'"online":true'* ]] && ok || fail "over TLS with the CA: $online $(cat "$work/serve_tls.log")"
kill -INT "${pids[-1]}"; wait "${pids[-1]}" 2> /dev/null
out=$("$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 --mqtt "mqtts://127.0.0.1:$port" \
  --name tls-2 2>&1 < /dev/null); rc=$?
[ $rc -eq 3 ] && [[ "$out" == *"certificate verify failed"* ]] && ok || fail "TLS with a CA that did not sign the broker: $rc $out"
# Plain MQTT to the TLS listener is not spoken either.
out=$(timeout -s KILL 20 "$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 --mqtt "mqtt://127.0.0.1:$port" \
  --name tls-3 2>&1 < /dev/null); rc=$?
[ $rc -eq 3 ] && ok || fail "plain MQTT to a TLS broker: $rc $out"

# Bad options: a name with a topic wildcard, --name without --mqtt.
out=$("$bin" serve -m "$machine" -t "$target" --mqtt "mqtt://127.0.0.1:$port" --name 'a/#' 2>&1); rc=$?
[ $rc -eq 2 ] && [[ "$out" == *"only letters, digits, _ and -"* ]] && ok || fail "bad name: $rc $out"

echo "mqtt_serve_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]

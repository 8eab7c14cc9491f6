#!/usr/bin/env bash
# pathstream fleet against a real broker (mosquitto on loopback, its own config and port), with
# mosquitto_pub standing in for three machines: status and jobs (tables and JSON) from retained
# topics, a malformed message counted and ignored, submit publishing the retained queued state
# and the job message on the right topic, submit --wait exiting as the final state says,
# command getting its reply (a responder answers it), bad values refused (exit 2), a machine
# that does not answer (exit 6), and a broker with passwords refusing a client without one
# (exit 3) while a password file lets it in; end to end, a real serve --mqtt machine (the
# simulated device) taking a job fleet submits and drawing it.
#   fleet_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && chmod 755 "$work"
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2> /dev/null; done; wait 2> /dev/null; }
trap cleanup EXIT

. "$src/tests/cli/mosquitto_broker.sh"
sub() { timeout -s KILL 12 mosquitto_sub -p "$port" "$@" < /dev/null; }
pub() { mosquitto_pub -p "$port" -q 1 "$@"; }
fleet() { timeout -s KILL 30 "$bin" fleet --mqtt "mqtt://127.0.0.1:$port" "$@" < /dev/null; }
# Waits (up to 10 s) until the retained message on a topic matches a pattern.
until_retained() {
  local pattern=$1; shift
  for _ in $(seq 50); do
    timeout -s KILL 3 mosquitto_sub -p "$port" "$@" -C 1 -W 2 < /dev/null | grep -q "$pattern" && return 0
    sleep 0.2
  done
  return 1
}
# Runs a check on a JSON document given on stdin: check_json 'python expression on d' what.
check_json() { /usr/bin/python3 -c "import json,sys; d=json.load(sys.stdin); sys.exit(0 if ($1) else 1)"; }

start_broker "allow_anonymous true" || exit 1

# Three stand-in machines, as serve --mqtt publishes them (retained), and three jobs.
now=$(date +%s)
for m in p1 p2 p3; do
  online=true; [ "$m" = p3 ] && online=false
  pub -r -t "pathstream/$m/online" -m "{\"name\":\"$m\",\"machine\":\"pen_plotter.json\",\"axes\":[\"x\",\"y\"],\"target\":\"t\",\"online\":$online}"
done
pub -r -t pathstream/p1/status -m '{"event":"device","state":"running","pen_down":true,"position_mm":{"x":10.5,"y":20}}'
pub -r -t pathstream/p2/status -m '{"event":"device","state":"idle","pen_down":false,"position_mm":{"x":0,"y":0}}'
pub -r -t pathstream/p1/progress -m '{"event":"progress","fraction":0.456,"eta_s":12.5}'
state() {  # state ID STATE MACHINE [ERROR]: a job state with a two-step history
  local machine=null; [ -n "$3" ] && machine="\"$3\""
  printf '{"id":"%s","state":"%s","machine":%s,"file":"rose.json","at":%s,"error":"%s","history":[{"state":"queued","machine":null,"at":%s},{"state":"%s","machine":%s,"at":%s}]}' \
    "$1" "$2" "$machine" "$now" "${4:-}" "$((now - 5))" "$2" "$machine" "$now"
}
pub -r -t pathstream/jobs/job-a/state -m "$(state job-a running p1)"
pub -r -t pathstream/jobs/job-b/state -m "$(state job-b done p2)"
pub -r -t pathstream/jobs/job-c/state -m "$(state job-c failed p3 'cannot read rose.json')"

out=$(fleet status); rc=$?
[ $rc -eq 0 ] && printf '%s\n' "$out" | grep -Eq '^p1 +yes +running +job-a +45 %' &&
  printf '%s\n' "$out" | grep -Eq '^p2 +yes +idle +- +-' && printf '%s\n' "$out" | grep -Eq '^p3 +no ' &&
  [[ "$out" == *"3 machines"* ]] && ok || fail "status: $rc $out"
fleet status --json > "$work/status.json" 2>&1
check_json 'len(d["machines"]) == 3 and d["machines"][0]["name"] == "p1" and d["machines"][0]["job"] == "job-a" and abs(d["machines"][0]["fraction"] - 0.456) < 1e-9 and d["machines"][0]["position_mm"]["x"] == 10.5 and d["machines"][2]["online"] is False and d["ignored"] == 0' \
  < "$work/status.json" && ok || fail "status --json: $(cat "$work/status.json")"
out=$(fleet jobs); rc=$?
[ $rc -eq 0 ] && printf '%s\n' "$out" | grep -Eq '^job-c +failed +p3 +rose.json .*cannot read rose.json' &&
  printf '%s\n' "$out" | grep -Eq '^job-b: queued [0-9:]+, done on p2 [0-9:]+$' && [[ "$out" == *"3 jobs"* ]] &&
  ok || fail "jobs: $rc $out"
fleet jobs --json > "$work/jobs.json" 2>&1
check_json '{j["id"]: j["state"] for j in d["jobs"]} == {"job-a": "running", "job-b": "done", "job-c": "failed"} and [h["state"] for h in d["jobs"][0]["history"]][0] == "queued"' \
  < "$work/jobs.json" && ok || fail "jobs --json: $(cat "$work/jobs.json")"

# A malformed machine and a malformed job state: counted, ignored, nothing else changes.
pub -r -t pathstream/p4/online -m 'not json'
pub -r -t pathstream/jobs/job-x/state -m '{"state":"exploded"}'
out=$(fleet status); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *"3 machines, 2 malformed messages ignored"* ]] && ok || fail "malformed: $rc $out"
pub -r -t pathstream/p4/online -n
pub -r -t pathstream/jobs/job-x/state -n

# submit to a queue: the retained queued state, then the job message with the drawing.
sub -t pathstream/queue/pen_plotter -C 1 -W 10 > "$work/queued.json" &
reader=$!
sleep 0.5
out=$(fleet submit "$src/examples/rose.json" --kind pen_plotter --id t-1 --fit a4 --margin 5); rc=$?
wait "$reader"
[ $rc -eq 0 ] && [ "$out" = t-1 ] && ok || fail "submit printed: $rc $out"
/usr/bin/python3 - "$work/queued.json" "$src/examples/rose.json" <<'PY' && ok || fail "the job message: $(head -c 300 "$work/queued.json")"
import json, sys
m = json.loads(open(sys.argv[1]).read())
drawing = open(sys.argv[2]).read()
bad = [k for k, want in [("id", "t-1"), ("file", "rose.json"), ("kind", "pen_plotter"),
                         ("options", {"fit": "a4", "margin": 5.0})] if m.get(k) != want]
if m.get("drawing") != drawing: bad.append("drawing")
if not isinstance(m.get("submitted"), (int, float)): bad.append("submitted")
print(bad) if bad else None
sys.exit(1 if bad else 0)
PY
state=$(sub -t pathstream/jobs/t-1/state -C 1 -W 5)
printf '%s' "$state" | check_json 'd["state"] == "queued" and d["machine"] is None and d["file"] == "rose.json" and d["history"][0]["state"] == "queued"' &&
  ok || fail "the retained queued state: $state"
# Without a kind: the queue of any machine; with --machine: that machine's own topic.
sub -t pathstream/queue/any -C 1 -W 10 > "$work/any.json" &
reader=$!
sub -t pathstream/p2/jobs -C 1 -W 10 > "$work/p2.json" &
reader2=$!
sleep 0.5
id_any=$(fleet submit "$src/examples/rose.json")
fleet submit "$src/examples/rose.json" --machine p2 --id to-p2 > /dev/null
wait "$reader" "$reader2"
[[ "$id_any" =~ ^job-[0-9]{8}-[0-9]{6}-[0-9a-f]{4}$ ]] && check_json "d['id'] == '$id_any' and d['kind'] == 'any'" < "$work/any.json" &&
  ok || fail "submit to any: $id_any $(head -c 200 "$work/any.json")"
check_json 'd["id"] == "to-p2" and d["machine"] == "p2"' < "$work/p2.json" && ok || fail "submit --machine: $(head -c 200 "$work/p2.json")"

# Bad values: exit 2 and the reason.
expect() {  # expect CODE TEXT what -- command...
  local code=$1 text=$2 what=$3 out rc; shift 4
  out=$("$@" 2>&1); rc=$?
  [ $rc -eq "$code" ] && [[ "$out" == *"$text"* ]] && ok || fail "$what: exit $rc (want $code): $out"
}
printf 'hello' > "$work/drawing.docx"
expect 2 "1 to 64 of A-Z a-z 0-9 _ -" "a bad id" -- fleet submit "$src/examples/rose.json" --id 'a/b'
expect 2 "no reader knows its extension (.json" "an unknown extension" -- fleet submit "$work/drawing.docx"
expect 2 "no machine named nobody on the broker" "an unknown machine" -- fleet submit "$src/examples/rose.json" --machine nobody
expect 2 "machine p3 is offline: a job sent to it now would not be drawn" "an offline machine" -- fleet submit "$src/examples/rose.json" --machine p3
expect 2 "larger than --max-upload-mb" "too large" -- fleet submit "$src/examples/rose.json" --max-upload-mb 0.001
expect 2 "excludes" "--kind and --machine" -- fleet submit "$src/examples/rose.json" --kind a --machine p1
expect 2 "the scheme must be mqtt or mqtts" "a bad URL" -- "$bin" fleet --mqtt http://x status

# submit --wait: a stand-in machine takes the job from its topic and reports running, then
# done (exit 0) or failed (exit 1 with the error).
machine_runs() {  # machine_runs NAME FINAL [ERROR]: takes one job, reports it
  local name=$1 final=$2 error=${3:-} job id
  job=$(sub -t "pathstream/$name/jobs" -C 1 -W 15)
  id=$(printf '%s' "$job" | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["id"])')
  pub -r -t "pathstream/jobs/$id/state" -m "$(state "$id" running "$name")"
  pub -r -t "pathstream/jobs/$id/progress" -m '{"event":"progress","fraction":0.5,"eta_s":1}'
  sleep 0.3
  pub -r -t "pathstream/jobs/$id/state" -m "$(state "$id" "$final" "$name" "$error")"
}
machine_runs p1 done &
stand_in=$!
sleep 0.5
out=$(fleet submit "$src/examples/rose.json" --machine p1 --id w-1 --wait 2>&1); rc=$?
wait "$stand_in"
[ $rc -eq 0 ] && [[ "$out" == *"w-1 done on p1"* ]] && ok || fail "submit --wait, done: $rc $out"
machine_runs p2 failed 'rose.json: cannot be placed on a4' &
stand_in=$!
sleep 0.5
out=$(fleet submit "$src/examples/rose.json" --machine p2 --id w-2 --wait 2>&1); rc=$?
wait "$stand_in"
[ $rc -eq 1 ] && [[ "$out" == *"pathstream: job w-2 failed on p2: rose.json: cannot be placed on a4"* ]] &&
  ok || fail "submit --wait, failed: $rc $out"
out=$(fleet jobs); [[ "$out" == *"w-2: queued "*", failed on p2 "* ]] && ok || fail "w-2's history: $out"

# command: a responder answers the command's id on the reply topic.
responder() {  # responder NAME STATUS: answers one command
  sub -t "pathstream/$1/command" -C 1 -W 15 |
    /usr/bin/python3 -c 'import json,sys; r=json.loads(sys.stdin.readline()); s=int(sys.argv[1]); print(json.dumps({"id": r["id"], "ok": s == 200, "status": s, "verb": r["verb"], "axis": r.get("axis"), "distance_mm": r.get("distance_mm"), "error": "" if s == 200 else "not allowed in this state"}))' "$2" |
    mosquitto_pub -p "$port" -t "pathstream/$1/reply" -l
}
responder p1 200 &
stand_in=$!
sleep 0.5
out=$(fleet command p1 jog --axis y --distance 2.5); rc=$?
wait "$stand_in"
[ $rc -eq 0 ] && printf '%s' "$out" | check_json 'd["status"] == 200 and d["verb"] == "jog" and d["axis"] == "y" and d["distance_mm"] == 2.5' &&
  ok || fail "command jog: $rc $out"
responder p2 422 &
stand_in=$!
sleep 0.5
expect 6 "machine p2 answered 422: not allowed in this state" "a refused command" -- fleet command p2 hold
wait "$stand_in"
expect 6 "machine p3 did not answer within 0.5 s" "no answer" -- fleet command p3 hold --timeout 0.5
expect 2 "1 to 64 of A-Z a-z 0-9 _ -" "a bad machine name" -- fleet command 'p/#' hold
kill -9 "$broker_pid"; wait "$broker_pid" 2> /dev/null

# A broker with passwords: refused without one (exit 3), let in with a password file.
mosquitto_passwd -b -c "$work/passwd" ann s3cret > /dev/null 2>&1 && chmod 644 "$work/passwd"
start_broker "allow_anonymous false
password_file $work/passwd" || exit 1
expect 3 "refused the connection" "no password" -- fleet status
printf 's3cret\n' > "$work/pw"
out=$(timeout -s KILL 30 "$bin" fleet --mqtt "mqtt://ann@127.0.0.1:$port?password_file=$work/pw" status 2>&1); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *"0 machines"* ]] && ok || fail "with the password file: $rc $out"

# End to end with a real machine on the same broker: the simulated device and serve --mqtt of
# its own kind take the job fleet submits, draw it and report it done.
url="mqtt://ann@127.0.0.1:$port?password_file=$work/pw"
real() { timeout -s KILL 60 "$bin" fleet --mqtt "$url" "$@" < /dev/null; }
machine="$src/examples/machines/pen_plotter.json"
"$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --time-scale 10 --exit-after 110 > "$work/device.log" 2>&1 &
pids+=($!)
for _ in $(seq 200); do
  target=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device.log"); [ -n "$target" ] && break; sleep 0.05
done
"$bin" serve -m "$machine" -t "$target" --listen 127.0.0.1:0 --state-dir "$work/state" --mqtt "$url" \
  --name real-1 --kind fleet-e2e > "$work/serve.log" 2>&1 < /dev/null &
pids+=($!)
until_retained '"state":"idle"' -u ann -P s3cret -t pathstream/real-1/status && ok || fail "real-1 never idle: $(cat "$work/serve.log")"
out=$(real status); [[ "$out" =~ real-1\ +yes\ +idle ]] && ok || fail "status of a real machine: $out"
out=$(real submit "$src/examples/wave.json" --kind fleet-e2e --id e2e-1 --wait 2>&1); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *"e2e-1 done on real-1"* ]] && ok || fail "a real machine's job: $rc $out $(tail -5 "$work/serve.log")"
real jobs --json > "$work/e2e.json"
check_json '[h["state"] for j in d["jobs"] if j["id"] == "e2e-1" for h in j["history"]] == ["queued", "running", "done"]' \
  < "$work/e2e.json" && ok || fail "e2e-1's history: $(cat "$work/e2e.json")"
out=$(real command real-1 pen --pen down); rc=$?
[ $rc -eq 0 ] && [[ "$out" == *'"status":200'* ]] && ok || fail "pen down on real-1: $rc $out"
expect 6 "machine real-1 answered 409" "resume_job with no job" -- real command real-1 resume_job
kill -9 "$broker_pid"; wait "$broker_pid" 2> /dev/null
# No broker at all: exit 3.
expect 3 "cannot reach the broker mqtt://127.0.0.1:$port" "no broker" -- fleet status
# A bad value is exit 2 even then: values are checked before connecting.
expect 2 "1 to 64 of A-Z a-z 0-9 _ -" "a bad id, no broker" -- fleet submit "$src/examples/rose.json" --id 'a/b'

echo "fleet_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]

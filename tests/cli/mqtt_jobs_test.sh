#!/usr/bin/env bash
# The job queue on a real broker: mosquitto on loopback with passwords, three simulated devices
# each with its `serve --mqtt`, twenty jobs (one sent to a machine by name, nineteen to the
# queue of the machines' kind). The host of the machine drawing the named job is killed
# (SIGKILL, its whole process group) in the middle of it while the queue is busy; its job stays
# on it, is published interrupted when the host comes back, and is resumed there. Checked: every
# job ends done, each drawn on exactly one device (the devices' records of every path tick),
# complete and not twice; a command reaches only the machine it names; a client without the
# password is refused.
#   mqtt_jobs_test.sh PATHSTREAM_BINARY SOURCE_DIR WORK_DIR
set -u
bin=$(realpath "$1") src=$(realpath "$2") work=$3
rm -rf "$work" && mkdir -p "$work" && chmod 755 "$work"
cd "$work" || exit 1
failures=0 passed=0
ok() { passed=$((passed + 1)); }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
py=/usr/bin/python3
machine="$src/examples/machines/pen_plotter.json"
pids=()
groups=()
cleanup() {
  for g in "${groups[@]}"; do kill -9 -- "-$g" 2> /dev/null; done
  for p in "${pids[@]}"; do kill -9 "$p" 2> /dev/null; done
  wait 2> /dev/null
}
trap cleanup EXIT

. "$src/tests/cli/mosquitto_broker.sh"
mosquitto_passwd -c -b "$work/passwords" fleet 's3cret pass' > /dev/null 2>&1 || { fail "mosquitto_passwd"; exit 1; }
chmod 644 "$work/passwords"
printf 's3cret pass\n' > "$work/password.txt"
start_broker "allow_anonymous false
password_file $work/passwords" || exit 1
url="mqtt://fleet@127.0.0.1:$port?password_file=$work/password.txt"
auth=(-p "$port" -u fleet -P 's3cret pass')
sub() { timeout -s KILL 12 mosquitto_sub "${auth[@]}" "$@" < /dev/null; }
pub() { mosquitto_pub "${auth[@]}" -q 1 "$@"; }
# Sends a command to machine $1 and writes its reply to $3: the reply's reader subscribes first.
send_command() {
  sub -t "pathstream/$1/reply" -C 1 -W 20 > "$3" &
  local reader=$!
  sleep 0.5
  pub -t "pathstream/$1/command" -m "$2"
  wait $reader
}
# Every job's retained state, one JSON object a line.
states() { timeout -s KILL 5 mosquitto_sub "${auth[@]}" -t 'pathstream/jobs/+/state' -W 1 < /dev/null 2> /dev/null; }
# Waits (up to $2 s) until the python condition $1 over `s` (job id -> state) holds.
until_states() {
  local deadline=$((SECONDS + $2))
  while [ $SECONDS -lt $deadline ]; do
    states > "$work/states.txt"
    $py - "$1" "$work/states.txt" <<'PY' && return 0
import json, sys
s = {}
for line in open(sys.argv[2]):
    try:
        j = json.loads(line)
        s[j["id"]] = j
    except Exception:
        pass
sys.exit(0 if eval(sys.argv[1]) else 1)
PY
    sleep 0.3
  done
  return 1
}

# A client without the password, and one with a wrong one, are refused.
timeout -s KILL 10 mosquitto_sub -p "$port" -t '#' -C 1 -W 3 < /dev/null > /dev/null 2>&1 && fail "no password let in" || ok
timeout -s KILL 10 mosquitto_sub -p "$port" -u fleet -P nope -t '#' -C 1 -W 3 < /dev/null > /dev/null 2>&1 &&
  fail "a wrong password let in" || ok

start_device() {  # start_device K
  "$bin" device -m "$machine" --no-gpio --tcp 127.0.0.1:0 --time-scale 5 --record "$work/record$1.csv" \
    --exit-after 300 > "$work/device$1.log" 2>&1 &
  device_pid[$1]=$!
  pids+=($!)
  for _ in $(seq 200); do
    target[$1]=$(sed -n 's/.*serving \(modbus-tcp:[^ ]*\).*/\1/p' "$work/device$1.log")
    [ -n "${target[$1]}" ] && return 0
    sleep 0.05
  done
  fail "device $1 did not start: $(cat "$work/device$1.log")"
  exit 1
}
start_serve() {  # start_serve K: its own process group, to be killed as a host dies
  setsid "$bin" serve -m "$machine" -t "${target[$1]}" --listen 127.0.0.1:0 --state-dir "$work/state$1" \
    --mqtt "$url" --name "plotter-$1" >> "$work/serve$1.log" 2>&1 < /dev/null &
  serve_pid[$1]=$!
  groups+=($!)
}
declare -a device_pid target serve_pid
for k in 1 2 3; do start_device $k; start_serve $k; done
for k in 1 2 3; do
  online=$(sub -t "pathstream/plotter-$k/online" -C 1 -W 10)
  [[ "$online" == *'"online":true'* && "$online" == *'"kind":"pen_plotter"'* ]] && ok ||
    fail "plotter-$k online: $online ($(cat "$work/serve$k.log"))"
done
# serve with no password for the broker: refused, exit 3, nothing served.
"$bin" serve -m "$machine" -t "${target[1]}" --listen 127.0.0.1:0 --mqtt "mqtt://127.0.0.1:$port" \
  --name intruder > "$work/intruder.log" 2>&1 < /dev/null
rc=$?
[ $rc = 3 ] && grep -q "refused" "$work/intruder.log" && ok || fail "serve without password: exit $rc $(cat "$work/intruder.log")"

# Twenty drawings: job k draws a 15 mm square of its own, five times over (job-00: thirty
# times, long enough to be killed in). Their job messages and the plans that say what each
# must draw.
$py - "$work" <<'PY'
import json, sys, time
work = sys.argv[1]
for k in range(20):
    x, y = 10 + 25 * (k % 5), 10 + 25 * (k // 5)
    square = [[x, y], [x + 15, y], [x + 15, y + 15], [x, y + 15]]
    loops = 30 if k == 0 else 5
    points = square * loops + [square[0]]
    text = json.dumps({"basis": "polyline", "subpaths": [{"points": points}]})
    open(f"{work}/job-{k:02d}.json", "w").write(text)
    job = {"id": f"job-{k:02d}", "file": f"job-{k:02d}.json", "drawing": text,
           "options": {"keep_order": True}, "kind": "pen_plotter", "submitted": time.time()}
    open(f"{work}/job-{k:02d}.msg", "w").write(json.dumps(job))
    queued = {"id": job["id"], "state": "queued", "machine": None, "file": job["file"],
              "at": job["submitted"], "error": "",
              "history": [{"state": "queued", "machine": None, "at": job["submitted"]}]}
    open(f"{work}/job-{k:02d}.queued", "w").write(json.dumps(queued))
PY
for k in $(seq -w 0 19); do
  "$bin" plan "$work/job-$k.json" -m "$machine" --keep-order --out "$work/plan-$k.csv" > /dev/null 2>&1 ||
    fail "plan job-$k"
done

# job-00 to plotter-2 by name; once it draws there, the other nineteen to the queue.
pub -r -t pathstream/jobs/job-00/state -f "$work/job-00.queued"
pub -t pathstream/plotter-2/jobs -f "$work/job-00.msg"
until_states 's.get("job-00", {}).get("state") == "running" and s["job-00"]["machine"] == "plotter-2"' 20 &&
  ok || fail "job-00 running on plotter-2: $(cat "$work/states.txt")"
for k in $(seq -w 1 19); do
  pub -r -t "pathstream/jobs/job-$k/state" -f "$work/job-$k.queued"
  pub -t pathstream/queue/pen_plotter -f "$work/job-$k.msg"
done
# Sent to plotter-2 by name while it is busy: refused there, with the reason.
printf '%s' '{"id":"job-busy","file":"b.json","drawing":"{}"}' > "$work/busy.msg"
pub -t pathstream/plotter-2/jobs -f "$work/busy.msg"
until_states 's.get("job-busy", {}).get("state") == "refused" and "busy" in s["job-busy"]["error"]' 10 &&
  ok || fail "a named job while busy: $(grep job-busy "$work/states.txt")"

# The host of plotter-2 dies in the middle of job-00.
sleep 1
kill -KILL -- "-${serve_pid[2]}"
wait "${serve_pid[2]}" 2> /dev/null
# The broker publishes the will once it sees the connection gone: look until it has.
for _ in $(seq 50); do
  online=$(timeout -s KILL 3 mosquitto_sub "${auth[@]}" -t pathstream/plotter-2/online -C 1 -W 2 < /dev/null)
  [[ "$online" == *'"online":false'* ]] && break
  sleep 0.2
done
[[ "$online" == *'"online":false'* ]] && ok || fail "plotter-2's will: $online"
states > "$work/states.txt"
grep -q '"id":"job-00".*"state":"running"\|"state":"running".*"id":"job-00"' "$work/states.txt" ||
  grep '"job-00"' "$work/states.txt" | grep -q '"running"' && ok || fail "job-00 still running on the broker: $(grep job-00 "$work/states.txt")"
# The other two draw the queue meanwhile; then plotter-2's host comes back, says the job was
# interrupted, and resumes it on the operator's command.
sleep 2
start_serve 2
until_states 's.get("job-00", {}).get("state") == "interrupted" and s["job-00"]["machine"] == "plotter-2"' 20 &&
  ok || fail "job-00 interrupted: $(grep job-00 "$work/states.txt") $(cat "$work/serve2.log")"
send_command plotter-2 '{"id": "r1", "verb": "resume_job"}' "$work/resume_reply.txt"
grep -q '"status":200' "$work/resume_reply.txt" && ok || fail "resume_job: $(cat "$work/resume_reply.txt")"
until_states 'all(s.get(f"job-{k:02d}", {}).get("state") == "done" for k in range(20))' 120 &&
  ok || fail "every job done: $(cat "$work/states.txt")"
$py - "$work/states.txt" <<'PY' && ok || fail "job-00's history"
import json, sys
s = {j["id"]: j for j in map(json.loads, filter(str.strip, open(sys.argv[1])))}
h = [e["state"] for e in s["job-00"]["history"]]
print("job-00:", " -> ".join(h), "on", s["job-00"]["machine"])
sys.exit(0 if h[0] == "queued" and "interrupted" in h and h[-1] == "done" else 1)
PY

# A command reaches only the machine it names: plotter-3's pen goes down, the others' not.
send_command plotter-3 '{"id": "c1", "verb": "pen", "down": true}' "$work/pen_reply.txt"
grep -q '"status":200' "$work/pen_reply.txt" && ok || fail "pen down on plotter-3: $(cat "$work/pen_reply.txt")"
sleep 0.5
for k in 1 2 3; do
  status=$(sub -t "pathstream/plotter-$k/status" -C 1 -W 10)
  want=false; [ $k = 3 ] && want=true
  [[ "$status" == *"\"pen_down\":$want"* ]] && ok || fail "plotter-$k pen after the command to plotter-3: $status"
done

# The devices write their records at exit; every job drawn on exactly one, whole, once.
for k in 1 2 3; do kill -INT "${device_pid[$k]}" 2> /dev/null; done
for k in 1 2 3; do
  for _ in $(seq 200); do kill -0 "${device_pid[$k]}" 2> /dev/null || break; sleep 0.05; done
done
$py - "$work" <<'PY' && ok || fail "the devices' records"
import sys
work = sys.argv[1]
lsb = 0.001
def pen_down(path, x_col, y_col, scale):
    out = []
    with open(path) as f:
        next(f)
        for line in f:
            c = line.rstrip("\n").split(",")
            if int(c[-1]):
                out.append((float(c[x_col]) * scale, float(c[y_col]) * scale))
    return out
records = {k: pen_down(f"{work}/record{k}.csv", 1, 2, lsb) for k in (1, 2, 3)}
bad = []
for k in range(20):
    x, y = 10 + 25 * (k % 5), 10 + 25 * (k // 5)
    inside = lambda p: x - 1 <= p[0] <= x + 16 and y - 1 <= p[1] <= y + 16
    plan = [p for p in pen_down(f"{work}/plan-{k:02d}.csv", 2, 3, 1) if inside(p)]
    where = {m: [p for p in r if inside(p)] for m, r in records.items()}
    on = [m for m, pts in where.items() if pts]
    if len(on) != 1:
        bad.append(f"job-{k:02d} drawn on {len(on)} devices")
        continue
    pts = where[on[0]]
    # Complete: every corner reached; once: not many more pen-down ticks than the plan's (a
    # resumed job re-enters with a few).
    for cx, cy in [(x, y), (x + 15, y), (x + 15, y + 15), (x, y + 15)]:
        if min((px - cx) ** 2 + (py - cy) ** 2 for px, py in pts) > 0.01 ** 2:
            bad.append(f"job-{k:02d}: corner {cx},{cy} not drawn")
    if not (0.98 * len(plan) <= len(pts) <= 1.02 * len(plan) + 200):
        bad.append(f"job-{k:02d}: {len(pts)} pen-down ticks, plan {len(plan)}")
    print(f"job-{k:02d} on device {on[0]}: {len(pts)} pen-down ticks (plan {len(plan)})")
for b in bad:
    print("FAIL", b)
sys.exit(1 if bad else 0)
PY
echo "mqtt jobs: $passed passed, $failures failed"
[ "$failures" -eq 0 ]

#!/usr/bin/python3
"""`pathstream serve` and the simulated device, attacked from loopback as a careless or hostile
client would, with Python's standard library only:

  serve_limits_test.py PATHSTREAM SOURCE_DIR WORK_DIR

* a stop through a crowd: 64 event streams that never read and 64 request heads sent one byte
  at a time, while a job streams: POST /api/control {"verb":"stop"} is answered and the job
  ends held or stopped (its journal kept);
* the 29-byte job (`G1 X400` at F1: 6.7 h of motion): its preview is cancelled when the
  client leaves (no planning child left); 8,280 moves of 10 mm at F60 (23 h) are stopped at
  --plan-timeout with the job's motion time in the message, at a tenth (67 h) refused before
  planning by --max-motion-hours; the server's memory stays near its idle figure;
* bodies past --max-upload-mb, chunked and not: 413, nothing stored;
* 200 KB of request headers: 431, the server's memory bounded;
* an upload named `-h.csv` is stored as `_h.csv` and a run of it streams it (no option);
* a run naming a preview of another drawing is refused, and an upload while a job runs.

Figures (times, memory) are printed; no check is on wall time: each waits for an outcome with
a bound only a hang reaches.
"""
import http.client
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import threading
import time

BIN, SOURCE, WORK = sys.argv[1:4]
MACHINE = os.path.join(SOURCE, "examples/machines/a3_plotter.json")
failures = 0
children = []


def check(ok, what):
    global failures
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures += 1


def start(args, pattern):
    """Starts BIN with args; returns (process, first match of pattern in its output)."""
    p = subprocess.Popen([BIN] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    children.append(p)
    text = ""
    end = time.time() + 20
    while time.time() < end:
        line = p.stdout.readline()
        if not line:
            break
        text += line
        m = re.search(pattern, text)
        if m:
            threading.Thread(target=lambda: [None for _ in p.stdout], daemon=True).start()
            return p, m
    raise RuntimeError(f"{args[0]}: no {pattern} in its output: {text}")


def rss_kb(pid):
    with open(f"/proc/{pid}/status") as f:
        return int(re.search(r"VmRSS:\s+(\d+)", f.read()).group(1))


def planning_children(pid):
    """The server's children that run `plan`."""
    found = []
    for task in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{task}/children") as f:
                kids = f.read().split()
        except OSError:
            continue
        for kid in kids:
            try:
                with open(f"/proc/{kid}/cmdline", "rb") as f:
                    if b"\0plan\0" in f.read():
                        found.append(kid)
            except OSError:
                pass
    return found


shutil.rmtree(WORK, ignore_errors=True)
state = os.path.join(WORK, "state")
os.makedirs(state)
device, m = start(["device", "--tcp", "127.0.0.1:0", "--time-scale", "2"], r"serving (modbus-tcp://\S+)")
target = m.group(1)
server, m = start(["serve", "-m", MACHINE, "-t", target, "--listen", "127.0.0.1:0", "--state-dir", state,
                   "--plan-timeout", "10", "--max-upload-mb", "1"], r"http://127\.0\.0\.1:(\d+)/")
PORT = int(m.group(1))
ORIGIN = f"http://127.0.0.1:{PORT}"


def request(method, path, body=b"", headers=None, timeout=60):
    c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=timeout)
    h = {"Origin": ORIGIN}
    h.update(headers or {})
    if isinstance(body, (dict, list)):
        body = json.dumps(body).encode()
        h["Content-Type"] = "application/json"
    c.request(method, path, body=body, headers=h)
    r = c.getresponse()
    data = r.read()
    c.close()
    try:
        return r.status, json.loads(data)
    except ValueError:
        return r.status, {"raw": data[:200]}


def upload(name, data, options=None):
    q = f"/api/drawing?name={name}"
    if options is not None:
        q += "&options=" + json.dumps(options)
    return request("POST", q, data)


def wait_for(what, condition, seconds=60):
    end = time.time() + seconds
    while time.time() < end:
        if condition():
            return True
        time.sleep(0.05)
    check(False, f"{what} (no outcome within {seconds} s)")
    return False


for _ in range(100):  # the server's first device read
    if request("GET", "/api/state")[0] == 200:
        break
idle_rss = rss_kb(server.pid)
print(f"figure: server memory idle {idle_rss / 1024:.1f} MB", flush=True)

# --- a stop through a crowd, while a job streams ---
with open(os.path.join(SOURCE, "examples/landscape.svg"), "rb") as f:
    landscape = f.read()
status, preview = upload("landscape.svg", landscape)
check(status == 200 and preview.get("ok"), f"landscape.svg previews: {status}")
status, run = request("POST", "/api/run", {"options": {}, "drawing_hash": preview.get("drawing_hash", "")})
check(status == 200, f"the run starts: {status} {run.get('error', '')}")
status, busy = upload("star.csv", open(os.path.join(SOURCE, "examples/star.csv"), "rb").read())
check(status == 409 and "job is running" in busy.get("error", ""), f"an upload while the job runs: {status} {busy.get('error')}")
crowd = []
for _ in range(64):
    s = socket.create_connection(("127.0.0.1", PORT))
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
    s.sendall(f"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\n\r\n".encode())
    crowd.append(s)
slow = [socket.create_connection(("127.0.0.1", PORT)) for _ in range(64)]
trickling = threading.Event()


def trickle():
    for s in slow:
        s.sendall(b"GET /api/state HTTP/1.1\r\n")
    while not trickling.is_set():
        for s in slow:
            try:
                s.sendall(b"X")
            except OSError:
                pass
        time.sleep(0.5)


trickler = threading.Thread(target=trickle)
trickler.start()
time.sleep(1.5)
# The stop must find the job streaming (its journal written with the first batch), however long
# planning its first window takes on this machine.
wait_for("the job streams", lambda: os.path.exists(os.path.join(state, "job.journal.json")), 60)
t0 = time.time()
status, stopped = request("POST", "/api/control", {"verb": "stop"}, timeout=30)
answered = time.time() - t0
check(status == 200 and stopped.get("ok"), f"stop answered through 64 silent event streams and 64 trickling heads: {status}")
print(f"figure: stop answered in {answered * 1000:.0f} ms with 128 hostile connections open", flush=True)
wait_for("the job ends", lambda: not request("GET", "/api/state")[1].get("job_running"), 60)
check(os.path.exists(os.path.join(state, "job.journal.json")), "the stopped job's journal is kept")
trickling.set()
trickler.join()
for s in crowd + slow:
    s.close()

# --- the 29-byte job ---
tiny = b"G21 G90\nG1 Z-1 F1\nG1 X400\nM2\n"
check(len(tiny) == 29, "the job is 29 bytes")
c = socket.create_connection(("127.0.0.1", PORT))
c.sendall(f"POST /api/drawing?name=tiny.gcode HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\nOrigin: {ORIGIN}\r\n"
          f"Content-Length: {len(tiny)}\r\n\r\n".encode() + tiny)
wait_for("the preview starts planning", lambda: planning_children(server.pid), 20)
c.close()
t0 = time.time()
wait_for("the planning child is gone once its client left", lambda: not planning_children(server.pid), 20)
print(f"figure: planning child killed {1000 * (time.time() - t0):.0f} ms after its client left", flush=True)
# 8,280 moves of 10 mm at F60, back and forth (23 h of motion, 124 bytes): read in a fraction
# of a second, so the estimate is out at once, and planned in over 20 s here (10 million
# spans), so it is stopped at --plan-timeout, its motion time named.
slow = (b"G21 G90\nG1 Z-1 F60\n#1 = 0\no1 while [#1 LT 4140]\nG1 X10 Y[#1 * 0.01]\n"
        b"G1 X0 Y[#1 * 0.01 + 0.005]\n#1 = [#1 + 1]\no1 endwhile\nM2\n")
t0 = time.time()
status, answer = upload("slow.gcode", slow)
took = time.time() - t0
message = answer.get("error", "")
check(status == 422 and "planning stopped after 10 s (serve --plan-timeout)" in message and
      "23.0 h" in message,
      f"a 23 h job is stopped at --plan-timeout, its motion time named: {status} {message}")
print(f"figure: the 23 h job's upload answered in {took:.2f} s (--plan-timeout 10)", flush=True)
# The 29-byte job at a tenth of its feed (67 h), past --max-motion-hours (24): refused before
# any planning.
status, answer = upload("longer.gcode", b"G21 G90\nG1 Z-1 F0.1\nG1 X400\nM2\n")
message = answer.get("error", "")
check(status == 422 and "the job moves for about 66.7 h (estimated before planning), longer than 24.0 h" in message,
      f"a 67 h job is refused before planning: {status} {message}")
after_rss = rss_kb(server.pid)
check(after_rss < idle_rss + 32 * 1024, f"server memory {after_rss / 1024:.1f} MB, idle {idle_rss / 1024:.1f} MB")
print(f"figure: server memory after the 29-byte job {after_rss / 1024:.1f} MB", flush=True)

# --- bodies past the limit ---
before = sorted(os.listdir(os.path.join(state, "drawing")))
s = socket.create_connection(("127.0.0.1", PORT))
s.sendall(f"POST /api/drawing?name=big.csv HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\nOrigin: {ORIGIN}\r\n"
          "Transfer-Encoding: chunked\r\n\r\n".encode())
sent = 0
try:
    while sent < 30 << 20:
        s.sendall(b"100000\r\n" + b"1" * 0x100000 + b"\r\n")
        sent += 0x100000
except OSError:
    pass
s.settimeout(20)
head = b""
try:
    while b"\r\n" not in head:
        chunk = s.recv(1)
        if not chunk:
            break
        head += chunk
except OSError:
    pass
s.close()
check(head.startswith(b"HTTP/1.1 413"), f"a chunked body past --max-upload-mb: {head.strip()!r} after {sent >> 20} MB sent")
status, _ = request("POST", "/api/drawing?name=big.csv", b"1" * (2 << 20))
check(status == 413, f"a 2 MB body with its length: {status}")
check(sorted(os.listdir(os.path.join(state, "drawing"))) == before, "nothing of either is stored")

# --- headers ---
s = socket.create_connection(("127.0.0.1", PORT))
try:
    s.sendall(f"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\n".encode())
    for i in range(2000):
        s.sendall(b"X-Pad-%d: %s\r\n" % (i, b"a" * 100))
except OSError:
    pass
s.settimeout(20)
try:
    answer = s.recv(200)
except OSError:
    answer = b""
s.close()
check(answer.startswith(b"HTTP/1.1 431"), f"200 KB of headers: {answer[:40]!r}")
check(rss_kb(server.pid) < idle_rss + 32 * 1024, f"server memory {rss_kb(server.pid) / 1024:.1f} MB after the headers")

# --- names and the drawing a run streams ---
star = open(os.path.join(SOURCE, "examples/star.csv"), "rb").read()
status, p = upload("-h.csv", star)
check(status == 200 and p.get("drawing") == "_h.csv", f"-h.csv is stored as {p.get('drawing')}")
star_hash = p.get("drawing_hash")
status, p = upload("landscape.svg", landscape)
status, refused = request("POST", "/api/run", {"options": {}, "drawing_hash": star_hash})
check(status == 409 and "changed since this page's preview" in refused.get("error", ""),
      f"a run naming the preview of another drawing: {status} {refused.get('error')}")
status, p = upload("-h.csv", star)
status, run = request("POST", "/api/run", {"options": {}, "drawing_hash": star_hash})
check(status == 200 and run.get("drawing") == "_h.csv", f"the run of _h.csv: {status} {run.get('error', '')}")
wait_for("the _h.csv job ends", lambda: not request("GET", "/api/state")[1].get("job_running"), 60)
with open(os.path.join(state, "job.journal.json")) as f:
    journal = json.load(f)
check(journal.get("drawing") == "_h.csv" and journal.get("outcome") == "finished",
      f"the journal is the _h.csv job's, finished: {journal.get('drawing')} {journal.get('outcome')}")

server.terminate()
check(server.wait(20) == 0, "the server exits 0 on SIGTERM")
device.terminate()
device.wait(10)
print(f"serve limits test: {failures} failed", flush=True)
sys.exit(1 if failures else 0)

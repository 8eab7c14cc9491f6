# A real MQTT broker for the CLI tests, sourced by them: Debian's mosquitto on loopback with its
# own configuration and a free port. The test defines $work, the array pids (killed at its
# exit) and fail().

free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }

# Starts mosquitto with `$1` as its extra configuration; sets $port and $broker_pid (retries a
# port another program took meanwhile).
start_broker() {
  for _ in 1 2 3 4 5; do
    port=$(free_port)
    printf 'listener %s 127.0.0.1\npersistence false\nlog_dest stderr\n%s\n' "$port" "$1" > "$work/mosquitto.conf"
    /usr/sbin/mosquitto -c "$work/mosquitto.conf" 2>> "$work/mosquitto.log" &
    broker_pid=$!
    for _ in $(seq 100); do
      kill -0 "$broker_pid" 2> /dev/null || break
      (echo > "/dev/tcp/127.0.0.1/$port") 2> /dev/null && { pids+=("$broker_pid"); return 0; }
      sleep 0.05
    done
  done
  fail "mosquitto did not start: $(tail -3 "$work/mosquitto.log")"; return 1
}

# Helpers of test/ros/test_{devel,install}_space.sh: a ROS master on a free
# port, waiting for a node, clean shutdown. Source it after the setup.bash.
# shellcheck shell=bash
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin:$PATH
export ROS_HOSTNAME=localhost
TMP=$(mktemp -d)
export ROS_LOG_DIR="$TMP/log" ROS_HOME="$TMP/home"
PIDS=()

fail() { echo "FAIL: $*" >&2; for f in "$TMP"/*.log; do [ -f "$f" ] && { echo "--- $f" >&2; tail -20 "$f" >&2; }; done; exit 1; }

cleanup() {
  local p
  for p in "${PIDS[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for p in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null || true
  done
  rm -rf "$TMP"
}
trap cleanup EXIT

start_master() {
  local port
  port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI=http://localhost:$port
  roscore -p "$port" >"$TMP/roscore.log" 2>&1 &
  PIDS+=($!)
  for _ in $(seq 100); do rosnode list >/dev/null 2>&1 && return 0; sleep 0.2; done
  fail "no ROS master on port $port"
}

# wait_for_topic TOPIC [SECONDS]: TOPIC is advertised
wait_for_topic() { wait_until_listed rostopic "$@"; }

# wait_until_listed TOOL NAME [SECONDS=20]: until `TOOL list` (rostopic,
# rosservice) lists NAME (a node advertises its services after its topics;
# on a loaded machine the gap can be seconds)
wait_until_listed() {
  local t=${3:-20} i
  for i in $(seq $((t * 5))); do
    "$1" list 2>/dev/null | grep -qx "$2" && return 0
    sleep 0.2
  done
  return 1
}

# wait_for_service NAME [SECONDS=20]
wait_for_service() { wait_until_listed rosservice "$@"; }

# stop PID NAME: SIGINT, and the process must end by itself within 10 s
stop() {
  kill -INT "$1" 2>/dev/null || fail "$2 is not running"
  for _ in $(seq 100); do kill -0 "$1" 2>/dev/null || { wait "$1" 2>/dev/null || true; return 0; }; sleep 0.1; done
  fail "$2 did not shut down within 10 s of SIGINT"
}

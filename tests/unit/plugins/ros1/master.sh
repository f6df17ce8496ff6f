# Sourced by the ROS tests: skips (exit 77) without ROS 1, else starts a real ROS master on a free
# loopback port in a ROS_HOME of its own, waits until it answers, and stops it on exit.
if ! command -v rosmaster >/dev/null || ! /usr/bin/python3 -c "import rospy, nav_msgs, geometry_msgs" 2>/dev/null; then
  echo "SKIPPED: ROS 1 is not installed (apt-get install python3-rosmaster python3-rospy libroscpp-dev ...)"
  exit 77
fi
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1
ROS_HOME=$(mktemp -d)
export ROS_HOME
rosmaster --core -p "$port" >"$ROS_HOME/master.log" 2>&1 &
master=$!
cleanup() {
  kill "$master" 2>/dev/null
  wait "$master" 2>/dev/null
  rm -rf "$ROS_HOME"
}
trap cleanup EXIT
# wait until the master answers
up=0
for _ in $(seq 100); do
  if /usr/bin/python3 -c "import xmlrpc.client; xmlrpc.client.ServerProxy('$ROS_MASTER_URI').getPid('/probe')" 2>/dev/null; then
    up=1
    break
  fi
  sleep 0.1
done
if [ $up -eq 0 ]; then
  echo "FAILED: rosmaster did not answer on port $port"; cat "$ROS_HOME/master.log"; exit 1
fi

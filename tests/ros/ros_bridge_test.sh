#!/bin/bash
# ctest: a real ROS master on a free loopback port, ssx with the ros1 extension and ten quadrotors,
# and a separate peer process that reads odometry and sends set-points; passes when every robot
# reaches its set-point and ssx ends cleanly. Exits 77 (ctest: skipped) when ROS 1 is not installed.
#
# usage: ros_bridge_test.sh SSX_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
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
/usr/bin/python3 "$here/peer.py" 10 30 &
peer=$!
"$ssx" run "$here/ros_swarm.xml" --realtime --quiet
ssx_status=$?
wait "$peer"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ]

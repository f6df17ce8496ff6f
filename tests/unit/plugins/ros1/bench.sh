#!/bin/bash
# Benchmark (not a test): N quadrotors bridged to ROS 1, odometry at 50 Hz out, a peer answering each
# odometry message with a set-point; prints the peer's message counts (loss) and the bridge's round
# trips, and ssx's timing summary (real time).  usage: tests/unit/plugins/ros1/bench.sh SSX_BINARY [N] [SECONDS]
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1; n=${2:-100}; seconds=${3:-20}
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1
ROS_HOME=$(mktemp -d); export ROS_HOME
rosmaster --core -p "$port" >"$ROS_HOME/master.log" 2>&1 &
master=$!
trap 'kill $master 2>/dev/null; wait $master 2>/dev/null; rm -rf "$ROS_HOME"' EXIT
for _ in $(seq 100); do
  /usr/bin/python3 -c "import xmlrpc.client; xmlrpc.client.ServerProxy('$ROS_MASTER_URI').getPid('/p')" 2>/dev/null && break
  sleep 0.1
done
sed "s/count=\"10\"/count=\"$n\"/; s/duration=\"16\"/duration=\"$seconds\"/" "$here/ros_swarm.xml" > "$ROS_HOME/scene.xml"
sed -i "s|file=\"../../../../examples|file=\"$here/../../../../examples|" "$ROS_HOME/scene.xml"
/usr/bin/python3 "$here/peer.py" "$n" "$((seconds + 3))" --bench &
peer=$!
sleep 1
"$ssx" run "$ROS_HOME/scene.xml" --realtime ${SSX_BENCH_ARGS:-}
wait "$peer"

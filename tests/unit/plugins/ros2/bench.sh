#!/bin/bash
# Benchmark (not a test): N quadrotors bridged to ROS 2 over DDS on loopback, odometry at 50 Hz and
# the IMU at 100 Hz out, a peer (peer.c, a Cyclone DDS program) answering each odometry message with a
# set-point; prints the peer's message counts (loss), the bridge's round trips and publishing cost,
# and ssx's timing summary (real time), as tests/unit/plugins/ros1/bench.sh does for ROS 1.
# usage: tests/unit/plugins/ros2/bench.sh SSX_BINARY PEER_BINARY [N] [SECONDS]
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1; peer=$2; n=${3:-100}; seconds=${4:-20}
. "$here/dds.sh" 67
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e "s/count=\"10\"/count=\"$n\"/; s/duration=\"12\"/duration=\"$seconds\"/" \
    -e "s|file=\"../../../../examples|file=\"$here/../../../../examples|" "$here/ros2_swarm.xml" > "$work/scene.xml"
"$peer" "$n" "$((seconds + 4))" --bench &
peer_pid=$!
sleep 1
"$ssx" run "$work/scene.xml" --realtime ${SSX_BENCH_ARGS:-}
wait "$peer_pid"

#!/bin/bash
# Benchmark (not a test): N robots bridged to ROS 2 over DDS on loopback, in real time.
#   quad (default): mk_quads, odometry and /tf at 50 Hz and the IMU at 100 Hz out, a peer (peer.c, a
#     Cyclone DDS program) answering each odometry message with a set-point; prints the peer's
#     message counts (loss) and the bridge's round trips.
#   burger: TurtleBot3 Burgers (wheels on hinges): odometry, /tf (base, wheels, caster) and joint
#     states at 50 Hz, no peer.
# Both print the bridge's publishing cost on the stepping thread and ssx's timing summary (late
# steps), as tests/unit/plugins/ros1/bench.sh does for ROS 1.
# usage: tests/unit/plugins/ros2/bench.sh SSX_BINARY PEER_BINARY [N] [SECONDS] [quad|burger]
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1; peer=$2; n=${3:-100}; seconds=${4:-20}; kind=${5:-quad}
. "$here/dds.sh" 67
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ "$kind" = burger ]; then
  cat > "$work/scene.xml" <<SCENE
<scene>
  <environment timestep="0.002" seed="3" threads="2" duration="$seconds"/>
  <type name="burger" file="$here/../../../../examples/artifacts/turtlebot3_burger.xml"/>
  <ground/>
  <swarm type="burger" count="$n" name="q{i}" spacing="1"/>
  <extension name="ros" plugin="ros2" odom_rate_hz="50"/>
</scene>
SCENE
  "$ssx" run "$work/scene.xml" --realtime ${SSX_BENCH_ARGS:-}
  exit
fi
sed -e "s/count=\"10\"/count=\"$n\"/; s/duration=\"12\"/duration=\"$seconds\"/" \
    -e "s|file=\"../../../../examples|file=\"$here/../../../../examples|" "$here/ros2_swarm.xml" > "$work/scene.xml"
"$peer" "$n" "$((seconds + 4))" --bench &
peer_pid=$!
sleep 1
"$ssx" run "$work/scene.xml" --realtime ${SSX_BENCH_ARGS:-}
wait "$peer_pid"

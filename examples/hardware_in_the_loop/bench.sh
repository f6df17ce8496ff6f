#!/bin/bash
# Benchmark (not a test): N real quadrotors' motion capture at 100 Hz (ghosts, replayed live by
# ssx_hil_peer over ROS 2: each pose sent when the simulated clock reaches its stamp) and N simulated
# quadrotors in real time, every ghost's range sensor published at 10 Hz. Prints ssx's timing summary
# (late steps) and the bridge's line with the age of the poses used (median, p99, max).
# usage: examples/hardware_in_the_loop/bench.sh SSX_BINARY HIL_PEER_BINARY [N] [SECONDS]
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1; peer=$2; n=${3:-100}; seconds=${4:-20}
eval "$(grep -m1 '^export CYCLONEDDS_URI=' "$here/../../docs/ros.md")"
export ROS_DOMAIN_ID=68
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 "$here/make_mocap.py" "$work/mocap.csv" --grid "$n" "$seconds"
cat > "$work/scene.xml" <<SCENE
<scene>
  <environment timestep="0.002" seed="1" threads="2" duration="$seconds"/>
  <type name="real" file="$here/../artifacts/mk_quad_formation.xml"/>
  <type name="sim" file="$here/../artifacts/mk_quad.xml"/>
  <ground/>
  <swarm type="real" count="$n" name="real{i}" spacing="2" columns="10" xyz="0 0 1.5"><ghost timeout="0.2"/></swarm>
  <swarm type="sim" count="$n" name="sim{i}" spacing="2" columns="10" xyz="1 1 1"/>
  <extension name="ros" plugin="ros2" range_rate_hz="10"/>
</scene>
SCENE
"$peer" "$work/mocap.csv" --quiet > "$work/peer.out" 2>&1 &  # (the last poses, stamped past the end, are not sent)
peer_pid=$!
"$ssx" run "$work/scene.xml" --realtime ${SSX_BENCH_ARGS:-}
wait "$peer_pid"

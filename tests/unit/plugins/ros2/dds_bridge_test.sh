#!/bin/bash
# ctest (plugins/ros2/dds_bridge.cpp): ssx with the ros2 extension and ten quadrotors, and a peer that
# is not ssx (peer.c: a plain Cyclone DDS program with ROS 2's types) on loopback. The peer checks
# the topics' DDS types and QoS, the odometry's and the clock's stamps, and flies the robots: first
# by set-points (each holds its own for 1 s), then by velocity commands (each moves about 1 m).
#
# usage: dds_bridge_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 61
for mode in "" --cmd-vel; do
  "$peer" 10 60 $mode &
  peer_pid=$!
  "$ssx" run "$here/ros2_swarm.xml" --realtime --quiet
  ssx_status=$?
  wait "$peer_pid"
  peer_status=$?
  echo "peer ${mode:-(set-points)}: ssx exit $ssx_status, peer exit $peer_status"
  [ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] || exit 1
done

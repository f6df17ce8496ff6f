#!/bin/bash
# ctest (plugins/bridge, plugins/ros2/dds_bridge.cpp): the Husky from its URDF, without a driver,
# its wheels driven over DDS by a peer that is not ssx (peer.c --wheels): sensor_msgs/JointState on
# /q0/joint_command naming its four wheels at 2 rad/s for 2 s, then 0. Its odometry must show it
# 2 x 2 x 0.17775 m ahead (within 15 %) and standing, its joint states the wheels at 2 rad/s; the
# first command, naming a joint the Husky lacks, is dropped with a warning naming the topic.
#
# usage: joints_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 66
log=$(mktemp)
trap 'rm -f "$log"' EXIT
"$peer" 1 60 --wheels 2.0 0.17775 &
peer_pid=$!
"$ssx" run "$here/ros2_husky.xml" --realtime --quiet 2> "$log"
ssx_status=$?
wait "$peer_pid"
peer_status=$?
dropped=0
grep -q "a message on /q0/joint_command was dropped (no joint 'no_such_joint'" "$log" && dropped=1
grep -v "husky.urdf:[0-9]*: warning" "$log" | head -20
echo "ssx exit $ssx_status, peer exit $peer_status, bad command dropped: $dropped"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] && [ $dropped -eq 1 ]

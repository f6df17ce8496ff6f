#!/bin/bash
# ctest (plugins/ros2/dds_bridge.cpp, plugins/diff_drive): three e-pucks and a TurtleBot3 Burger driven
# over DDS by a peer that is not ssx (peer.c --drive): a Twist of 0.1 m/s forward and 1 rad/s about z
# on /q<i>/cmd_vel for 2 s, then 0. Each robot's odometry must show 0.2 m driven (within 15 %), 2 rad
# turned (within 10 %) and the robot standing 2 s later (the 2 s start from 1 s, once the peer's
# writer matched ssx's reader). /tf carries each robot's base_link at every odometry stamp, equal to
# its odometry, and the Burger's wheel and caster frames; /q3/joint_states its wheels, turning as
# the Twist asks.
#
# usage: ground_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 65
"$peer" 4 60 --drive 0.1 1.0 &
peer_pid=$!
"$ssx" run "$here/ros2_ground.xml" --realtime --quiet
ssx_status=$?
wait "$peer_pid"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ]

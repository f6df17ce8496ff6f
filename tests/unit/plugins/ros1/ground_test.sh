#!/bin/bash
# ctest (plugins/ros1/ros_bridge.cpp, plugins/diff_drive): a real ROS master on a free loopback port,
# three e-pucks and a TurtleBot3 Burger driven by a separate peer (peer.py --drive): a Twist of 0.1 m/s
# forward and 1 rad/s about z on /q<i>/cmd_vel for 2 s, then 0. Each robot's odometry must show 0.2 m
# driven (within 15 %), 2 rad turned (within 10 %) and the robot standing 2 s later (the 2 s start
# from 1 s, once ssx is connected to the robot's /cmd_vel). Exits 77 (ctest: skipped) when ROS 1 is
# not installed.
#
# usage: ground_test.sh SSX_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
. "$here/master.sh"
/usr/bin/python3 "$here/peer.py" 4 40 --drive 0.1 1.0 &
peer=$!
"$ssx" run "$here/ros_ground.xml" --realtime --quiet
ssx_status=$?
wait "$peer"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ]

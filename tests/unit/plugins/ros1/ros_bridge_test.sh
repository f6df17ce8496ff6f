#!/bin/bash
# ctest (plugins/ros1/ros_bridge.cpp): a real ROS master on a free loopback port, ssx with the ros1 extension and ten quadrotors,
# and a separate peer process that reads odometry and sends set-points; passes when every robot
# reaches its set-point and ssx ends cleanly; then the same with velocity commands (/<robot>/cmd_vel):
# every robot moves about 1 m. Exits 77 (ctest: skipped) when ROS 1 is not installed.
#
# usage: ros_bridge_test.sh SSX_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
. "$here/master.sh"
/usr/bin/python3 "$here/peer.py" 10 30 &
peer=$!
"$ssx" run "$here/ros_swarm.xml" --realtime --quiet
ssx_status=$?
wait "$peer"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] || exit 1
/usr/bin/python3 "$here/peer.py" 10 30 --cmd-vel &
peer=$!
"$ssx" run "$here/ros_swarm.xml" --realtime --quiet
ssx_status=$?
wait "$peer"
peer_status=$?
echo "cmd_vel: ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ]

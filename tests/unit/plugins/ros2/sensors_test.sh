#!/bin/bash
# ctest (plugins/ros2/dds_bridge.cpp, scan_layout.hpp): standard sensor messages read over DDS by a
# subscriber that is not ssx (sensors_peer.c): an e-puck's proximity ring as sensor_msgs/LaserScan
# seeing a wall, a camera's sensor_msgs/CameraInfo beside its images.
#
# usage: sensors_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 68
"$peer" 30 &
peer_pid=$!
"$ssx" run "$here/ros2_sensors.xml" --realtime --quiet
ssx_status=$?
wait "$peer_pid"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ]

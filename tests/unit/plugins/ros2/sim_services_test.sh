#!/bin/bash
# ctest (plugins/ros2/sim_services.cpp, RunControl's posted tasks): the simulation_interfaces
# services called over DDS by a client that is not ssx (services_client.c), as ROS 2's
# rmw_cyclonedds_cpp calls them: features, simulation state (play, pause, stop, quit), stepping,
# entities, their states got and set, reset, spawn and delete refused. The client's quit ends the
# run, well before the scene's 60 s: ssx must exit 0 within the test's time.
#
# usage: services_test.sh SSX_BINARY CLIENT_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
client=$2
. "$here/dds.sh" 67
log=$(mktemp)
trap 'rm -f "$log"' EXIT
"$client" 30 &
client_pid=$!
start=$(date +%s)
"$ssx" run "$here/ros2_services.xml" --realtime 2> "$log"
ssx_status=$?
took=$(( $(date +%s) - start ))
wait "$client_pid"
client_status=$?
grep "ros2:" "$log"
echo "ssx exit $ssx_status after $took s, client exit $client_status"
[ $ssx_status -eq 0 ] && [ $client_status -eq 0 ] && [ $took -lt 50 ]

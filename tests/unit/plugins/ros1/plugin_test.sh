#!/bin/bash
# ctest: the ros1 extension (plugins/ros1/plugin.cpp) in lock-step with a real ROS master. (1) Ten quadrotors run as fast as they can with
# lockstep="true" while a peer answers each odometry message after a varying delay; the peer checks
# that no odometry round arrives before every robot's answer to the round before was sent, and that
# the robots reach their set-points. (2) Without a peer the run fails, inside its connect timeout,
# with the documented message. Exits 77 (ctest: skipped) when ROS 1 is not installed.
#
# usage: plugin_test.sh SSX_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
. "$here/master.sh"

/usr/bin/python3 "$here/peer.py" 10 60 --lockstep &
peer=$!
"$ssx" run "$here/ros_lockstep.xml" --fast --quiet
ssx_status=$?
wait "$peer"
peer_status=$?
echo "with a peer: ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] || exit 1

# no peer: the same scene with a 2 s connect timeout
sed -e 's|lockstep_connect_timeout_s="20"|lockstep_connect_timeout_s="2"|' \
    -e "s|file=\"../../../../examples/|file=\"$here/../../../../examples/|" "$here/ros_lockstep.xml" > "$ROS_HOME/alone.xml"
start=$(date +%s)
"$ssx" run "$ROS_HOME/alone.xml" --fast --quiet 2> "$ROS_HOME/alone.err"
status=$?
elapsed=$(( $(date +%s) - start ))
cat "$ROS_HOME/alone.err"
echo "without a peer: ssx exit $status after ${elapsed} s"
[ $status -eq 1 ] || exit 1
grep -q "lock-step: no controller connected within 2" "$ROS_HOME/alone.err" || exit 1
[ $elapsed -lt 15 ] || exit 1

#!/bin/bash
# ctest (plugins/bridge over ROS 1: ghosts and operators): the hardware-in-the-loop example with the
# ros1 extension, a real ROS master on a free loopback port, and a rospy peer (ghosts_peer.py) that
# sends the real robots' motion capture 200 ms ahead of /clock and steers op0; it checks that each
# ghost's odometry is the interpolation of its poses, that its /range shows the virtual pillar, that
# /op0/force comes and that the operator's command moved sim0 and the dead-man rule stopped it.
# Exits 77 (ctest: skipped) when ROS 1 is not installed.
#
# usage: ghosts_test.sh SSX_BINARY WORK_DIR
set -u
here=$(cd "$(dirname "$0")" && pwd)
example=$(cd "$here/../../../../examples/hardware_in_the_loop" && pwd)
ssx=$1
work=$2
mkdir -p "$work"
. "$here/master.sh"
sed -e 's#file="../artifacts/#file="'"$example"'/../artifacts/#' -e 's#plugin="ros2"#plugin="ros1"#' \
    -e 's#duration="12"#duration="9"#' "$example/ghosts.xml" > "$work/ghosts_ros1.xml"
grep -q 'plugin="ros1" range_rate_hz="20" operators="op0"' "$work/ghosts_ros1.xml" || { echo "the example's extension line changed: update this test"; exit 1; }
/usr/bin/python3 "$here/ghosts_peer.py" "$example/mocap.csv" &
peer=$!
"$ssx" run "$work/ghosts_ros1.xml" --realtime --quiet > "$work/ssx.out" 2>&1
ssx_status=$?
wait "$peer"
peer_status=$?
cat "$work/ssx.out"
echo "ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] || exit 1
grep -Eq "ros1: 1[0-9]{3} ghost poses applied, 0 refused, 0 dropped unread" "$work/ssx.out" || { echo "poses refused or dropped"; exit 1; }

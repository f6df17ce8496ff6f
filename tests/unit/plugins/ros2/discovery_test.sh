#!/bin/bash
# ctest (plugins/ros2/discovery.cpp): ros_discovery_info in ROS 2 Humble's layout, read over DDS by
# a program that is not ssx (discovery_peer.c) with Humble's types (24-byte ids); Iron's layout is
# read by the services test's client. And a distribution's name that is not one is refused at its
# line before anything runs.
#
# usage: discovery_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 71
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset ROS_DISTRO
"$peer" 20 ssx_humble &
peer_pid=$!
"$ssx" run "$here/ros2_humble.xml" --realtime --quiet
ssx_status=$?
wait "$peer_pid"
peer_status=$?
echo "ssx exit $ssx_status, peer exit $peer_status"
# Iron's layout (ros_distro="jazzy") is not Humble's: the same reader finds no node (it drops the
# announcement it cannot read) while the run itself goes well
sed -e 's#ros_distro="humble"#ros_distro="jazzy"#' -e 's#file="../../../../#file="'"$here"'/../../../../#' \
    "$here/ros2_humble.xml" > "$work/jazzy.xml"
"$peer" 4 ssx_humble > "$work/jazzy_peer.out" &
jazzy_pid=$!
"$ssx" run "$work/jazzy.xml" --realtime --quiet
jazzy_status=$?
wait "$jazzy_pid"
if [ $jazzy_status -eq 0 ] && grep -q "FAILED: the node is on ros_discovery_info" "$work/jazzy_peer.out"; then
  echo "ok: Iron's layout is not read as Humble's"
else
  echo "FAILED: with ros_distro=\"jazzy\" the Humble reader found the node, or the run failed ($jazzy_status)"
  cat "$work/jazzy_peer.out"
  peer_status=1
fi
# bad names, from the scene and from the environment
sed -e 's#ros_distro="humble"#ros_distro="Humble 22.04"#' -e 's#file="../../../../#file="'"$here"'/../../../../#' \
    "$here/ros2_humble.xml" > "$work/bad.xml"
"$ssx" run "$work/bad.xml" --fast --quiet > "$work/bad.out" 2>&1
bad_status=$?
cat "$work/bad.out"
refused=0
if [ $bad_status -ne 0 ] && grep -q "bad.xml:9: error: .*ros_distro 'Humble 22.04' is not a ROS 2 distribution" "$work/bad.out" &&
   grep -q "nothing was run" "$work/bad.out"; then
  refused=1
fi
sed -e 's# ros_distro="humble"##' -e 's#file="../../../../#file="'"$here"'/../../../../#' "$here/ros2_humble.xml" > "$work/env.xml"
ROS_DISTRO='humble!' "$ssx" run "$work/env.xml" --fast --quiet > "$work/env.out" 2>&1
env_status=$?
cat "$work/env.out"
if [ $env_status -eq 0 ] || ! grep -q "ROS_DISTRO 'humble!' is not a ROS 2 distribution's name" "$work/env.out"; then
  refused=0
fi
echo "bad names refused: $refused"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] && [ $refused -eq 1 ]

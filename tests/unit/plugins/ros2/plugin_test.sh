#!/bin/bash
# ctest (plugins/ros2/plugin.cpp): the ros2 extension in lock-step with a peer that is not ssx.
# (1) Ten quadrotors run as fast as they can with lockstep="true" while the peer answers each
# odometry message after 0-30 ms; the peer checks that no odometry round arrives before every
# robot's answer to the round before was sent, and that the robots reach their set-points.
# (2) A peer that vanishes mid-run: the run stops with the lock-step message, inside its timeout.
# (3) Without a peer the run fails, inside its connect timeout, with the documented message.
# (4) A domain ROS 2 cannot use is refused before anything runs. (5) So is a run whose DDS cannot
# start (network="system" with a broken CYCLONEDDS_URI), with the reason. (6) Ctrl-C (SIGINT) or
# SIGTERM while lock-step waits for a controller that never comes ends the run at once, with 130
# or 143, not at the wait's timeout (an hour here).
#
# usage: plugin_test.sh SSX_BINARY PEER_BINARY
set -u
here=$(cd "$(dirname "$0")" && pwd)
ssx=$1
peer=$2
. "$here/dds.sh" 62
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$peer" 10 60 --lockstep &
peer_pid=$!
"$ssx" run "$here/ros2_lockstep.xml" --fast --quiet
ssx_status=$?
wait "$peer_pid"
peer_status=$?
echo "(1) lock-step: ssx exit $ssx_status, peer exit $peer_status"
[ $ssx_status -eq 0 ] && [ $peer_status -eq 0 ] || exit 1

sed -e "s|file=\"../../../../examples/|file=\"$here/../../../../examples/|" \
    -e 's|lockstep_timeout_s="5"|lockstep_timeout_s="2"|' "$here/ros2_lockstep.xml" > "$work/vanish.xml"
"$peer" 10 60 --lockstep --vanish-after 2 &
peer_pid=$!
start=$(date +%s)
"$ssx" run "$work/vanish.xml" --fast --quiet 2> "$work/vanish.err"
status=$?
elapsed=$(( $(date +%s) - start ))
wait "$peer_pid"
cat "$work/vanish.err"
echo "(2) the peer vanished: ssx exit $status after ${elapsed} s"
[ $status -eq 1 ] || exit 1
grep -q "lock-step: no set-point stamped at or after" "$work/vanish.err" || exit 1
[ $elapsed -lt 10 ] || exit 1

sed -e 's|lockstep_connect_timeout_s="20"|lockstep_connect_timeout_s="2"|' "$work/vanish.xml" > "$work/alone.xml"
start=$(date +%s)
"$ssx" run "$work/alone.xml" --fast --quiet 2> "$work/alone.err"
status=$?
elapsed=$(( $(date +%s) - start ))
cat "$work/alone.err"
echo "(3) no peer: ssx exit $status after ${elapsed} s"
[ $status -eq 1 ] || exit 1
grep -q "lock-step: no controller connected within 2" "$work/alone.err" || exit 1
[ $elapsed -lt 15 ] || exit 1

sed -e 's|plugin="ros2"|plugin="ros2" domain_id="300"|' "$work/alone.xml" > "$work/domain.xml"
"$ssx" validate "$work/domain.xml" 2> "$work/domain.err"
status=$?
cat "$work/domain.err"
echo "(4) domain 300: ssx validate exit $status"
[ $status -ne 0 ] || exit 1
grep -q "domain.xml:[0-9]*: error: .*domain_id '300' is not a ROS 2 domain" "$work/domain.err" || exit 1

sed -e 's|plugin="ros2"|plugin="ros2" network="system"|' "$work/alone.xml" > "$work/system.xml"
CYCLONEDDS_URI='<CycloneDDS><Domain><Bogus>1</Bogus></Domain></CycloneDDS>' "$ssx" run "$work/system.xml" --fast 2> "$work/system.err"
status=$?
cat "$work/system.err"
echo "(5) DDS cannot start: ssx run exit $status"
[ $status -ne 0 ] || exit 1
grep -q "system.xml:[0-9]*: error: .*ros2: joining DDS domain 62 .*failed" "$work/system.err" || exit 1

sed -e 's|lockstep_connect_timeout_s="2"|lockstep_connect_timeout_s="3600"|' "$work/alone.xml" > "$work/hour.xml"
for sig in INT TERM; do
  "$ssx" run "$work/hour.xml" --fast 2> "$work/hour.err" &
  ssx_pid=$!
  # once the run has begun (its summary line printed), it waits for a controller
  for _ in $(seq 1 300); do grep -q "artifacts," "$work/hour.err" && break; sleep 0.1; done
  start=$(date +%s)
  kill -s "$sig" "$ssx_pid"
  wait "$ssx_pid"
  status=$?
  elapsed=$(( $(date +%s) - start ))
  cat "$work/hour.err"
  echo "(6) SIG$sig while waiting for a controller: ssx exit $status after ${elapsed} s"
  expected=130; [ "$sig" = TERM ] && expected=143
  [ $status -eq $expected ] || exit 1
  [ $elapsed -lt 30 ] || exit 1
done

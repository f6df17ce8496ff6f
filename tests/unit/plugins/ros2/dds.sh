# Sourced by the ros2 tests: the DDS configuration a ROS 2 program uses to see ssx on this machine,
# read from docs/ros.md (so the documented line is the tested one), and a domain of the test's own.
# usage: . dds.sh DOMAIN
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
line=$(grep -m1 "^export CYCLONEDDS_URI=" "$here/../../../../docs/ros.md")
[ -n "$line" ] || { echo "docs/ros.md has no 'export CYCLONEDDS_URI=' line"; exit 1; }
eval "$line"
export ROS_DOMAIN_ID=$1

#!/usr/bin/python3
"""A controller outside ssx: subscribes to each robot's odometry and sends it a set-point 1 m east,
0.5 m south of where it started, 1.5 m up; succeeds when every robot has held within 0.1 m of its
set-point for 1 s of simulated time.

usage: peer.py COUNT [TIMEOUT_S]   (robots q0 .. q<COUNT-1>; exit 0 on success, 1 otherwise)
       peer.py COUNT SECONDS --bench  (answer every odometry message at once with a set-point stamped
                                       like it, for SECONDS; print how many messages came per robot)
"""
import sys
import time

import rospy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry


def main():
    count = int(sys.argv[1])
    timeout = float(sys.argv[2]) if len(sys.argv) > 2 else 40.0
    rospy.init_node("peer", anonymous=True, disable_signals=True)
    names = ["q%d" % i for i in range(count)]
    target, error, held_since, last_stamp, received = {}, {}, {}, {}, {}
    pubs = {n: rospy.Publisher("/%s/setpoint" % n, PoseStamped, queue_size=10) for n in names}

    bench = "--bench" in sys.argv

    def on_odom(msg, name):
        p = msg.pose.pose.position
        t = msg.header.stamp.to_sec()
        received[name] = received.get(name, 0) + 1
        if name not in target:
            target[name] = (p.x + 1.0, p.y - 0.5, 1.5)
        if bench:
            m = PoseStamped()
            m.header.stamp = msg.header.stamp
            m.pose.position.x, m.pose.position.y, m.pose.position.z = target[name]
            m.pose.orientation.w = 1.0
            pubs[name].publish(m)
        x, y, z = target[name]
        e = ((p.x - x) ** 2 + (p.y - y) ** 2 + (p.z - z) ** 2) ** 0.5
        error[name] = e
        last_stamp[name] = t
        if e < 0.1:
            held_since.setdefault(name, t)
        else:
            held_since.pop(name, None)

    subs = [rospy.Subscriber("/%s/odom" % n, Odometry, on_odom, callback_args=n, tcp_nodelay=True) for n in names]
    start = time.time()
    if bench:
        while time.time() - start < timeout:
            time.sleep(0.1)
        counts = sorted(received.get(n, 0) for n in names)
        print("peer: odometry messages per robot: min %d median %d max %d (%d robots heard of %d)"
              % (counts[0], counts[len(counts) // 2], counts[-1], len(received), count))
        return 0
    rate = 20.0
    while time.time() - start < timeout:
        for n in names:
            if n not in target:
                continue
            m = PoseStamped()
            m.header.stamp = rospy.Time.from_sec(last_stamp[n])
            m.header.frame_id = "world"
            m.pose.position.x, m.pose.position.y, m.pose.position.z = target[n]
            m.pose.orientation.w = 1.0
            pubs[n].publish(m)
        done = [n for n in names if n in held_since and last_stamp[n] - held_since[n] >= 1.0]
        if len(done) == count:
            print("peer: all %d robots held their set-points (errors: %s m; odometry messages: %s)"
                  % (count, " ".join("%.3f" % error[n] for n in names), " ".join(str(received[n]) for n in names)))
            return 0
        time.sleep(1.0 / rate)
    print("peer: timed out; odometry from %d of %d robots; errors: %s"
          % (len(target), count, " ".join("%s=%.3f" % (n, error.get(n, float("nan"))) for n in names)))
    return 1


if __name__ == "__main__":
    code = main()
    rospy.signal_shutdown("done")
    sys.exit(code)

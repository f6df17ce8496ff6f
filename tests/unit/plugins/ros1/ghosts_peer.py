#!/usr/bin/python3
"""What is outside a hardware-in-the-loop run, over ROS 1 (a rospy node): the example's motion
capture (examples/hardware_in_the_loop/mocap.csv) sent on /<robot>/pose 200 ms ahead of the
simulated clock, an operator steering op0 north at 0.4 m/s from 4 to 6 s of simulated time.

Checks: each ghost's odometry is the file's poses interpolated at its stamp (within 1 mm, where the
poses around it were sent 20 ms of simulated time before); its /range shows the pillar at (2, 0),
radius 0.25, at its nearest point whenever it is within 2.5 m; /op0/force comes; sim0 moved
0.6-1.0 m north while steered and at most 0.35 m more after (the dead-man rule). Ends when /clock
stops for 3 s. Prints what it found; exit 0 when all of it held.

usage: ghosts_peer.py MOCAP.csv
"""
import bisect
import csv
import math
import sys
import threading
import time

import rospy
from geometry_msgs.msg import PoseArray, PoseStamped, Twist, WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

LEAD, PILLAR, RADIUS, RANGE = 0.2, (2.0, 0.0), 0.25, 2.5
MARGIN = LEAD / 2  # a pose counts as arrived this long (simulated time) after it was sent


def main():
    samples = {}
    with open(sys.argv[1]) as f:
        for row in csv.DictReader(f):
            samples.setdefault(row["robot"], []).append([float(row[k]) for k in ("t", "x", "y", "z", "qw", "qx", "qy", "qz")])
    lock = threading.Lock()
    now = [-1.0]
    last_tick = [time.time()]
    sent = {n: 0 for n in samples}
    sent_at = {n: [] for n in samples}
    odom_error = {n: 0.0 for n in samples}
    odoms = {n: 0 for n in samples}
    seen = {n: [0, 0] for n in samples}  # pillar seen, missed
    forces = [0, 0.0]
    sim0 = {}

    def position(name, t):
        """the file's position at t, interpolated, when both poses around it were sent MARGIN before"""
        s = samples[name]
        times = [p[0] for p in s]
        hi = bisect.bisect_right(times, t)
        if hi == 0 or hi >= len(s) or hi >= sent[name] or sent_at[name][hi] + MARGIN > t:
            return None
        a, b = s[hi - 1], s[hi]
        u = (t - a[0]) / (b[0] - a[0])
        return [a[k] + u * (b[k] - a[k]) for k in (1, 2, 3)]

    def on_clock(msg):
        with lock:
            t = msg.clock.to_sec()
            if t > now[0]:
                last_tick[0] = time.time()
            now[0] = max(now[0], t)

    def on_odom(msg, name):
        with lock:
            p = position(name, msg.header.stamp.to_sec())
            if p is None:
                return
            q = msg.pose.pose.position
            odom_error[name] = max(odom_error[name], math.dist(p, (q.x, q.y, q.z)))
            odoms[name] += 1

    def on_range(msg, name):
        with lock:
            p = position(name, msg.header.stamp.to_sec())
            if p is None:
                return
            d = math.hypot(p[0] - PILLAR[0], p[1] - PILLAR[1])
            nearest = (PILLAR[0] + (p[0] - PILLAR[0]) / d * RADIUS - p[0], PILLAR[1] + (p[1] - PILLAR[1]) / d * RADIUS - p[1])
            if math.hypot(*nearest) > RANGE - 0.01:
                return
            best = min((math.dist((q.position.x, q.position.y, q.position.z), (*nearest, 0.0)) for q in msg.poses), default=1e9)
            seen[name][0 if best < 0.01 else 1] += 1

    def on_force(msg):
        f = msg.wrench.force
        with lock:
            forces[0] += 1
            forces[1] = max(forces[1], math.sqrt(f.x * f.x + f.y * f.y + f.z * f.z))

    def on_sim0(msg):
        t = msg.header.stamp.to_sec()
        with lock:
            sim0[0 if t <= 4.0 else 1 if t <= 6.0 else 2] = msg.pose.pose.position.y

    rospy.init_node("ghosts_peer", anonymous=True, disable_signals=True)
    subs = [rospy.Subscriber("/clock", Clock, on_clock, tcp_nodelay=True),
            rospy.Subscriber("/op0/force", WrenchStamped, on_force, tcp_nodelay=True),
            rospy.Subscriber("/sim0/odom", Odometry, on_sim0, tcp_nodelay=True)]
    for n in samples:
        subs.append(rospy.Subscriber("/%s/odom" % n, Odometry, on_odom, callback_args=n, tcp_nodelay=True))
        subs.append(rospy.Subscriber("/%s/range" % n, PoseArray, on_range, callback_args=n, tcp_nodelay=True))
    poses = {n: rospy.Publisher("/%s/pose" % n, PoseStamped, queue_size=100) for n in samples}
    twist = rospy.Publisher("/op0/cmd_vel", Twist, queue_size=10)
    next_twist = 4.0
    started = time.time()
    while True:
        with lock:
            t_now = now[0]
            idle = time.time() - last_tick[0]
        # (ROS 1 drops what is published before a subscriber is connected: wait for ssx's)
        connected = all(pub.get_num_connections() > 0 for pub in poses.values()) and twist.get_num_connections() > 0
        if t_now >= 0 and connected:
            for n, s in samples.items():
                while sent[n] < len(s) and s[sent[n]][0] - LEAD <= t_now:
                    p = s[sent[n]]
                    m = PoseStamped()
                    m.header.stamp = rospy.Time.from_sec(p[0])
                    m.header.frame_id = "world"
                    m.pose.position.x, m.pose.position.y, m.pose.position.z = p[1:4]
                    m.pose.orientation.w, m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z = p[4:8]
                    with lock:
                        sent_at[n].append(t_now)
                        sent[n] += 1
                    poses[n].publish(m)
            if next_twist <= t_now < 6.0:
                m = Twist()
                m.linear.y = 0.4
                twist.publish(m)
                next_twist += 0.05
        if (t_now >= 0 and idle > 3.0) or (t_now < 0 and time.time() - started > 30):
            break
        time.sleep(0.001)

    ok = True
    with lock:
        for n in samples:
            print("%s: %d poses sent; %d odometry messages within %.6f m of the file's poses; the pillar seen in %d "
                  "range messages, missed in %d" % (n, sent[n], odoms[n], odom_error[n], seen[n][0], seen[n][1]))
            ok = ok and odoms[n] > 100 and odom_error[n] < 1e-3 and seen[n][0] > 10 and seen[n][1] == 0
        print("op0: %d force messages, the largest %.3f N" % (forces[0], forces[1]))
        ok = ok and forces[0] > 100
        if len(sim0) == 3:
            moved, coast = sim0[1] - sim0[0], sim0[2] - sim0[1]
            print("sim0 moved %.3f m north while steered, %.3f m after" % (moved, coast))
            ok = ok and 0.6 < moved < 1.0 and -0.1 < coast < 0.35
        else:
            print("sim0: no odometry before, during and after the commands")
            ok = False
    for s in subs:
        s.unregister()
    rospy.signal_shutdown("done")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()

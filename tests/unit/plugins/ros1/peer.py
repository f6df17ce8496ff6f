#!/usr/bin/python3
"""A controller outside ssx: subscribes to each robot's odometry and sends it a set-point 1 m east,
0.5 m south of where it started, 1.5 m up; succeeds when every robot has held within 0.1 m of its
set-point for 1 s of simulated time.

usage: peer.py COUNT [TIMEOUT_S]   (robots q0 .. q<COUNT-1>; exit 0 on success, 1 otherwise; it also
                                    checks that /clock came at its 100 Hz of simulated time)
       peer.py COUNT TIMEOUT_S --lockstep  (answer each odometry message after a varying delay of
                                       0-30 ms with a set-point stamped like it, and check lock-step:
                                       no odometry of a round may arrive before every robot's answer
                                       to the round before was sent; exit 0 when there were at least
                                       100 rounds, no violation, and every robot held its set-point)
       peer.py COUNT SECONDS --bench  (answer every odometry message at once with a set-point stamped
                                       like it, for SECONDS; print how many messages came per robot)
       peer.py COUNT TIMEOUT_S --cmd-vel  (send /<robot>/cmd_vel, a Twist 0.5 m/s forward from 4 to 6 s of
                                       simulated time (the robots took off from the ground before), then 0;
                                       exit 0 once every robot moved 0.7-1.3 m along x from 4 s to 8 s and
                                       its odometry reached 0.4 m/s)
       peer.py COUNT TIMEOUT_S --drive V W  (as a ROS user drives a wheeled robot: a Twist of V m/s forward
                                       and W rad/s about z for 2 s of simulated time (from 1 s or once
                                       connected), then 0; exit 0 once every robot's odometry went 2 V
                                       along its path (within 15 %), turned by 2 W (within 10 %, unwrapped)
                                       and stood 4 s after the start)
"""
import math
import sys
import threading
import time

import rospy
from geometry_msgs.msg import PoseStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock


def fly_by_velocity(names, timeout):
    """Twists in the robots' frame: 0.5 m/s forward from 4 s to 6 s of simulated time."""
    lock = threading.Lock()
    x_at_go, fastest, latest, x_now = {}, {}, {}, {}

    def on_odom(msg, name):
        t = msg.header.stamp.to_sec()
        with lock:
            latest[name] = t
            x_now[name] = msg.pose.pose.position.x
            if t >= 4.0 and name not in x_at_go:
                x_at_go[name] = msg.pose.pose.position.x
            fastest[name] = max(fastest.get(name, 0.0), msg.twist.twist.linear.x)

    subs = [rospy.Subscriber("/%s/odom" % n, Odometry, on_odom, callback_args=n, tcp_nodelay=True) for n in names]
    pubs = {n: rospy.Publisher("/%s/cmd_vel" % n, Twist, queue_size=10) for n in names}
    start = time.time()
    while time.time() - start < timeout:
        with lock:
            state = {n: (latest.get(n, -1.0), x_now.get(n), x_at_go.get(n), fastest.get(n, 0.0)) for n in names}
        for n in names:
            if state[n][0] >= 0:
                m = Twist()
                m.linear.x = 0.5 if 4.0 <= state[n][0] < 6.0 else 0.0
                pubs[n].publish(m)
        if all(state[n][0] >= 8.0 for n in names):
            moved = {n: state[n][1] - state[n][2] for n in names}
            ok = all(0.7 <= moved[n] <= 1.3 and state[n][3] >= 0.4 for n in names)
            print("peer: cmd_vel: moved %s m, fastest %s m/s" % (" ".join("%.3f" % moved[n] for n in names),
                                                               " ".join("%.2f" % state[n][3] for n in names)))
            return 0 if ok else 1
        time.sleep(0.05)
    print("peer: cmd_vel: timed out")
    return 1


def drive(names, timeout, v, w):
    """Twists in the robots' frame: v forward, w about z for 2 s of simulated time, from the first
    odometry at or after 1 s that came once ssx was connected to the robot's cmd_vel (a ROS 1
    subscriber connects to a new publisher some time after it appears)."""
    lock = threading.Lock()
    path, turned, last, latest, result, go = {}, {}, {}, {}, {}, {}
    pubs = {n: rospy.Publisher("/%s/cmd_vel" % n, Twist, queue_size=10) for n in names}

    def on_odom(msg, name):
        t = msg.header.stamp.to_sec()
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        with lock:
            latest[name] = t
            if name not in go and t >= 1.0 and pubs[name].get_num_connections() > 0:
                go[name] = t
                path[name], turned[name] = 0.0, 0.0
            elif name in go and name not in result:
                x, y, a = last[name]
                path[name] += math.hypot(p.x - x, p.y - y)
                turned[name] += math.remainder(yaw - a, 2 * math.pi)
                if t >= go[name] + 4.0:
                    lin = msg.twist.twist.linear
                    result[name] = (path[name], turned[name], math.hypot(lin.x, lin.y))
            last[name] = (p.x, p.y, yaw)

    subs = [rospy.Subscriber("/%s/odom" % n, Odometry, on_odom, callback_args=n, tcp_nodelay=True) for n in names]
    start = time.time()
    while time.time() - start < timeout:
        with lock:
            stamps = {n: (t, go.get(n)) for n, t in latest.items()}
            done = dict(result)
        for n, (t, t0) in stamps.items():
            m = Twist()
            if t0 is not None and t0 <= t < t0 + 2.0:
                m.linear.x, m.angular.z = v, w
            pubs[n].publish(m)
        if len(done) == len(names):
            ok = True
            for n in names:
                driven, angle, speed = done[n]
                good = (abs(driven - 2 * v) <= 0.15 * abs(2 * v) + 1e-3 and abs(angle - 2 * w) <= 0.1 * abs(2 * w) + 1e-2
                        and speed <= 0.01)
                ok &= good
                print("peer: %s: path %.4f m (%.4f asked), turned %.4f rad (%.4f asked), %.4f m/s 4 s after the start%s"
                      % (n, driven, 2 * v, angle, 2 * w, speed, "" if good else "  FAILED"))
            return 0 if ok else 1
        time.sleep(0.01)
    print("peer: drive: timed out")
    return 1


def main():
    count = int(sys.argv[1])
    timeout = float(sys.argv[2]) if len(sys.argv) > 2 else 40.0
    rospy.init_node("peer", anonymous=True, disable_signals=True)
    names = ["q%d" % i for i in range(count)]
    target, error, held_since, last_stamp, received = {}, {}, {}, {}, {}
    pubs = {n: rospy.Publisher("/%s/setpoint" % n, PoseStamped, queue_size=10) for n in names}

    bench = "--bench" in sys.argv
    lockstep = "--lockstep" in sys.argv
    period = 0.02  # odometry at 50 Hz of simulated time
    lock = threading.Lock()
    answered = {}          # robot -> newest stamp answered (sent)
    pending = []           # (due wall time, robot, stamp)
    violations = []
    rounds = set()

    def answer(name, stamp, ros_stamp):
        m = PoseStamped()
        m.header.stamp = ros_stamp  # exactly the odometry's (a float would round some below it)
        m.pose.position.x, m.pose.position.y, m.pose.position.z = target[name]
        m.pose.orientation.w = 1.0
        pubs[name].publish(m)
        answered[name] = max(answered.get(name, -1.0), stamp)

    def answerer():
        while not rospy.is_shutdown():
            now = time.time()
            with lock:
                due = [p for p in pending if p[0] <= now]
                for p in due:
                    pending.remove(p)
                    answer(p[1], p[2], p[3])
            time.sleep(0.001)

    def on_odom(msg, name):
        p = msg.pose.pose.position
        t = msg.header.stamp.to_sec()
        received[name] = received.get(name, 0) + 1
        if name not in target:
            target[name] = (p.x + 1.0, p.y - 0.5, 1.5)
        if lockstep:
            with lock:
                # the round before this one must have been answered by every robot already
                previous = t - period
                if rounds and previous >= min(rounds) - 1e-9:
                    late = [n for n in names if answered.get(n, -1.0) < previous - 1e-9]
                    if late:
                        violations.append((t, name, late[:3]))
                rounds.add(round(t, 6))
                # a delay of 0-30 ms that varies with the robot and the round
                delay = ((hash((name, round(t, 6))) % 31) / 1000.0)
                pending.append((time.time() + delay, name, t, msg.header.stamp))
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

    if "--cmd-vel" in sys.argv:
        return fly_by_velocity(names, timeout)
    if "--drive" in sys.argv:
        i = sys.argv.index("--drive")
        return drive(names, timeout, float(sys.argv[i + 1]), float(sys.argv[i + 2]))
    subs = [rospy.Subscriber("/%s/odom" % n, Odometry, on_odom, callback_args=n, tcp_nodelay=True) for n in names]
    clock_stamps = []
    clock_sub = rospy.Subscriber("/clock", Clock, lambda m: clock_stamps.append(m.clock.to_sec()), queue_size=1000)
    start = time.time()
    if lockstep:
        threading.Thread(target=answerer, daemon=True).start()
        # answer until the simulation is over: no odometry for 2 s of wall time
        last_count, quiet_since = -1, time.time()
        while time.time() - start < timeout:
            with lock:
                n_rounds = len(rounds)
            if n_rounds != last_count:
                last_count, quiet_since = n_rounds, time.time()
            elif n_rounds > 0 and time.time() - quiet_since > 2.0:
                break
            time.sleep(0.05)
        done = [n for n in names if n in held_since and last_stamp[n] - held_since[n] >= 1.0]
        with lock:
            print("peer: lock-step: %d rounds, %d violations%s; %d of %d robots held their set-points"
                  % (len(rounds), len(violations), (" (first: t=%.3f %s before %s answered)" % violations[0])
                     if violations else "", len(done), count))
        return 0 if not violations and len(rounds) >= 100 and len(done) == count else 1
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
            # /clock at 100 Hz of simulated time: at least 90 % of the ticks between the first and last heard
            ticks = list(clock_stamps)
            expected = (ticks[-1] - ticks[0]) / 0.01 + 1 if len(ticks) > 1 else 0
            print("peer: /clock: %d messages over %.2f s of simulated time (%d expected)"
                  % (len(ticks), ticks[-1] - ticks[0] if ticks else 0.0, round(expected)))
            return 0 if expected >= 100 and len(ticks) >= 0.9 * expected else 1
        time.sleep(1.0 / rate)
    print("peer: timed out; odometry from %d of %d robots; errors: %s"
          % (len(target), count, " ".join("%s=%.3f" % (n, error.get(n, float("nan"))) for n in names)))
    return 1


if __name__ == "__main__":
    code = main()
    rospy.signal_shutdown("done")
    sys.exit(code)

#!/usr/bin/env python3
"""What ssx.learn delivers per second from Python on this machine, beside the published figures
of other CPU learning environments.

    PYTHONPATH=build/python python3 examples/learn/bench_learn.py [--envs 1024] [--batches 100]
    PYTHONPATH=build/python python3 examples/learn/bench_learn.py --against OTHER/build/python [--rounds 3]
    PYTHONPATH=build/python python3 examples/learn/bench_learn.py --huge-pages [--rounds 3]

Prints, for the Crazyflie `goto` task (actions at 50 Hz over 500 Hz physics, observations of pose,
velocity and IMU) and for `formation` (64 environments of 16 robots): agent steps per second,
the part of a step spent in Python (everything but the C++ stepping), the time to reset one
environment, whether the batch allocates per step (tracemalloc over 20 and 200 steps, Python side), what a
Crazyflie's step costs as a world of its own against one world of many, with free bodies stepped
by ssx against every body handed to ODE, stepped 10 against 100 steps a call, and a copy's memory. With --against, only the
two throughputs, of this build and of another build's Python package, in separate processes taking
turns (the machine's speed swings between minutes: builds are compared in the same minutes); with
--huge-pages, of this build with glibc's malloc on transparent huge pages and without.
"""
import argparse
import os
import subprocess
import sys
import time
import tracemalloc

import numpy as np

import ssx.learn as learn

PEERS = [
    ("EnvPool, MuJoCo, per core", "about 12,000 steps/s"),
    ("QuadSwarm, 16 cores", "62,000 samples/s"),
    ("gym-pybullet-drones", "about 15,000 robot steps/s"),
]
TARGET = 150_000


def in_turns(first, second, rounds):
    """Seconds spent in `first()` and in `second()`, called in turns `rounds` times (the machine's
    speed drifts between minutes: timings compared are taken in the same minutes)."""
    a = b = 0.0
    for _ in range(rounds):
        start = time.perf_counter()
        first()
        middle = time.perf_counter()
        second()
        a += middle - start
        b += time.perf_counter() - middle
    return a, b


def measure(env, batches, agents_per_env):
    env.reset(seed=1)
    actions = np.zeros(env.action_space.shape, dtype=np.float32)
    for _ in range(5):
        env.step(actions)
    # a whole step, then the C++ stepping alone
    sim, n = env._b.sim, env._b.steps_per_action
    total, core = in_turns(lambda: env.step(actions), lambda: sim.step(n), batches)
    rate = env.num_envs * agents_per_env * batches / total
    return rate, total / batches, (total - core) / batches


def allocations(env, batches=20):
    actions = np.zeros(env.action_space.shape, dtype=np.float32)
    env.step(actions)
    tracemalloc.start()
    env.step(actions)
    first = tracemalloc.get_traced_memory()[0]
    for _ in range(batches):
        env.step(actions)
    grown = tracemalloc.get_traced_memory()[0] - first
    tracemalloc.stop()
    return grown


RANDOMIZE = {"mass": (0.9, 1.1), "thrust_coefficient": (0.95, 1.05), "time_constant_up": (0.8, 1.25),
             "gyro_noise": (0.5, 2.0), "wind_x": (-0.5, 0.5)}


def reset_one(env, count=200):
    """Seconds per reset of one environment (the task's draw and the domain randomisation included)."""
    start = time.perf_counter()
    for k in range(count):
        env._b.reset_copies([k % env.num_envs])
    return (time.perf_counter() - start) / count


def per_world_cost(robots=256, steps=500):
    """us per Crazyflie step on one thread: as `robots` worlds of one, and as one world of `robots`."""
    import ssx

    task = learn.GoTo()
    copies = ssx._ssx.VectorEnvironment(task.scene(), robots, base_dir=ssx.data_directory(), threads=1)
    task.robots = robots
    world = ssx.load_scene_string(task.scene(), base_dir=ssx.data_directory(), threads=1)
    for sim in (copies, world):
        sim.step(200)
    separate, together = in_turns(lambda: copies.step(steps), lambda: world.step(steps), 4)
    copies.close()
    world.close()
    return separate / (4 * steps * robots) * 1e6, together / (4 * steps * robots) * 1e6


def memory_per_copy(copies=200):
    """KiB allocated (glibc's mallinfo2) and resident (the growth of the process's peak resident
    set: call it before anything else) per goto copy, after 10 steps."""
    import ctypes
    import resource

    import ssx

    class MallInfo(ctypes.Structure):
        _fields_ = [(n, ctypes.c_size_t) for n in
                    "arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks keepcost".split()]

    libc = ctypes.CDLL("libc.so.6")
    libc.mallinfo2.restype = MallInfo

    def allocated():
        m = libc.mallinfo2()
        return m.uordblks + m.hblkhd

    a0, r0 = allocated(), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    sim = ssx._ssx.VectorEnvironment(learn.GoTo().scene(), copies, base_dir=ssx.data_directory(), threads=1)
    sim.step(10)
    a1, r1 = allocated(), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    sim.close()
    return (a1 - a0) / copies / 1024, (r1 - r0) / copies


class _GoToAllByOde(learn.GoTo):
    """goto with every body handed to ODE's world step (the same bits, for the comparison)."""
    name = "goto_all_by_ode"

    def scene(self):
        return super().scene().replace("<ground/>", '<physics engine="ode" integrate_free_bodies="false"/>\n  <ground/>')


def free_bodies_cost(copies=256, steps=200, rounds=4):
    """us per copy step on one thread (C++ only): free bodies stepped by ssx, and every body by ODE."""
    envs = [learn.VectorEnv(task, num_envs=copies, threads=1) for task in ("goto", _GoToAllByOde())]
    for e in envs:
        e.reset(seed=1)
    free, ode = in_turns(lambda: envs[0].sim.step(steps), lambda: envs[1].sim.step(steps), rounds)
    for e in envs:
        e.close()
    return free / (rounds * steps * copies) * 1e6, ode / (rounds * steps * copies) * 1e6


def cold_copies(copies=1024, rounds=4):
    """us per copy step on one thread (C++ only), the copies stepped 10 and 100 steps a call."""
    env = learn.VectorEnv("goto", num_envs=copies, threads=1)
    env.reset(seed=1)
    ten, hundred = in_turns(lambda: [env.sim.step(10) for _ in range(10)], lambda: env.sim.step(100), rounds)
    env.close()
    return ten / (rounds * 100 * copies) * 1e6, hundred / (rounds * 100 * copies) * 1e6


def throughputs(args):
    """The goto and formation throughputs alone, one line."""
    env = learn.VectorEnv("goto", num_envs=args.envs, threads=args.threads)
    goto, goto_batch, _ = measure(env, args.batches, 1)
    env.close()
    env = learn.VectorEnv("formation", num_envs=64, robots=16, threads=args.threads)
    formation, formation_batch, _ = measure(env, max(10, args.batches // 2), 16)
    env.close()
    print(f"goto {goto:,.0f} agent steps/s ({goto_batch * 1e3:.2f} ms a batch step), formation {formation:,.0f} "
          f"({formation_batch * 1e3:.2f} ms)", flush=True)


def in_processes(args, variants):
    """The throughputs of each variant (a name and the environment of its process), in turns,
    each in a process of its own."""
    for r in range(args.rounds):
        for name, env in variants:
            line = subprocess.run([sys.executable, __file__, "--throughput-only", "--envs", str(args.envs),
                                   "--batches", str(args.batches)], env=env, check=True, capture_output=True,
                                  text=True).stdout.strip().splitlines()[-1]
            print(f"round {r + 1}, {name}: {line}", flush=True)


def against(args):
    """This build and another's, in turns, each in a process of its own."""
    here = os.path.dirname(os.path.dirname(learn.__file__))
    in_processes(args, [(f"this build ({here})", dict(os.environ, PYTHONPATH=here)),
                        (f"other build ({args.against})", dict(os.environ, PYTHONPATH=args.against))])


def huge_pages(args):
    """The same build with glibc's malloc on transparent huge pages and without, in turns (a
    thousand copies' memory spans more pages than the processor's TLB holds)."""
    plain = {k: v for k, v in os.environ.items() if k != "GLIBC_TUNABLES"}
    in_processes(args, [("malloc on huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1)",
                         dict(plain, GLIBC_TUNABLES="glibc.malloc.hugetlb=1")), ("malloc as it comes", plain)])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--envs", type=int, default=1024)
    parser.add_argument("--batches", type=int, default=100)
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--against", metavar="PYTHON_DIR", help="another build's python directory, in turns")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--huge-pages", action="store_true",
                        help="throughputs with glibc's malloc on transparent huge pages and without, in turns")
    parser.add_argument("--throughput-only", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.throughput_only:
        return throughputs(args)
    if args.against:
        return against(args)
    if args.huge_pages:
        return huge_pages(args)
    kib, resident = memory_per_copy()  # first: the peak resident set has not grown yet
    print(f"machine: {os.cpu_count()} cores")
    for name, figure in PEERS:
        print(f"  peer: {name}: {figure}")

    env = learn.VectorEnv("goto", num_envs=args.envs, threads=args.threads)
    rate, batch, python = measure(env, args.batches, 1)
    print(f"goto, {args.envs} Crazyflies, attitude actions at 50 Hz over 500 Hz physics, on {env._b.sim.threads} threads:")
    print(f"  {rate:,.0f} agent steps/s (target {TARGET:,}); {batch * 1e3:.2f} ms a batch step, "
          f"of which {python * 1e3:.2f} ms in Python ({python / args.envs * 1e6:.2f} us per agent step)")
    sim, state = env._b, env._b.start_state
    start = time.perf_counter()
    for k in range(200):
        sim.reset_copies([k % args.envs])
    whole = (time.perf_counter() - start) / 200
    start = time.perf_counter()
    for k in range(200):
        sim.sim.reset([k % args.envs], state, [k])
    core = (time.perf_counter() - start) / 200
    print(f"  reset of one environment: {whole * 1e6:.0f} us (target under 50 us), of which {core * 1e6:.0f} us "
          f"restoring and reseeding the copy (C++), the rest in Python (the task's draw, moving the robots)")
    # (what the last step leaves alive is counted too: memory that grows from 20 to 200 steps is per step)
    print(f"  Python memory grown over 20 and over 200 batch steps: {allocations(env)} and "
          f"{allocations(env, 200)} bytes")
    env.close()
    randomized = learn.VectorEnv("goto", num_envs=args.envs, threads=args.threads, randomize=RANDOMIZE)
    plain = learn.VectorEnv("goto", num_envs=args.envs, threads=args.threads)
    # five rounds of 200 resets each, in turns
    with_draws, without = in_turns(lambda: reset_one(randomized), lambda: reset_one(plain), 5)
    print(f"  reset of one environment with {len(RANDOMIZE)} constants drawn: {with_draws / 1000 * 1e6:.0f} us, "
          f"{without / 1000 * 1e6:.0f} us without (in turns)")
    randomized.close()
    plain.close()

    separate, together = per_world_cost()
    print(f"a Crazyflie's step on one thread: {separate:.2f} us as a world of its own, {together:.2f} us as one "
          f"of 256 in one world")
    free, ode = free_bodies_cost()
    print(f"  with free bodies stepped by ssx {free:.2f} us, with every body handed to ODE {ode:.2f} us "
          f"(256 copies, in turns)")
    ten, hundred = cold_copies()
    print(f"  1,024 copies stepped 10 steps a call: {ten:.2f} us per copy step, 100 a call: {hundred:.2f} us")
    print(f"  memory per copy: {kib:.0f} KiB allocated, {resident:.0f} KiB resident (200 copies, after 10 steps)")

    env = learn.VectorEnv("formation", num_envs=64, robots=16, threads=args.threads)
    rate, batch, python = measure(env, max(10, args.batches // 2), 16)
    print(f"formation, 64 environments of 16 Crazyflies, velocity actions at 50 Hz over 500 Hz physics:")
    print(f"  {rate:,.0f} agent steps/s (target {TARGET:,}); {batch * 1e3:.2f} ms a batch step, "
          f"of which {python * 1e3:.2f} ms in Python")
    env.close()


if __name__ == "__main__":
    main()

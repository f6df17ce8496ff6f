#!/usr/bin/env python3
"""A swarm flown from Python: N mk_quads take off from a grid and fly a rotating ring; a vectorised
numpy controller computes every robot's set-point (position and velocity feed-forward) and sends
them all with one set_setpoints call every 20 ms of simulated time. Plots the paths and the
tracking error with matplotlib.

    PYTHONPATH=build/python python3 examples/python/swarm_controller.py --n 16 --out ring.png
"""
import argparse
import sys

import numpy as np

import ssx

SCENE = """<scene>
  <environment timestep="0.002" seed="{seed}"/>
  <type name="mk_quad"/>
  <ground/>
  <swarm type="mk_quad" count="{n}" name="q{{i}}" spacing="1.5" xyz="-{half} -{half} 0.05">
    <driver reference="external"/>
  </swarm>
</scene>"""


class RingController:
    """Every robot holds its slot on a ring of `radius` at `height` that turns at `omega` rad/s.
    Until `climb` seconds, each robot flies a straight line from its start to its slot; the slots
    are handed out in the order of the robots' bearings from the swarm's centre, so that no two
    of those lines cross."""

    def __init__(self, start, radius=3.0, height=1.5, omega=0.3, climb=4.0):
        self.start = start
        n = len(start)
        offset = start[:, :2] - start[:, :2].mean(axis=0)
        bearing = np.arctan2(offset[:, 1], offset[:, 0])
        self.phase = np.empty(n)
        self.phase[np.argsort(bearing, kind="stable")] = bearing.min() + 2 * np.pi * np.arange(n) / n
        self.radius, self.height, self.omega, self.climb = radius, height, omega, climb

    def reference(self, t):
        """Positions and velocities (N x 3) of the ring slots at time t."""
        angle = self.phase + self.omega * max(0.0, t - self.climb)
        ring = np.stack([self.radius * np.cos(angle), self.radius * np.sin(angle), np.full_like(angle, self.height)], 1)
        turning = 1.0 if t >= self.climb else 0.0
        velocity = turning * self.omega * self.radius * np.stack([-np.sin(angle), np.cos(angle), np.zeros_like(angle)], 1)
        if t < self.climb:
            # a straight line from the start to the slot, at constant speed
            s = t / self.climb
            return (1 - s) * self.start + s * ring, (ring - self.start) / self.climb
        return ring, velocity


def fly(n=16, seconds=20.0, seed=1, threads=None, period=0.02):
    """Flies the ring; returns (times, positions T x N x 3, references T x N x 3)."""
    half = 0.75 * (int(np.ceil(np.sqrt(n))) - 1)
    env = ssx.load_scene_string(SCENE.format(n=n, seed=seed, half=half), label="swarm_controller.xml", threads=threads)
    controller = RingController(env.positions())
    steps = round(period / env.timestep)
    times, flown, wanted = [], [], []
    while env.time < seconds - 1e-9:
        position, velocity = controller.reference(env.time)
        env.set_setpoints(position, velocity)
        env.step(steps)
        times.append(env.time)
        flown.append(env.positions())
        wanted.append(controller.reference(env.time)[0])
    env.close()
    return np.array(times), np.array(flown), np.array(wanted)


def plot(times, flown, wanted, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    error = np.linalg.norm(flown - wanted, axis=2)
    fig, (top, err) = plt.subplots(1, 2, figsize=(11, 4.5))
    for i in range(flown.shape[1]):
        top.plot(flown[:, i, 0], flown[:, i, 1], lw=0.8)
    top.set_aspect("equal")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    top.set_title(f"{flown.shape[1]} mk_quads, set-points from numpy every 20 ms")
    err.plot(times, error.mean(axis=1), label="mean")
    err.plot(times, error.max(axis=1), label="max")
    err.set_xlabel("simulated time (s)")
    err.set_ylabel("distance to the set-point (m)")
    err.set_yscale("log")
    err.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=16)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default="swarm_controller.png", help="the plot (PNG); empty: no plot")
    args = parser.parse_args(argv)
    times, flown, wanted = fly(args.n, args.seconds, args.seed)
    error = np.linalg.norm(flown - wanted, axis=2)
    turning = times >= 8.0  # after the climb and its transient
    print(f"robots={args.n} simulated_s={times[-1]:.2f} "
          f"mean_error_m={error[turning].mean():.4f} max_error_m={error[turning].max():.4f}")
    if args.out:
        try:
            import matplotlib  # noqa: F401 (optional: only the plot needs it)
        except ImportError:
            print("no plot: matplotlib is not installed (apt-get install python3-matplotlib)")
            return 0
        plot(times, flown, wanted, args.out)
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

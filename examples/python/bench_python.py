#!/usr/bin/env python3
"""What the Python layer costs, printed as key=value lines:

  positions  n=10000 positions_ms=...        reading the N x 3 positions of 10,000 quadrotors
  step       overhead_us=... cpp_step_us=... one env.step() called from Python, minus the same step
                                             taken inside one env.step(n) call (a C++ loop)

Targets: positions of 10,000 under 1 ms; overhead under 10 us.
    PYTHONPATH=build/python python3 examples/python/bench_python.py
"""
import argparse
import statistics
import time

import ssx

SWARM = """<scene>
  <environment timestep="0.002" seed="1"/>
  <type name="mk_quad"/>
  <ground/>
  <swarm type="mk_quad" count="{n}" spacing="1.5" xyz="0 0 1"/>
</scene>"""


def median_of(fn, repeats):
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--n", type=int, default=10000)
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()

    env = ssx.load_scene_string(SWARM.format(n=args.n), threads=args.threads)
    env.step()
    for name in ("positions", "orientations", "linear_velocities"):
        read = getattr(env, name)
        read()
        print(f"{name} n={args.n} {name}_ms={1e3 * median_of(read, 200):.3f}")

    # one robot: the step itself is small, so the call's cost shows
    one = ssx.load_scene_string(SWARM.format(n=1), threads=1)
    one.step(1000)
    n = args.steps

    def from_python():
        for _ in range(n):
            one.step()

    loop = median_of(from_python, 5) / n
    inside = median_of(lambda: one.step(n), 5) / n
    print(f"step robots=1 steps={n} python_step_us={1e6 * loop:.3f} cpp_step_us={1e6 * inside:.3f} "
          f"overhead_us={1e6 * (loop - inside):.3f}")


if __name__ == "__main__":
    main()

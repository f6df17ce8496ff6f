#!/usr/bin/env python3
"""A reset / step / observation environment for learning, on ssx (no RL library needed).

Task: every quadrotor of a small swarm must reach its goal, a point drawn per episode, by
commanding a velocity. One `step(action)` holds the action for `control_period` seconds of
simulated time. `reset()` restores the state saved once after load (all robots hovering), so
every episode starts from the same bits, and the episode's goals come from its seed.

    PYTHONPATH=build/python python3 examples/python/learning_env.py --episodes 3
"""
import argparse
import sys

import numpy as np

import ssx

SCENE = """<scene>
  <environment timestep="0.002" seed="11"/>
  <type name="mk_quad"/>
  <ground/>
  <swarm type="mk_quad" count="{n}" name="q{{i}}" spacing="2" xyz="0 0 0.05">
    <driver reference="external"/>
  </swarm>
</scene>"""


class SwarmReachEnv:
    """Observation: per robot, position minus goal and velocity (N x 6). Action: per robot, a
    velocity (N x 3, m/s, clipped to max_speed); the set-point moves along it. Reward: minus the
    mean distance to the goals. Done after `horizon` steps."""

    def __init__(self, n=4, control_period=0.1, horizon=60, max_speed=1.0, threads=None):
        self.sim = ssx.load_scene_string(SCENE.format(n=n), label="learning_env.xml", threads=threads)
        self.n = n
        self.steps_per_action = round(control_period / self.sim.timestep)
        self.control_period = control_period
        self.horizon = horizon
        self.max_speed = max_speed
        # take off and hover 1 m up, then keep that state: every reset returns to it
        start = self.sim.positions()
        self.sim.set_setpoints(start + [0, 0, 1.0])
        self.sim.step(round(4.0 / self.sim.timestep))
        self.initial = self.sim.save_state()
        self.goals = None
        self.target = None
        self.t = 0

    def reset(self, seed=0):
        self.sim.restore_state(self.initial)
        self.sim.reseed(seed)  # the sensors' noise and the wind of this episode: the seed's, not the saved state's
        rng = np.random.default_rng(seed)
        home = self.sim.positions()
        self.goals = home + rng.uniform([-1.5, -1.5, 0.0], [1.5, 1.5, 1.0], size=(self.n, 3))
        self.target = home.copy()
        self.t = 0
        return self.observation()

    def observation(self):
        return np.hstack([self.sim.positions() - self.goals, self.sim.linear_velocities()])

    def step(self, action):
        velocity = np.clip(np.asarray(action, dtype=float).reshape(self.n, 3), -self.max_speed, self.max_speed)
        self.target = self.target + velocity * self.control_period
        self.sim.set_setpoints(self.target, velocity)
        self.sim.step(self.steps_per_action)
        self.t += 1
        obs = self.observation()
        reward = -float(np.linalg.norm(obs[:, :3], axis=1).mean())
        return obs, reward, self.t >= self.horizon, {"time": self.sim.time}


def proportional_policy(obs, gain=1.0):
    """Flies straight at the goal: velocity = -gain * (position - goal)."""
    return -gain * obs[:, :3]


def episode(env, policy, seed):
    obs = env.reset(seed)
    total, done = 0.0, False
    while not done:
        obs, reward, done, _ = env.step(policy(obs))
        total += reward
    return total, obs


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=3)
    parser.add_argument("--robots", type=int, default=4)
    args = parser.parse_args(argv)
    env = SwarmReachEnv(n=args.robots)
    for k in range(args.episodes):
        idle, _ = episode(env, lambda o: np.zeros((args.robots, 3)), seed=k)
        ret, obs = episode(env, proportional_policy, seed=k)
        print(f"episode={k} return_idle={idle:.2f} return_proportional={ret:.2f} "
              f"final_mean_distance_m={np.linalg.norm(obs[:, :3], axis=1).mean():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

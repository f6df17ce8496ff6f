#!/usr/bin/env python3
"""Trains a policy on an ssx.learn task with the PPO of ppo.py and prints how well it does.

    PYTHONPATH=build/python python3 examples/learn/train.py goto      [--minutes 15] [--out DIR]
    PYTHONPATH=build/python python3 examples/learn/train.py formation [--minutes 15] [--out DIR]

goto: one Crazyflie per environment at the attitude level (roll, pitch, yaw rate, thrust at
50 Hz), 64 environments; afterwards 100 episodes with goals it never trained on (seeds from
1,000,000 on), its success rate (within 10 cm of the goal at the episode's end) printed.
formation: 8 Crazyflies per environment at the velocity level, one policy shared by the robots,
16 environments; afterwards 20 held-out episodes, their mean distance to the slots at the end and
how often two robots came closer than 15 cm (pairs times steps).
The learning curve goes to DIR/curve.csv and DIR/curve.png (DIR must not exist yet, or be empty).
"""
import argparse
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import ssx.learn as learn  # noqa: E402
from ppo import PPO, plot_curve  # noqa: E402

SETUPS = {
    "goto": dict(env=dict(task="goto", num_envs=64, level="attitude"), ppo=dict(horizon=64, epochs=5, minibatches=4),
                 held_out=100),
    "formation": dict(env=dict(task="formation", num_envs=16, robots=8), ppo=dict(horizon=64, epochs=4, minibatches=4),
                      held_out=20),
}


def evaluate(agent, task, episodes, **options):
    """Held-out episodes (seeds 1,000,000 and up), the deterministic policy: per episode its final
    distance, whether it succeeded, its collisions."""
    env = learn.VectorEnv(task, num_envs=episodes, **options)
    obs, _ = env.reset(seed=1_000_000)
    collisions = np.zeros(episodes)
    final = None
    for _ in range(env.task.horizon):
        obs, reward, term, trunc, infos = env.step(agent.policy(obs))
        collisions += infos.get("collisions", 0)
        ended = term | trunc
        if final is None:
            final = {"distance": np.full(episodes, np.nan), "success": np.zeros(episodes, bool), "crashed": np.zeros(episodes, bool)}
        live = np.isnan(final["distance"]) & ended
        final["distance"][live] = infos["distance"][live]
        final["success"][live] = infos.get("success", np.zeros(episodes, bool))[live] & ~term[live]
        final["crashed"][live] = term[live]
    env.close()
    final["collisions"] = collisions
    return final


def main():
    parser = argparse.ArgumentParser(description="Trains a policy on an ssx.learn task with a small PPO.")
    parser.add_argument("task", choices=sorted(SETUPS))
    parser.add_argument("--minutes", type=float, default=15.0, help="training time (default 15)")
    parser.add_argument("--steps", type=int, default=None, help="agent steps to train instead of a time")
    parser.add_argument("--envs", type=int, default=None, help="environments (default: the task's)")
    parser.add_argument("--out", type=pathlib.Path, default=None, help="where the curve goes (default: learn-TASK)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    setup = SETUPS[args.task]
    out = args.out or pathlib.Path(f"learn-{args.task}")
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        parser.error(f"{out} exists and is not an empty folder; give another with --out (nothing is overwritten)")
    env_options = dict(setup["env"])
    if args.envs:
        env_options["num_envs"] = args.envs
    env = learn.VectorEnv(**env_options)
    agent = PPO(env, seed=args.seed, **setup["ppo"])
    out.mkdir(parents=True, exist_ok=True)

    def log(row):
        print(f"{row[0]:>10,} agent steps  {row[1]:7.1f} s  mean return {row[2]:8.3f}  ({row[3]} episodes)", flush=True)

    agent.train(total_steps=args.steps, seconds=None if args.steps else args.minutes * 60, log=log,
                csv_path=out / "curve.csv")
    env.close()
    plot_curve(agent.curve, out / "curve.png", f"ssx.learn {args.task}: PPO")
    options = {k: v for k, v in setup["env"].items() if k not in ("task", "num_envs")}
    result = evaluate(agent, args.task, setup["held_out"], **options)
    if args.task == "goto":
        print(f"held-out goals: {result['success'].mean() * 100:.0f} % reached within 10 cm "
              f"(median final distance {np.nanmedian(result['distance']) * 100:.1f} cm, {result['crashed'].sum()} crashed)")
    else:
        print(f"held-out formations: mean distance to the slots {np.nanmean(result['distance']) * 100:.1f} cm at the end, "
              f"a pair of robots closer than 15 cm at {int(result['collisions'].sum())} (pair, step)s over "
              f"{setup['held_out']} episodes, {result['crashed'].sum()} episodes ended by a crash")
    print(f"curve: {out / 'curve.csv'}, {out / 'curve.png'}")


if __name__ == "__main__":
    main()

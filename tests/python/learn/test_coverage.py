"""The ground-robot task `coverage`: e-pucks in a walled arena commanded at the wheels level,
observing their own proximity sensors (batched reads) and the cells around them. A hand-written
wanderer (turn on the spot while something is ahead) covers most of the arena and earns more than
robots standing still; the reward counts each cell once; the episode ends only at the horizon;
ParallelEnv keeps every agent; the same seed gives the same bits."""
import numpy as np

import ssx.learn as learn


def wander(obs):
    ahead = obs[..., 4:12][..., [0, 1, 6, 7]].max(axis=-1) > 0.05  # the four forward rays
    return np.where(ahead[..., None], np.array([-1.0, 1.0]), np.array([1.0, 0.9])).astype(np.float32)


def run(env, policy, steps, seed):
    obs, _ = env.reset(seed=seed)
    total = np.zeros(env.num_envs)
    for _ in range(steps):
        obs, rewards, terminations, truncations, infos = env.step(policy(obs))
        total += rewards
        assert not terminations.any()
    return total, infos, truncations


def test_a_wanderer_covers_the_arena_and_standing_still_does_not():
    env = learn.VectorEnv("coverage", num_envs=4, robots=4, action_period=0.1, threads=2)
    assert env.single_observation_space.shape == (4, 21) and env.single_action_space.shape == (4, 2)
    assert env.task.level == "wheels"
    wandered, infos, truncations = run(env, wander, 300, seed=1)
    assert truncations.all()  # 30 s at 10 actions a second: the horizon
    assert np.all(infos["coverage"] > 0.4)
    assert infos["agent_rewards"].shape == (4, 4)
    stood, still, _ = run(env, lambda obs: np.zeros(env.action_space.shape, np.float32), 300, seed=1)
    assert np.all(still["coverage"] < 0.1)
    assert np.all(wandered > stood)
    # every cell counts once: the rewards for cells add up to the cells covered
    cells = env.task.cells ** 2
    assert np.allclose(stood, np.round(still["coverage"] * cells))
    env.close()


def test_coverage_is_repeatable_and_a_parallel_env_keeps_its_agents():
    a = learn.VectorEnv("coverage", num_envs=2, robots=4, action_period=0.1, threads=1)
    b = learn.VectorEnv("coverage", num_envs=2, robots=4, action_period=0.1, threads=2)
    for env in (a, b):
        run(env, wander, 50, seed=9)
    assert np.array_equal(a.state_hashes(), b.state_hashes())
    swarm = learn.ParallelEnv("coverage", robots=4, action_period=0.1)
    observations, _ = swarm.reset(seed=2)
    for _ in range(20):
        actions = {agent: swarm.action_space(agent).sample() for agent in swarm.agents}
        observations, rewards, terminations, truncations, infos = swarm.step(actions)
    assert swarm.agents == swarm.possible_agents and not any(terminations.values())
    for env in (a, b, swarm):
        env.close()


def test_velocity_actions_drive_along_each_robots_heading():
    env = learn.VectorEnv("coverage", num_envs=2, robots=4, action_period=0.1, level="velocity", threads=1)
    assert env.single_action_space.shape == (4, 2)
    env.reset(seed=1)
    start = env.sim.robot_states()[:, :, :2].copy()
    forward = np.zeros(env.action_space.shape, np.float32)
    forward[..., 0] = 1.0  # full speed ahead, no turn: 1 s at 0.128 m/s
    for _ in range(10):
        env.step(forward)
    moved = np.linalg.norm(env.sim.robot_states()[:, :, :2] - start, axis=-1)
    assert np.allclose(moved, 0.128, atol=0.01)
    env.close()

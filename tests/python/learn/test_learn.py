"""ssx.learn: the Gymnasium vector API and PettingZoo's parallel API as their documentation states
them (spaces, dtypes, reset and step's returns, seeding, both autoreset modes), determinism that
does not depend on threads, on an environment's index or on the others' resets, tasks that mean
what they say (a hand-written controller at the attitude level reaches the goals), and errors."""
import numpy as np
import pytest

import ssx
import ssx.learn as learn


def proportional_attitude(obs, task):
    """Flies at the goal: acceleration = 4 (goal - position) - 3 velocity, as roll, pitch, thrust."""
    rel, vel = obs[:, 0:3], obs[:, 3:6] * 2.0
    acc = 4.0 * rel - 3.0 * vel
    a = np.zeros((len(obs), 4), dtype=np.float32)
    a[:, 0] = -acc[:, 1] / 9.81 / task.max_tilt  # roll right (positive) accelerates towards -y
    a[:, 1] = acc[:, 0] / 9.81 / task.max_tilt   # pitch (positive) towards +x
    a[:, 3] = acc[:, 2] / 9.81 / task.thrust_range
    return np.clip(a, -1, 1)


@pytest.fixture(scope="module")
def goto8():
    env = learn.VectorEnv("goto", num_envs=8, threads=2)
    yield env
    env.close()


def test_spaces_and_returns_follow_gymnasium(goto8):
    env = goto8
    assert env.num_envs == 8
    assert env.single_observation_space.shape == (16,) and env.single_observation_space.dtype == np.float32
    assert env.single_action_space.shape == (4,)
    assert env.observation_space.shape == (8, 16) and env.action_space.shape == (8, 4)
    assert env.metadata["autoreset_mode"] in ("next_step", getattr(learn, "_MODES")["next_step"])
    obs, infos = env.reset(seed=3)
    assert isinstance(infos, dict)
    assert obs.shape == (8, 16) and obs.dtype == np.float32
    assert env.observation_space.contains(obs)
    actions = env.action_space.sample()
    assert env.action_space.contains(actions)
    obs, rewards, terminations, truncations, infos = env.step(actions)
    assert env.observation_space.contains(obs)
    assert rewards.shape == (8,) and rewards.dtype == np.float64
    assert terminations.shape == (8,) and terminations.dtype == bool
    assert truncations.shape == (8,) and truncations.dtype == bool
    assert infos["distance"].shape == (8,)


def test_seeding_repeats_and_differs(goto8):
    env = goto8
    rng = np.random.default_rng(0)
    actions = [rng.uniform(-0.3, 0.3, size=(8, 4)).astype(np.float32) for _ in range(20)]

    def rollout(seed):
        obs, _ = env.reset(seed=seed)
        out = [obs]
        for a in actions:
            out.append(env.step(a)[0])
        return np.array(out), env.state_hashes().copy()

    a, ha = rollout(5)
    b, hb = rollout(5)
    c, hc = rollout(6)
    assert np.array_equal(a, b) and np.array_equal(ha, hb)
    assert not np.array_equal(a[0], c[0])
    # seed=int gives environment i the seed seed + i: seed 6's environment 0 starts as seed 5's environment 1
    assert np.array_equal(a[0, 1], c[0, 0])
    # one seed per environment, as a list
    obs, _ = env.reset(seed=[5 + i for i in range(8)])
    assert np.array_equal(obs, a[0])
    with pytest.raises(ValueError, match="8 environments"):
        env.reset(seed=[1, 2])


def test_same_bits_on_one_and_two_threads_and_whatever_the_index():
    seeds = [11, 12, 13, 14]
    actions = np.random.default_rng(1).uniform(-0.5, 0.5, size=(30, 4, 4)).astype(np.float32)

    def run(threads, order):
        env = learn.VectorEnv("goto", num_envs=4, threads=threads)
        obs, _ = env.reset(seed=[seeds[i] for i in order])
        trace = [obs]
        for a in actions:
            trace.append(env.step(a[order])[0])
        hashes = env.state_hashes().copy()
        env.close()
        return np.array(trace), hashes

    one, h1 = run(1, [0, 1, 2, 3])
    two, h2 = run(2, [0, 1, 2, 3])
    assert np.array_equal(one, two) and np.array_equal(h1, h2)
    # the environments in another order: their trajectories permuted, not a bit changed (Isaac Lab #3824)
    order = [2, 0, 3, 1]
    permuted, hp = run(2, order)
    assert np.array_equal(permuted, one[:, order]) and np.array_equal(hp, h1[order])


def test_a_reset_in_the_middle_of_a_batch_changes_nothing_else():
    actions = np.random.default_rng(2).uniform(-0.4, 0.4, size=(20, 4, 4)).astype(np.float32)

    def run(reset_at):
        env = learn.VectorEnv("goto", num_envs=4, threads=2)
        env.reset(seed=7)
        trace = []
        for k, a in enumerate(actions):
            if k == reset_at:
                env.reset(options={"reset_mask": np.array([False, True, False, False])})
            trace.append(env.step(a)[0])
        env.close()
        return np.array(trace)

    plain, reset = run(None), run(10)
    others = [0, 2, 3]
    assert np.array_equal(plain[:, others], reset[:, others])
    assert not np.array_equal(plain[10:, 1], reset[10:, 1])


def test_next_step_autoreset():
    env = learn.VectorEnv("hover", num_envs=3, horizon_seconds=0.1, threads=1)  # 5 actions an episode
    obs, _ = env.reset(seed=1)
    zero = np.zeros((3, 4), dtype=np.float32)
    for _ in range(4):
        obs, r, term, trunc, _ = env.step(zero)
        assert not trunc.any()
    obs, r, term, trunc, _ = env.step(zero)
    assert trunc.all() and not term.any()
    last = obs
    # the next step starts the new episode: its first observation, reward 0, neither flag
    obs, r, term, trunc, _ = env.step(zero)
    assert not np.array_equal(obs, last)
    assert np.all(r == 0) and not term.any() and not trunc.any()
    # and it is the episode the environments' generators drew next: the same again from the same seed
    again = learn.VectorEnv("hover", num_envs=3, horizon_seconds=0.1, threads=2)
    again.reset(seed=1)
    for _ in range(6):
        o2 = again.step(zero)[0]
    assert np.array_equal(o2, obs)
    env.close()
    again.close()


def test_same_step_autoreset():
    env = learn.VectorEnv("hover", num_envs=2, horizon_seconds=0.06, autoreset_mode="same_step", threads=1)
    env.reset(seed=4)
    zero = np.zeros((2, 4), dtype=np.float32)
    for _ in range(2):
        env.step(zero)
    obs, r, term, trunc, infos = env.step(zero)
    assert trunc.all()
    assert infos["_final_obs"].all()
    assert infos["final_obs"][0].shape == (16,)
    assert not np.array_equal(infos["final_obs"][0], obs[0])  # obs is already the next episode's first
    env.close()


def test_goto_means_what_it_says_a_proportional_controller_reaches_the_goals():
    env = learn.VectorEnv("goto", num_envs=16, threads=2, horizon_seconds=6.0)
    obs, _ = env.reset(seed=21)
    start = np.linalg.norm(obs[:, 0:3], axis=1)
    for _ in range(200):  # 4 s
        obs, r, term, trunc, infos = env.step(proportional_attitude(obs, env.task))
        assert not term.any()
    end = np.linalg.norm(obs[:, 0:3], axis=1)
    assert start.mean() > 0.5
    assert np.median(end) < 0.1, end
    assert r.mean() > 0.7


def test_a_crash_terminates():
    env = learn.VectorEnv("goto", num_envs=2, threads=1)
    env.reset(seed=1)
    down = np.tile(np.array([0, 0, 0, -1], dtype=np.float32), (2, 1))  # 40 % of the weight: it falls
    ended = np.zeros(2, dtype=bool)
    for _ in range(100):
        obs, r, term, trunc, _ = env.step(down)
        assert np.all(r[term] < 0)  # the step that crashed is punished
        ended |= term
    assert ended.all()
    env.close()


def test_parallel_env_follows_pettingzoo():
    env = learn.ParallelEnv("formation", robots=4, horizon_seconds=2.0)
    assert env.possible_agents == ["r0", "r1", "r2", "r3"]
    obs, infos = env.reset(seed=2)
    assert set(obs) == set(env.agents) == set(env.possible_agents) and set(infos) == set(env.agents)
    for agent in env.agents:
        assert env.observation_space(agent).contains(obs[agent])
        assert env.action_space(agent).shape == (4,)
    again, _ = env.reset(seed=2)
    assert all(np.array_equal(obs[a], again[a]) for a in obs)
    # robot r0 dives into the ground: it leaves `agents`; the others fly on
    for _ in range(100):
        actions = {a: np.zeros(4, dtype=np.float32) for a in env.agents}
        if "r0" in actions:
            actions["r0"] = np.array([0, 0, -1, 0], dtype=np.float32)
        obs, rewards, terms, truncs, infos = env.step(actions)
        assert set(obs) == set(rewards) == set(terms) == set(truncs) == set(infos)
        if "r0" not in env.agents:
            break
    assert "r0" not in env.agents and terms["r0"]
    assert env.agents == ["r1", "r2", "r3"]
    for _ in range(100):
        if not env.agents:
            break
        obs, rewards, terms, truncs, infos = env.step({a: np.zeros(4) for a in env.agents})
    assert env.agents == [] and all(truncs.values())
    env.close()


def test_formation_vector_env_counts_collisions():
    env = learn.VectorEnv("formation", num_envs=2, robots=4, threads=2)
    assert env.single_observation_space.shape == (4, 15) and env.single_action_space.shape == (4, 4)
    env.reset(seed=3)
    obs, r, term, trunc, infos = env.step(np.zeros((2, 4, 4), dtype=np.float32))
    assert infos["collisions"].shape == (2,) and (infos["collisions"] == 0).all()
    env.close()


def test_formation_observes_each_robots_slot_velocity_and_nearest_neighbours():
    # checked robot by robot against the positions read afterwards, the robots flying random
    # velocity actions (neighbours change order; with a collision distance of 0.5 m some pairs
    # come closer than it: asserted below)
    env = learn.VectorEnv("formation", num_envs=3, robots=6, threads=2, collision_distance=0.5)
    env.reset(seed=8)
    rng = np.random.default_rng(1)
    collisions = 0
    for step in range(40):
        actions = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, r, term, trunc, infos = env.step(actions)
        states = env.sim.robot_states()
        for e in range(3):
            p = states[e, :, 0:3]
            apart = np.linalg.norm(p[None, :, :] - p[:, None, :], axis=-1)
            assert infos["collisions"][e] == (np.count_nonzero(apart < 0.5) - 6) // 2
            collisions += infos["collisions"][e]
            for i in range(6):
                others = [j for j in sorted(range(6), key=lambda j: apart[i, j]) if j != i][:3]
                expected = np.concatenate([env.task.slots[e, i] - p[i], states[e, i, 7:10] * 0.5] +
                                          [p[j] - p[i] for j in others])
                assert np.array_equal(obs[e, i], np.clip(expected, -10, 10).astype(np.float32))
    assert collisions > 0
    env.close()


def test_a_task_of_ones_own():
    class StayLow(learn.GoTo):
        name = "stay_low"

        def evaluate(self, states, imu, actions):
            rewards, terminated, infos = super().evaluate(states, imu, actions)
            return -states[:, 0, 2], terminated, infos

    env = learn.VectorEnv(StayLow(), num_envs=2, threads=1)
    env.reset(seed=0)
    _, r, _, _, _ = env.step(np.zeros((2, 4), dtype=np.float32))
    assert np.all(r < -0.5)  # about 1 m up
    env.close()
    with pytest.raises(TypeError, match="made already"):
        learn.VectorEnv(StayLow(), num_envs=1, goal_range=2)


def test_nonsense_is_refused():
    with pytest.raises(ValueError, match="unknown task"):
        learn.VectorEnv("fly_to_the_moon", num_envs=1)
    with pytest.raises(ValueError, match="level must be one of"):
        learn.VectorEnv("goto", num_envs=1, level="thoughts")
    with pytest.raises(ValueError, match="whole number of physics"):
        learn.VectorEnv("goto", num_envs=1, action_period=0.003)
    env = learn.VectorEnv("goto", num_envs=2, threads=1)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros((2, 4)))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.full((2, 4), np.nan))
    env.close()


def test_vector_environment_core_reads_into_given_arrays():
    sim = learn._ssx.VectorEnvironment(learn.GoTo().scene(), 3, base_dir=ssx.data_directory(), threads=2)
    states = np.empty((3, 1, 13))
    assert sim.robot_states(out=states) is not None
    with pytest.raises(ValueError, match=r"\(3, 1, 13\)"):
        sim.robot_states(out=np.empty((3, 13)))
    with pytest.raises(ValueError, match="copy 0, robot 'r0'"):
        sim.set_commands("wheels", np.zeros((3, 1, 2)))  # a quadrotor has no wheels
    sim.close()
    with pytest.raises(RuntimeError, match="closed"):
        sim.step()


def test_environment_reseed_after_restore_draws_the_seeds_noise():
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml", seed=3, threads=1)
    env.step(100)
    saved = env.save_state()

    def episode(seed):
        env.restore_state(saved)
        if seed is not None:
            env.reseed(seed)
        env.step(50)
        return env.imu("cf")["accelerometer"].copy(), env.state_hash()

    plain_a, plain_b = episode(None), episode(None)
    assert np.array_equal(plain_a[0], plain_b[0])  # restoring restores the noise streams too
    one, one_again, two = episode(1), episode(1), episode(2)
    assert np.array_equal(one[0], one_again[0]) and one[1] == one_again[1]
    assert not np.array_equal(one[0], two[0])
    env.close()


def test_spaces_without_gymnasium_sample_contain_and_seed():
    from ssx.spaces import Box, Dict

    box = Box(-1.0, 1.0, (3, 2), np.float32, seed=4)
    a = box.sample()
    assert a.shape == (3, 2) and a.dtype == np.float32 and box.contains(a) and a in box
    assert not box.contains(np.full((3, 2), 2.0, dtype=np.float32))
    assert not box.contains(np.zeros((2, 3), dtype=np.float32))
    box.seed(9)
    first = box.sample()
    box.seed(9)
    assert np.array_equal(first, box.sample())
    half = Box([0.0, -np.inf], [1.0, 0.0], dtype=np.float64, seed=1)  # one bound infinite
    assert all(half.contains(half.sample()) for _ in range(20))
    with pytest.raises(ValueError, match="low above high"):
        Box(1.0, 0.0, (2,))
    both = Dict({"pose": Box(-1, 1, (3,)), "speed": Box(0, 2, (1,))}, seed=3)
    sample = both.sample()
    assert set(sample) == {"pose", "speed"} and both.contains(sample)
    assert not both.contains({"pose": sample["pose"]})
    both.seed(5)
    again = both.sample()
    both.seed(5)
    assert all(np.array_equal(again[k], v) for k, v in both.sample().items())


def test_position_actions_fly_to_set_points_near_the_robot():
    env = learn.VectorEnv("goto", num_envs=4, level="position", threads=2)
    obs, _ = env.reset(seed=3)
    for _ in range(150):  # 3 s, each action a set-point towards the goal (at most 0.5 m away)
        a = np.zeros((4, 4), dtype=np.float32)
        a[:, :3] = np.clip(obs[:, 0:3] / env.task.max_offset, -1, 1)
        obs, rewards, terminations, truncations, infos = env.step(a)
        assert not terminations.any()
    assert np.all(infos["distance"] < 0.2)
    env.close()


@pytest.mark.parametrize("vehicle", ["crazyflie", "mk_quad"])
def test_rotor_speed_actions_hold_the_weight_climb_and_turn(vehicle):
    env = learn.VectorEnv("goto", num_envs=3, level="rotors", vehicle=vehicle, start_speed=0.0, threads=1)
    assert env.single_action_space.shape == (4,)
    env.reset(seed=2)
    states = env._b.states
    z0 = states[:, 0, 2].copy()
    a = np.zeros((3, 4), dtype=np.float32)
    a[1] = 0.5  # every rotor's thrust x 1.5: climbs
    a[2] = [0.3, -0.3, 0.3, -0.3]  # one diagonal faster, the other slower: turns about z, the same thrust
    for _ in range(25):  # 0.5 s
        env.step(a)
    dz = states[:, 0, 2] - z0
    yaw_rate = np.abs(states[:, 0, 12])
    assert abs(dz[0]) < 0.02  # a = 0: each rotor at the speed that holds its share of the weight
    assert dz[1] > dz[0] + 0.2
    assert yaw_rate[2] > 0.3 and yaw_rate[2] > 50 * yaw_rate[0]
    env.close()

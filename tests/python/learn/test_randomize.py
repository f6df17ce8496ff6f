"""ssx.learn's domain randomisation and the Stable-Baselines3 adapter: each robot's constants are
drawn per episode from its environment's own stream (the same seed, the same draws and bits; other
environments other draws), reach the simulation (a heavier robot sinks), come back in infos, are
part of a saved state, and bad ranges are refused before anything runs; SB3VecEnv follows SB3's
VecEnv rules (same-step reset, terminal_observation, TimeLimit.truncated)."""
import numpy as np
import pytest

import ssx
import ssx.learn as learn

RANGES = {"mass": (0.8, 1.25), "thrust_coefficient": (0.9, 1.1), "time_constant_up": (0.8, 1.2),
          "wind_x": (-1.0, 1.0), "gyro_noise": (0.5, 2.0)}


def test_draws_per_environment_and_robot_repeat_with_the_seed_and_reach_infos():
    env = learn.VectorEnv("formation", num_envs=3, robots=4, threads=2, randomize=RANGES)
    obs, infos = env.reset(seed=11)
    drawn = infos["variations"]
    assert set(drawn) == set(RANGES)
    for name, (low, high) in RANGES.items():
        assert drawn[name].shape == (3, 4)
        assert np.all((drawn[name] >= low) & (drawn[name] <= high))
        assert len(np.unique(drawn[name])) == 12  # every robot of every environment its own draw
    zero = np.zeros(env.action_space.shape, dtype=np.float32)
    for _ in range(5):
        env.step(zero)
    first = env.state_hashes()
    obs2, infos2 = env.reset(seed=11)
    for name in RANGES:
        assert np.array_equal(infos2["variations"][name], drawn[name])
    for _ in range(5):
        env.step(zero)
    assert np.array_equal(env.state_hashes(), first)
    _, infos3 = env.reset(seed=12)
    assert not np.array_equal(infos3["variations"]["mass"], drawn["mass"])
    env.close()


def test_a_heavier_robot_sinks_and_neutral_draws_are_the_scene():
    heavy = learn.VectorEnv("hover", num_envs=2, threads=1, randomize={"mass": (1.5, 1.5)})
    plain = learn.VectorEnv("hover", num_envs=2, threads=1)
    neutral = learn.VectorEnv("hover", num_envs=2, threads=1, randomize={"mass": (1.0, 1.0), "wind_y": (0.0, 0.0)})
    for env in (heavy, plain, neutral):
        env.reset(seed=5)
    hold = np.zeros((2, 4), dtype=np.float32)  # attitude level: level, thrust of the nominal hover
    for _ in range(10):
        for env in (heavy, plain, neutral):
            env.step(hold)
    z = {name: env.sim.robot_states()[:, 0, 2] for name, env in (("heavy", heavy), ("plain", plain))}
    assert np.all(z["heavy"] < z["plain"] - 0.05)  # 0.2 s at 2/3 g less: tens of centimetres
    assert np.array_equal(neutral.state_hashes(), plain.state_hashes())
    for env in (heavy, plain, neutral):
        env.close()


def test_draws_are_part_of_a_saved_state_and_redrawn_at_autoreset():
    env = learn.VectorEnv("hover", num_envs=2, threads=1, horizon_seconds=0.06, randomize={"mass": (0.8, 1.2)})
    _, infos = env.reset(seed=2)
    core = ssx.load_scene_string(env.task.scene(), base_dir=ssx.data_directory())
    core.restore_state(env.sim.save_state(1))
    assert core.variation("r0", "mass") == pytest.approx(infos["variations"]["mass"][1, 0], abs=0)
    first = infos["variations"]["mass"]
    zero = np.zeros((2, 4), dtype=np.float32)
    for _ in range(3):
        _, _, _, trunc, infos = env.step(zero)
        assert "variations" not in infos
    assert trunc.all()
    _, _, _, _, infos = env.step(zero)  # next-step autoreset: both copies start again, new draws
    assert infos["_variations"].all()
    assert np.all(infos["variations"]["mass"] != first)
    env.close()


def test_latency_and_battery_are_drawn_like_the_other_constants():
    # latency: the action reaches the motors that many whole physics steps later (the one before held);
    # a tilt commanded 10 ms late has moved the robot less by the end of the action
    late = learn.VectorEnv("hover", num_envs=2, threads=1, randomize={"latency": (0.0095, 0.0105)})
    prompt = learn.VectorEnv("hover", num_envs=2, threads=1)
    _, infos = late.reset(seed=3)
    prompt.reset(seed=3)
    assert np.allclose(infos["variations"]["latency"], 0.01)  # rounded to whole steps of 2 ms
    tilt = np.tile(np.array([0.5, 0.0, 0.0, 0.0], dtype=np.float32), (2, 1))  # attitude: roll
    late.step(tilt)
    prompt.step(tilt)
    roll = {name: abs(env.sim.robot_states()[:, 0, 4]) for name, env in (("late", late), ("prompt", prompt))}  # qx
    assert np.all(roll["late"] < 0.9 * roll["prompt"])  # (0.54 and 0.80 of it: the motors lag either way)
    # no latency drawn is the scene's run, bit for bit
    none = learn.VectorEnv("hover", num_envs=2, threads=1, randomize={"latency": (0.0, 0.0009)})
    again = learn.VectorEnv("hover", num_envs=2, threads=1)
    for env in (none, again):
        env.reset(seed=3)
        env.step(tilt)
    assert np.array_equal(none.state_hashes(), again.state_hashes())
    with pytest.raises(ValueError, match=r"latency.*within \[0, 0.02\]"):
        learn.VectorEnv("hover", num_envs=1, randomize={"latency": (0.0, 0.05)})
    # the battery: the Crazyflie's firmware sees the voltage drawn; a drained one cannot lift as much
    weak = learn.VectorEnv("hover", num_envs=2, threads=1, randomize={"battery_volts": (-1.8, -1.8)})
    _, infos = weak.reset(seed=3)
    assert np.all(infos["variations"]["battery_volts"] == -1.8)
    full = np.tile(np.array([0.0, 0.0, 0.0, 1.0], dtype=np.float32), (2, 1))  # the most thrust
    prompt.reset(seed=3)
    start = prompt.sim.robot_states()[:, 0, 2]  # (the same start: the task draws it before the constants)
    for _ in range(8):
        weak.step(full)
        prompt.step(full)
    climbed = {name: env.sim.robot_states()[:, 0, 2] - start for name, env in (("weak", weak), ("full", prompt))}
    assert np.all(climbed["weak"] < climbed["full"] - 0.02)
    for env in (late, prompt, none, again, weak):
        env.close()


def test_bad_ranges_are_refused_before_anything_runs():
    with pytest.raises(ValueError, match="has no such constant"):
        learn.VectorEnv("hover", num_envs=1, randomize={"weight": (0.9, 1.1)})
    with pytest.raises(ValueError, match=r"within \[0.05, 20\]"):
        learn.VectorEnv("hover", num_envs=1, randomize={"mass": (0.0, 1.1)})
    with pytest.raises(ValueError, match="low <= high"):
        learn.VectorEnv("hover", num_envs=1, randomize={"mass": (1.2, 1.1)})
    with pytest.raises(ValueError, match="pair"):
        learn.VectorEnv("hover", num_envs=1, randomize={"mass": 1.1})


def test_environment_vary_from_python():
    env = ssx.load_scene_string(learn.Hover().scene(), base_dir=ssx.data_directory())
    names = [v["name"] for v in env.variables("r0")]
    assert names[:3] == ["mass", "inertia", "thrust_coefficient"] and "accel_noise" in names
    env.vary("r0", "thrust_coefficient", 1.1)
    assert env.variation("r0", "thrust_coefficient") == 1.1
    with pytest.raises(ssx.ConfigError, match="within"):
        env.vary("r0", "thrust_coefficient", 9.0)
    with pytest.raises(KeyError):
        env.vary("nobody", "mass", 1.0)


def test_sb3_adapter_follows_stable_baselines3s_vecenv_rules():
    with pytest.raises(ValueError, match="same_step"):
        learn.SB3VecEnv(learn.VectorEnv("hover", num_envs=2, threads=1))
    venv = learn.SB3VecEnv(learn.VectorEnv("hover", num_envs=2, threads=1, horizon_seconds=0.06,
                                           autoreset_mode="same_step", randomize={"mass": (0.9, 1.1)}))
    assert venv.num_envs == 2 and venv.observation_space.shape == (16,) and venv.action_space.shape == (4,)
    assert venv.seed(7) == [7, 8]
    obs = venv.reset()
    assert obs.shape == (2, 16) and "mass" in venv.reset_infos[0]["variations"]
    again = learn.SB3VecEnv(learn.VectorEnv("hover", num_envs=2, threads=1, horizon_seconds=0.06,
                                            autoreset_mode="same_step", randomize={"mass": (0.9, 1.1)}))
    again.seed(7)
    assert np.array_equal(again.reset(), obs)
    zero = np.zeros((2, 4), dtype=np.float32)
    for step in range(3):
        obs, rewards, dones, infos = venv.step(zero)
        assert rewards.dtype == np.float32 and dones.dtype == bool and len(infos) == 2
    assert dones.all()  # the horizon: three actions of 0.02 s
    for info in infos:
        assert info["terminal_observation"].shape == (16,)
        assert info["TimeLimit.truncated"] is True
    assert not np.array_equal(infos[0]["terminal_observation"], obs[0])  # obs is the next episode's first
    assert venv.get_attr("num_envs") == [2, 2] and venv.env_is_wrapped(object) == [False, False]
    venv.close()
    again.close()

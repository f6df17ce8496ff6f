"""The Python examples do what their docstrings say."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples" / "python"))

import learning_env  # noqa: E402
import swarm_controller  # noqa: E402


def test_swarm_controller_tracks_the_turning_ring(tmp_path):
    times, flown, wanted = swarm_controller.fly(n=9, seconds=12.0, threads=2)
    assert flown.shape == (600, 9, 3) and times[-1] == pytest.approx(12.0)
    error = np.linalg.norm(flown - wanted, axis=2)
    assert error[times >= 8.0].max() < 0.05  # turning on the ring, after the climb
    # on the ring: 3 m from its centre, 1.5 m up
    np.testing.assert_allclose(np.linalg.norm(flown[-1, :, :2], axis=1), 3.0, atol=0.05)
    np.testing.assert_allclose(flown[-1, :, 2], 1.5, atol=0.05)
    pytest.importorskip("matplotlib")
    out = tmp_path / "ring.png"
    swarm_controller.plot(times, flown, wanted, out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_learning_env_resets_to_the_same_bits_and_rewards_reaching():
    env = learning_env.SwarmReachEnv(n=3, horizon=40, threads=1)
    first = env.reset(seed=5)
    actions = [np.full((3, 3), 0.1 * k) for k in range(5)]
    run1 = [env.step(a)[:2] for a in actions]
    again = env.reset(seed=5)
    assert np.array_equal(first, again)
    run2 = [env.step(a)[:2] for a in actions]
    for (o1, r1), (o2, r2) in zip(run1, run2):
        assert np.array_equal(o1, o2) and r1 == r2
    # another seed, other goals, same start
    other = env.reset(seed=6)
    assert np.array_equal(first[:, 3:], other[:, 3:]) and not np.array_equal(first[:, :3], other[:, :3])
    idle, _ = learning_env.episode(env, lambda o: np.zeros((3, 3)), seed=5)
    reached, obs = learning_env.episode(env, learning_env.proportional_policy, seed=5)
    assert reached > idle
    assert np.linalg.norm(obs[:, :3], axis=1).max() < 0.05

"""examples/learn: the PPO of ppo.py learns on ssx.learn, here a tiny version for about a minute
(goto with 16 environments): the mean return of the last updates is well above the first's. And
the torch adapter hands out tensors that share memory with the numpy arrays."""
import pathlib
import sys

import numpy as np
import pytest

torch = pytest.importorskip("torch")  # Debian's python3-torch (./dev.sh installs it)

import ssx.learn as learn  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "examples" / "learn"))
from ppo import PPO  # noqa: E402


def test_ppo_return_rises_within_a_minute(tmp_path):
    torch.set_num_threads(1)
    env = learn.VectorEnv("goto", num_envs=16, threads=2)
    agent = PPO(env, horizon=64, epochs=5, minibatches=4, seed=1)
    curve = agent.train(total_steps=16 * 64 * 200, seconds=60, csv_path=tmp_path / "curve.csv")
    env.close()
    returns = [row[2] for row in curve if not np.isnan(row[2])]
    assert len(returns) >= 40, f"only {len(returns)} updates with ended episodes in a minute"
    first, last = np.mean(returns[:10]), np.mean(returns[-10:])
    assert last > first + 20, f"mean return {first:.1f} in the first updates, {last:.1f} in the last"
    assert (tmp_path / "curve.csv").read_text().count("\n") == len(curve) + 1


def test_torch_adapter_shares_memory():
    env = learn.TorchVectorEnv(learn.VectorEnv("hover", num_envs=2, threads=1))
    obs, _ = env.reset(seed=0)
    assert isinstance(obs, torch.Tensor) and obs.shape == (2, 16)
    obs, rewards, term, trunc, _ = env.step(torch.zeros((2, 4)))
    assert rewards.dtype == torch.float64 and term.dtype == torch.bool
    assert env.num_envs == 2
    env.close()

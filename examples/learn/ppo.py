"""A small PPO (clipped surrogate, GAE, one Gaussian policy and a value network) for ssx.learn's
vector environments, written for this repository with Debian's python3-torch; no RL library.

Works with next-step autoreset (Gymnasium 1.x's default): the step after an episode ended only
starts the next one, so that transition is left out of the loss; a truncated episode is
bootstrapped from the value of its last observation, a terminated one is not.

Multi-robot tasks (observations (E, R, n)) train one policy shared by every robot: each robot is
a sample, rewarded with infos["agent_rewards"] when the task gives it (else its environment's).
"""
import csv
import time

import numpy as np
import torch
from torch import nn


class ActorCritic(nn.Module):
    def __init__(self, obs_size, act_size, hidden=64):
        super().__init__()

        def mlp(out, scale):
            layers = [nn.Linear(obs_size, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(), nn.Linear(hidden, out)]
            for layer in layers:
                if isinstance(layer, nn.Linear):
                    nn.init.orthogonal_(layer.weight, np.sqrt(2))
                    nn.init.zeros_(layer.bias)
            nn.init.orthogonal_(layers[-1].weight, scale)
            return nn.Sequential(*layers)

        self.actor = mlp(act_size, 0.01)
        self.critic = mlp(1, 1.0)
        self.log_std = nn.Parameter(torch.full((act_size,), -0.5))

    def value(self, obs):
        return self.critic(obs).squeeze(-1)

    def distribution(self, obs):
        return torch.distributions.Normal(self.actor(obs), self.log_std.exp())

    def act(self, obs, deterministic=False):
        with torch.no_grad():
            dist = self.distribution(obs)
            action = dist.mean if deterministic else dist.sample()
            return action, dist.log_prob(action).sum(-1), self.value(obs)


class PPO:
    """PPO over a VectorEnv: `train(total_steps)` collects `horizon` steps of every environment per
    update and writes one CSV row per update (steps, seconds, mean return of the episodes ended)."""

    def __init__(self, env, horizon=128, epochs=4, minibatches=4, lr=3e-4, gamma=0.99, lam=0.95, clip=0.2,
                 entropy=0.0, value_coef=0.5, max_grad=0.5, seed=0, hidden=64):
        torch.manual_seed(seed)
        self.env, self.horizon, self.epochs, self.minibatches = env, horizon, epochs, minibatches
        self.gamma, self.lam, self.clip, self.entropy, self.value_coef, self.max_grad = gamma, lam, clip, entropy, value_coef, max_grad
        shape = env.single_observation_space.shape
        self.agents = shape[0] if len(shape) == 2 else 1
        self.obs_size, self.act_size = shape[-1], env.single_action_space.shape[-1]
        self.model = ActorCritic(self.obs_size, self.act_size, hidden)
        self.optimizer = torch.optim.Adam(self.model.parameters(), lr=lr, eps=1e-5)
        self.seed = seed
        self.curve = []  # (agent steps, seconds, mean return, episodes)

    def _flat(self, obs):
        return torch.from_numpy(np.ascontiguousarray(obs, dtype=np.float32)).reshape(-1, self.obs_size)

    def train(self, total_steps=None, seconds=None, log=None, csv_path=None):
        """Trains until `total_steps` agent steps or `seconds` of wall time, whichever comes first;
        the curve goes to `log(row)` and the CSV `csv_path` as it grows."""
        env, T, A = self.env, self.horizon, self.agents
        N = env.num_envs * A  # samples per step
        obs_b = torch.zeros((T, N, self.obs_size))
        act_b = torch.zeros((T, N, self.act_size))
        logp_b, val_b, rew_b, term_b, done_b, valid_b, next_val_b = (torch.zeros((T, N)) for _ in range(7))
        obs, _ = env.reset(seed=self.seed)
        obs = self._flat(obs)
        prev_done = np.zeros(env.num_envs, dtype=bool)
        episode_return = np.zeros(env.num_envs)
        finished = []
        steps, start = 0, time.perf_counter()
        handle = open(csv_path, "w", newline="") if csv_path else None
        writer = csv.writer(handle) if handle else None
        if writer:
            writer.writerow(["agent_steps", "seconds", "mean_return", "episodes"])
        while (total_steps is None or steps < total_steps) and (seconds is None or time.perf_counter() - start < seconds):
            for t in range(T):
                action, logp, value = self.model.act(obs)
                env_action = action.clamp(-1, 1).reshape((env.num_envs,) + env.single_action_space.shape).numpy()
                next_obs, reward, term, trunc, infos = env.step(env_action)
                agent_reward = infos.get("agent_rewards", np.repeat(reward[:, None], A, axis=1)).reshape(-1)
                done = term | trunc
                obs_b[t], act_b[t], logp_b[t], val_b[t] = obs, action, logp, value
                rew_b[t] = torch.from_numpy(np.asarray(agent_reward, dtype=np.float32))
                term_b[t] = torch.from_numpy(np.repeat(term, A).astype(np.float32))
                done_b[t] = torch.from_numpy(np.repeat(done, A).astype(np.float32))
                valid_b[t] = torch.from_numpy(np.repeat(~prev_done, A).astype(np.float32))
                obs = self._flat(next_obs)
                # the value of what follows: the observation returned (with next-step autoreset it
                # is the episode's last when it ended)
                with torch.no_grad():
                    next_val_b[t] = self.model.value(obs)
                episode_return += np.where(prev_done, 0.0, reward)
                for i in np.flatnonzero(done & ~prev_done):
                    finished.append(episode_return[i])
                episode_return[prev_done] = 0.0
                prev_done = done
            steps += T * env.num_envs * A
            self._update(obs_b, act_b, logp_b, val_b, rew_b, term_b, done_b, valid_b, next_val_b)
            mean_return = float(np.mean(finished)) if finished else float("nan")
            row = (steps, time.perf_counter() - start, mean_return, len(finished))
            self.curve.append(row)
            if writer:
                writer.writerow([row[0], f"{row[1]:.1f}", f"{row[2]:.4f}", row[3]])
                handle.flush()
            if log:
                log(row)
            finished = []
        if handle:
            handle.close()
        return self.curve

    def _update(self, obs_b, act_b, logp_b, val_b, rew_b, term_b, done_b, valid_b, next_val_b):
        T = obs_b.shape[0]
        adv = torch.zeros_like(rew_b)
        last = torch.zeros(rew_b.shape[1])
        for t in reversed(range(T)):
            # a chain of advantages stops where an episode ended; a terminated one has no value after
            delta = rew_b[t] + self.gamma * next_val_b[t] * (1 - term_b[t]) - val_b[t]
            last = delta + self.gamma * self.lam * (1 - done_b[t]) * last
            adv[t] = last
        ret = adv + val_b
        mask = valid_b.reshape(-1) > 0
        obs, act = obs_b.reshape(-1, self.obs_size)[mask], act_b.reshape(-1, self.act_size)[mask]
        logp_old, adv, ret = logp_b.reshape(-1)[mask], adv.reshape(-1)[mask], ret.reshape(-1)[mask]
        adv = (adv - adv.mean()) / (adv.std() + 1e-8)
        n = obs.shape[0]
        size = max(1, n // self.minibatches)
        for _ in range(self.epochs):
            order = torch.randperm(n)
            for k in range(0, n, size):
                idx = order[k:k + size]
                dist = self.model.distribution(obs[idx])
                logp = dist.log_prob(act[idx]).sum(-1)
                ratio = (logp - logp_old[idx]).exp()
                surrogate = torch.min(ratio * adv[idx], ratio.clamp(1 - self.clip, 1 + self.clip) * adv[idx])
                value_loss = (self.model.value(obs[idx]) - ret[idx]).pow(2).mean()
                loss = -surrogate.mean() + self.value_coef * value_loss - self.entropy * dist.entropy().sum(-1).mean()
                self.optimizer.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(self.model.parameters(), self.max_grad)
                self.optimizer.step()

    def policy(self, obs):
        """The deterministic policy (the Gaussian's mean), clipped to [-1, 1], for numpy observations."""
        shape = obs.shape[:-1] + (self.act_size,)
        action = self.model.act(self._flat(obs), deterministic=True)[0]
        return action.clamp(-1, 1).reshape(shape).numpy()


def plot_curve(curve, png, title):
    """The learning curve (mean return of the episodes ended in each update) as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = [c[0] for c in curve]
    returns = [c[2] for c in curve]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(steps, returns)
    ax.set_xlabel("agent steps")
    ax.set_ylabel("mean episode return")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)

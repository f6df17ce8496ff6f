"""ssx.learn: vectorised, deterministic learning environments on ssx.

    import numpy as np
    import ssx.learn

    envs = ssx.learn.VectorEnv("goto", num_envs=64)          # 64 Crazyflies, each in a world of its own
    obs, infos = envs.reset(seed=1)
    for _ in range(100):
        actions = envs.action_space.sample()                  # (64, 4) in [-1, 1]
        obs, rewards, terminations, truncations, infos = envs.step(actions)
    envs.close()

`VectorEnv` speaks Gymnasium 1.x's vector API (and is a `gymnasium.vector.VectorEnv` when
gymnasium is importable); `ParallelEnv` speaks PettingZoo's parallel API, one agent per robot of
one world. Each copy of the scene is a world of its own (ssx::VectorEnvironment): copies cannot
touch or sense each other, a copy's trajectory depends only on its own seed and actions, and the
copies are stepped in C++ on a pool of threads with the GIL released. See docs/learning.md.
"""
from __future__ import annotations

import numpy as np

from . import _ssx
from .spaces import Box, Dict, box  # noqa: F401  (re-exported)
from .tasks import Coverage, Formation, GoTo, Hover, Task  # noqa: F401  (re-exported)

try:  # Gymnasium when it is there (Debian 12 does not package it): the class is then one of its
    import gymnasium as _gymnasium

    _VectorBase = _gymnasium.vector.VectorEnv
    try:
        from gymnasium.vector import AutoresetMode as _AutoresetMode

        _MODES = {"next_step": _AutoresetMode.NEXT_STEP, "same_step": _AutoresetMode.SAME_STEP}
    except ImportError:  # gymnasium 1.0 names the mode with a string
        _MODES = {"next_step": "next_step", "same_step": "same_step"}
except ImportError:
    _gymnasium = None
    _VectorBase = object
    _MODES = {"next_step": "next_step", "same_step": "same_step"}

TASKS = {"hover": Hover, "goto": GoTo, "formation": Formation, "coverage": Coverage}


def make_task(task, **options):
    """A Task from a name of TASKS (with its options) or a Task given as it is."""
    if isinstance(task, Task):
        if options:
            raise TypeError("ssx.learn: options go to a task named by a string; this task is made already")
        return task
    if task not in TASKS:
        raise ValueError(f"ssx.learn: unknown task {task!r}: one of {', '.join(sorted(TASKS))}, or a Task")
    return TASKS[task](**options)


def _sim_seed(rng):
    """A 64-bit seed for a copy's random streams, drawn from its episode generator."""
    return int(rng.integers(0, 2**63, dtype=np.int64))


def _latency(action_period):
    """The actuation latency as learn's randomize takes it, beside what the robots' plugins vary."""
    return {"name": "latency", "neutral": 0.0, "min": 0.0, "max": action_period,
            "doc": "s from an action to the motors (whole physics steps, at most action_period)"}


def _ranges(randomize, sim, action_period):
    """The domain randomisation asked for, checked against what every robot can vary: {name: (low, high)}."""
    if not randomize:
        return {}
    if not isinstance(randomize, dict):
        raise TypeError("ssx.learn: randomize must be a dict {name: (low, high)}")
    out = {}
    for name, bounds in randomize.items():
        try:
            low, high = (float(x) for x in bounds)
        except (TypeError, ValueError):
            raise ValueError(f"ssx.learn: randomize[{name!r}] must be a pair (low, high), got {bounds!r}") from None
        for r, robot in enumerate(sim.robot_names):
            known = {v["name"]: v for v in sim.variables(r) + [_latency(action_period)]}
            if name not in known:
                raise ValueError(f"ssx.learn: randomize[{name!r}]: robot {robot!r} has no such constant; it has "
                                 f"{', '.join(known) or 'none'}")
            v = known[name]
            if not (v["min"] <= low <= high <= v["max"]):
                raise ValueError(f"ssx.learn: randomize[{name!r}] = ({low:g}, {high:g}) must have low <= high within "
                                 f"[{v['min']:g}, {v['max']:g}] ({v['doc']})")
        out[name] = (low, high)
    return out


class _Batch:
    """What VectorEnv and ParallelEnv share: the copies, the task, the episodes' generators, the
    buffers every step reuses (no array is made per step on the C++ side)."""

    def __init__(self, task, num_envs, action_period, threads, physics, randomize=None):
        self.task = task
        self.num_envs = int(num_envs)
        if self.num_envs < 1:
            raise ValueError("ssx.learn: num_envs must be at least 1")
        self.sim = _ssx.VectorEnvironment(task.scene(), self.num_envs, threads=threads, label=f"task {task.name}",
                                          physics=physics, base_dir=_ssx.data_directory())
        self.robots = len(self.sim.robot_names)
        if self.robots != task.robots:
            raise ValueError(f"ssx.learn: task {task.name}'s scene has {self.robots} robots, the task says {task.robots}")
        steps = action_period / self.sim.timestep
        self.steps_per_action = int(round(steps))
        if self.steps_per_action < 1 or abs(steps - self.steps_per_action) > 1e-9 * steps:
            raise ValueError(f"ssx.learn: action_period {action_period} s is not a whole number of physics "
                             f"timesteps ({self.sim.timestep} s)")
        self.action_period = self.steps_per_action * self.sim.timestep
        # the start state: every copy's robots taken off and hovering where the task puts them
        takeoff = task.takeoff_commands(self.sim.robot_states(), self.num_envs)
        if takeoff is not None:
            self.sim.set_commands("position", takeoff)
        self.sim.step(max(1, int(round(task.takeoff_seconds / self.sim.timestep))))
        self.start_state = self.sim.save_state(0)
        self.states = np.empty((self.num_envs, self.robots, 13))
        self.imu = np.empty((self.num_envs, self.robots, 6)) if task.reads_imu else None
        self.sensors = [(kind, slots, self.sim.read(kind, slots=slots)) for kind, slots in task.sensors]
        task.readings = {kind: out for kind, _, out in self.sensors}
        self.rngs = [np.random.default_rng() for _ in range(self.num_envs)]
        self.steps = np.zeros(self.num_envs, dtype=np.int64)
        self.randomize = _ranges(randomize, self.sim, self.action_period)
        low = np.array([r[0] for r in self.randomize.values()]).reshape(-1, 1, 1)
        self._bounds = (low, np.array([r[1] for r in self.randomize.values()]).reshape(-1, 1, 1) - low)
        # each copy's draws now, (constants, E, R) in the order of randomize; neutral until the first reset
        neutral = {v["name"]: v["neutral"] for v in self.sim.variables(0) + [_latency(self.action_period)]}
        self.drawn = np.array([np.full((self.num_envs, self.robots), neutral[name]) for name in self.randomize])
        self.read()
        task.bind(self.num_envs, self.action_period, self.states)

    def variation_infos(self):
        """The constants drawn for each copy's episode, {name: (E, R) array}, for infos."""
        return {name: self.drawn[j].copy() for j, name in enumerate(self.randomize)}

    def read(self):
        self.sim.robot_states(out=self.states)
        if self.imu is not None:
            self.sim.imu(out=self.imu)
        self.read_sensors()

    def read_sensors(self):
        for kind, slots, out in self.sensors:
            self.sim.read(kind, out=out, slots=slots)

    def step(self, commands, active=None):
        """The task's commands sent to the copies `active` flags (all: None), held for an action period,
        and the copies read, in one pass over each copy in C++ (a thousand copies do not stay in the
        caches between passes of their own)."""
        self.sim.step(self.steps_per_action, active, level=self.task.level, commands=commands, states=self.states,
                      imu=self.imu)
        self.read_sensors()

    def seed_all(self, seed):
        """Gymnasium's convention: an int seeds copy i with seed + i, a list one seed per copy,
        None with fresh entropy."""
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"ssx.learn: reset(seed=) has {len(seeds)} seeds for {self.num_envs} environments")
        for i, s in enumerate(seeds):
            if s is not None and (not isinstance(s, (int, np.integer)) or s < 0):
                raise ValueError(f"ssx.learn: seed {s!r} (environment {i}) is not a whole number >= 0")
            self.rngs[i] = np.random.default_rng(s)

    def reset_copies(self, ids):
        """Restores the copies `ids` to the start state, reseeds their streams from their episode
        generators, draws their episodes (the task: start offsets, goals) and moves the robots."""
        ids = [int(i) for i in ids]
        if not ids:
            return
        rngs = [self.rngs[i] for i in ids]
        self.sim.reset(ids, self.start_state, [_sim_seed(rng) for rng in rngs])
        offsets, velocities = self.task.draw(ids, rngs)
        self.sim.move_robots(ids, offsets, velocities)
        # domain randomisation: each robot's constants drawn from its copy's episode generator
        if self.randomize:
            low, span = self._bounds
            draws = low + span * np.stack([rng.random((len(self.randomize), self.robots)) for rng in rngs], axis=1)
            for j, name in enumerate(self.randomize):
                if name == "latency":  # in whole physics steps: what the copies take
                    steps = np.rint(draws[j] / self.sim.timestep).astype(np.int64)
                    self.sim.set_command_delays(ids, steps)
                    draws[j] = steps * self.sim.timestep
                else:
                    self.sim.vary(ids, name, draws[j])
            self.drawn[:, ids] = draws
        self.steps[ids] = 0


class VectorEnv(_VectorBase):
    """`num_envs` copies of a task's scene, stepped together (Gymnasium 1.x vector API).

    task: "hover", "goto", "formation" or a Task; options go to the named task. action_period:
    how long an action is held, s of simulated time (a whole number of physics steps).
    autoreset_mode: "next_step" (Gymnasium's default: the step after an episode ended resets that
    copy and returns its first observation, reward 0) or "same_step" (reset at once; the last
    observation in infos["final_obs"]). threads: threads stepping the copies (None: one per core).
    randomize: domain randomisation, {name: (low, high)}: each robot's constant drawn uniformly at
    every reset from its copy's episode generator ("mass", "inertia", "thrust_coefficient",
    "time_constant_up", "wind_x", "gyro_noise", "battery_volts", ...: sim.variables(0) lists them; and
    "latency", s from an action to the motors, whole physics steps up to action_period); the draws are
    in infos["variations"] at reset and whenever a copy resets in step (infos["_variations"] says which).
    """

    def __init__(self, task="goto", num_envs=16, action_period=0.02, autoreset_mode="next_step", threads=None,
                 physics=None, randomize=None, **task_options):
        if autoreset_mode not in _MODES:
            raise ValueError(f"ssx.learn: autoreset_mode must be 'next_step' or 'same_step', got {autoreset_mode!r}")
        self.task = make_task(task, **task_options)
        self._b = _Batch(self.task, num_envs, action_period, threads, physics, randomize)
        self.num_envs = self._b.num_envs
        self.action_period = self._b.action_period
        self.metadata = {"autoreset_mode": _MODES[autoreset_mode], "render_modes": []}
        self.render_mode = None
        self._same_step = autoreset_mode == "same_step"
        self.single_observation_space = self.task.observation_space()
        self.single_action_space = self.task.action_space()
        self.observation_space = box(self.single_observation_space, self.num_envs)
        self.action_space = box(self.single_action_space, self.num_envs)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._active = np.ones(self.num_envs, dtype=np.uint8)
        self._obs = np.zeros(self.observation_space.shape, dtype=np.float32)
        self._started = False
        self.closed = False

    @property
    def unwrapped(self):
        return self

    @property
    def robot_names(self):
        return self._b.sim.robot_names

    def reset(self, seed=None, options=None):
        """Every copy to a new episode: (observations, infos). `seed`: int (copy i gets seed + i),
        a list of one per copy, or None. options={"reset_mask": bool array} resets only those copies."""
        b = self._b
        ids = np.arange(self.num_envs)
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"], dtype=bool)
            if mask.shape != (self.num_envs,):
                raise ValueError(f"ssx.learn: reset_mask must have shape ({self.num_envs},)")
            ids = np.flatnonzero(mask)
            if seed is not None:
                raise ValueError("ssx.learn: seed and reset_mask together are not supported: seed the copies first")
        else:
            b.seed_all(seed)
        b.reset_copies(ids)
        self._autoreset[ids] = False
        self._started = True
        b.read()
        self.task.observe(b.states, b.imu, self._obs)
        return self._obs.copy(), ({"variations": b.variation_infos()} if b.randomize else {})

    @property
    def sim(self):
        """The copies (ssx._ssx.VectorEnvironment): their robots, variables and state hashes."""
        return self._b.sim

    def step(self, actions):
        """Holds the actions for action_period: (observations, rewards, terminations, truncations, infos)."""
        if not self._started:
            raise RuntimeError("ssx.learn: call reset() before step()")
        b, task = self._b, self.task
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != self.action_space.shape:
            raise ValueError(f"ssx.learn: actions must have shape {self.action_space.shape}, got {actions.shape}")
        if not np.all(np.isfinite(actions)):
            raise ValueError("ssx.learn: actions hold a NaN or an infinity")
        commands = task.commands(actions)
        resetting = np.flatnonzero(self._autoreset)
        if len(resetting):
            b.sim.check_commands(task.level, commands)  # (refused before any copy is reset)
            b.reset_copies(resetting)
        np.logical_not(self._autoreset, out=self._active.view(bool))
        b.step(commands, self._active if len(resetting) else None)
        b.steps += self._active
        task.observe(b.states, b.imu, self._obs)
        rewards, terminated, infos = task.evaluate(b.states, b.imu, actions)
        truncated = b.steps >= task.horizon
        if len(resetting):
            rewards[resetting] = 0.0
            terminated[resetting] = False
            truncated[resetting] = False
        done = terminated | truncated
        obs = self._obs.copy()
        if self._same_step:
            ended = np.flatnonzero(done)
            if len(ended):
                infos["final_obs"] = np.array([obs[i] if done[i] else None for i in range(self.num_envs)], dtype=object)
                infos["_final_obs"] = done.copy()
                b.reset_copies(ended)
                b.read()
                task.observe(b.states, b.imu, self._obs)
                obs[ended] = self._obs[ended]
        else:
            self._autoreset = done
        if b.randomize and (len(resetting) or (self._same_step and done.any())):
            reset_now = np.zeros(self.num_envs, dtype=bool)
            reset_now[resetting] = True
            if self._same_step:
                reset_now |= done
            infos["variations"] = b.variation_infos()
            infos["_variations"] = reset_now
        return obs, rewards.astype(np.float64), terminated, truncated, infos

    def close(self, **kwargs):
        if not self.closed:
            self._b.sim.close()
            self.closed = True

    def state_hashes(self):
        """Each copy's state hash: for determinism checks."""
        return self._b.sim.state_hashes()

    def __repr__(self):
        return f"ssx.learn.VectorEnv({self.task.name!r}, num_envs={self.num_envs})"


class ParallelEnv:
    """A swarm in one world, one agent per robot (PettingZoo's parallel API). Agents whose robot
    crashed or left the bounds leave `agents`; the episode ends for all at the horizon."""

    metadata = {"name": "ssx_parallel_v0", "render_modes": []}

    def __init__(self, task="formation", action_period=0.02, threads=1, physics=None, randomize=None,
                 **task_options):
        self.task = make_task(task, **task_options)
        self._b = _Batch(self.task, 1, action_period, threads, physics, randomize)
        self.possible_agents = list(self._b.sim.robot_names)
        self.agents = []
        self.render_mode = None
        self._obs_space = self.task.observation_space(per_agent=True)
        self._act_space = self.task.action_space(per_agent=True)
        self._obs = np.zeros((1,) + self.task.observation_space().shape, dtype=np.float32)
        self._alive = np.zeros(len(self.possible_agents), dtype=bool)

    def observation_space(self, agent):
        return self._obs_space

    def action_space(self, agent):
        return self._act_space

    @property
    def num_agents(self):
        return len(self.agents)

    @property
    def max_num_agents(self):
        return len(self.possible_agents)

    def reset(self, seed=None, options=None):
        b = self._b
        b.seed_all(None if seed is None else [seed])
        b.reset_copies([0])
        self._alive[:] = True
        self.agents = list(self.possible_agents)
        b.read()
        self.task.observe(b.states, b.imu, self._obs)
        drawn = b.variation_infos()
        infos = {a: {name: float(values[0, k]) for name, values in drawn.items()} for k, a in enumerate(self.agents)}
        return {a: self._obs[0, k].copy() for k, a in enumerate(self.possible_agents)}, infos

    def step(self, actions):
        b, task = self._b, self.task
        if not self.agents:
            raise RuntimeError("ssx.learn: every agent is done: call reset()")
        act = np.zeros((1,) + task.action_space().shape)
        for k, a in enumerate(self.possible_agents):
            if a in actions:
                act[0, k] = actions[a]
            elif self._alive[k]:
                raise KeyError(f"ssx.learn: no action for agent {a!r}")
        b.step(task.commands(act))
        b.steps += 1
        task.observe(b.states, b.imu, self._obs)
        rewards, terminated, infos = task.evaluate(b.states, b.imu, act)
        truncate = bool(b.steps[0] >= task.horizon)
        agent_done = task.agent_terminations(b.states)[0]
        per_agent = infos.get("agent_rewards", np.repeat(rewards[:, None], task.robots, axis=1))
        obs, rew, term, trunc, info = {}, {}, {}, {}, {}
        for k, a in enumerate(self.possible_agents):
            if not self._alive[k]:
                continue
            obs[a] = self._obs[0, k].copy()
            rew[a] = float(per_agent[0, k])
            term[a] = bool(agent_done[k])
            trunc[a] = truncate
            info[a] = {key: value[0] for key, value in infos.items() if not key.startswith("_")}
            if term[a] or trunc[a]:
                self._alive[k] = False
        self.agents = [a for k, a in enumerate(self.possible_agents) if self._alive[k]]
        return obs, rew, term, trunc, info

    def state(self):
        return self._obs[0].copy()

    def close(self):
        self._b.sim.close()


class TorchVectorEnv:
    """A VectorEnv whose observations, rewards and flags come as torch tensors sharing memory with
    the numpy arrays (torch.from_numpy), and whose actions may be tensors."""

    def __init__(self, env):
        import torch  # noqa: F401  (torch is needed; ImportError says so)

        self.env = env

    def __getattr__(self, name):
        return getattr(self.env, name)

    def reset(self, seed=None, options=None):
        import torch

        obs, infos = self.env.reset(seed=seed, options=options)
        return torch.from_numpy(obs), infos

    def step(self, actions):
        import torch

        if isinstance(actions, torch.Tensor):
            actions = actions.detach().cpu().numpy()
        obs, rew, term, trunc, infos = self.env.step(actions)
        return (torch.from_numpy(obs), torch.from_numpy(rew), torch.from_numpy(term), torch.from_numpy(trunc), infos)


try:  # Stable-Baselines3 when it is there: the adapter is then one of its VecEnvs
    from stable_baselines3.common.vec_env import VecEnv as _SB3Base
except ImportError:
    _SB3Base = object


class SB3VecEnv(_SB3Base):
    """A VectorEnv behind Stable-Baselines3's VecEnv interface (reset() -> obs, step_async /
    step_wait -> obs, rewards, dones, infos as a list of dicts, with "terminal_observation" and
    "TimeLimit.truncated" where an episode ended). SB3 resets a finished environment in the step
    that ends it: the VectorEnv must be made with autoreset_mode="same_step"."""

    def __init__(self, env):
        if env.metadata["autoreset_mode"] != _MODES["same_step"]:
            raise ValueError("ssx.learn: SB3VecEnv needs a VectorEnv made with autoreset_mode='same_step' "
                             "(Stable-Baselines3 resets an environment in the step that ends its episode)")
        self.env = env
        if _SB3Base is not object:
            super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        else:
            self.num_envs = env.num_envs
            self.observation_space = env.single_observation_space
            self.action_space = env.single_action_space
        self.reset_infos = [{} for _ in range(env.num_envs)]
        self._actions = None
        self._seed = None

    def _per_env(self, infos):
        out = [{} for _ in range(self.num_envs)]
        for key, value in infos.items():
            if key.startswith("_") or key == "final_obs":
                continue
            if isinstance(value, dict):  # variations: {name: (E, R)}
                for name, values in value.items():
                    for i in range(self.num_envs):
                        out[i].setdefault(key, {})[name] = values[i]
            elif isinstance(value, np.ndarray) and value.shape[:1] == (self.num_envs,):
                for i in range(self.num_envs):
                    out[i][key] = value[i]
        return out

    def seed(self, seed=None):
        """Seeds the next reset: environment i with seed + i (SB3's convention)."""
        self._seed = seed
        return [None if seed is None else seed + i for i in range(self.num_envs)]

    def reset(self):
        obs, infos = self.env.reset(seed=self._seed)
        self._seed = None
        self.reset_infos = self._per_env(infos)
        return obs

    def step_async(self, actions):
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("ssx.learn: step_wait() without step_async()")
        obs, rewards, terminated, truncated, infos = self.env.step(self._actions)
        self._actions = None
        dones = terminated | truncated
        out = self._per_env(infos)
        for i in np.flatnonzero(dones):
            out[i]["terminal_observation"] = infos["final_obs"][i]
            out[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, rewards.astype(np.float32), dones, out

    def step(self, actions):
        self.step_async(actions)
        return self.step_wait()

    def close(self):
        self.env.close()

    def _indices(self, indices):
        if indices is None:
            return range(self.num_envs)
        return [indices] if isinstance(indices, int) else indices

    # the copies share one VectorEnv: an attribute or method is the VectorEnv's, once per index
    def get_attr(self, attr_name, indices=None):
        return [getattr(self.env, attr_name) for _ in self._indices(indices)]

    def set_attr(self, attr_name, value, indices=None):
        setattr(self.env, attr_name, value)

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        return [getattr(self.env, method_name)(*method_args, **method_kwargs) for _ in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False for _ in self._indices(indices)]

    def get_images(self):
        return [None for _ in range(self.num_envs)]

"""Tasks of ssx.learn: what a learning environment observes, how actions become commands, the
reward, when an episode ends. Every hook works on the whole batch at once (numpy arrays whose
first axis is the environment), so a task adds little per step however many environments run.

A task of your own subclasses Task (or GoTo, Formation) and overrides the hooks; see
docs/learning.md.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree

import numpy as np

from . import _ssx
from .spaces import make_box

VEHICLES = ("crazyflie", "mk_quad", "hummingbird")
LEVELS = ("position", "velocity", "attitude", "rates", "rotors")
GRAVITY = 9.81


def vehicle_mass(vehicle):
    """The mass (kg) of an installed vehicle type: the sum of its artifact file's physic masses."""
    path = _ssx.data_directory() / "artifacts" / f"{vehicle}.xml"
    root = ElementTree.parse(path).getroot()
    return sum(float(p.get("mass", "0")) for p in root.iter("physic"))


def vehicle_rotors(vehicle):
    """(thrust coefficient N s^2, top rotor speed rad/s, rotor count) of an installed vehicle type: its
    artifact's quadrotor driver, each value from the driver's attributes or else from its preset."""
    data = _ssx.data_directory()
    driver = ElementTree.parse(data / "artifacts" / f"{vehicle}.xml").getroot().find(".//driver")
    preset = ElementTree.parse(data / "presets" / "quadrotor" / f"{driver.get('preset', 'mk_quad')}.xml").getroot()
    values = {p.get("name"): p.get("value") for p in preset.iter("param")}
    values.update(driver.attrib)
    rotors = len(values["rotors"].split()) if "rotors" in values else 4
    return float(values["thrust_coefficient"]), float(values["max_rotor_speed"]), rotors


class Task:
    """The hooks a learning environment calls. Arrays: E environments, R robots each.

    states (E, R, 13): x y z, qw qx qy qz, vx vy vz, wx wy wz (world frame); imu (E, R, 6):
    accelerometer (m/s^2), gyroscope (rad/s), body frame, or None when reads_imu is False.
    """

    name = "task"
    robots = 1
    level = "attitude"  # the command level actions become (ssx/command.hpp)
    reads_imu = True
    # batched sensor reads (VectorEnvironment.read): (kind, slots) pairs, read after every step
    # into self.readings[kind], (E, R, width) arrays the environment fills before bind
    sensors = ()
    takeoff_seconds = 3.0
    horizon = 250  # actions per episode (set by bind from horizon_seconds)

    def scene(self):
        """The scene of one environment, as XML (files resolve against ssx.data_directory())."""
        raise NotImplementedError

    def takeoff_commands(self, states, num_envs):
        """(E, R, 4) position commands flown for takeoff_seconds before the start state is saved
        (None: no commands, the robots stand or hover as the scene has them)."""
        raise NotImplementedError

    def bind(self, num_envs, action_period, states):
        """Called once the start state is saved: `states` are the robots hovering in it."""

    def draw(self, ids, rngs):
        """A new episode for environments `ids`, each drawing from its own generator `rngs[k]`:
        returns the robots' start offsets and velocities, (len(ids), R, 3) each."""
        raise NotImplementedError

    def observation_space(self, per_agent=False):
        raise NotImplementedError

    def action_space(self, per_agent=False):
        raise NotImplementedError

    def observe(self, states, imu, out):
        """Writes the observations of every environment into `out` (E, ...) float32."""
        raise NotImplementedError

    def commands(self, actions):
        """(E, R, columns) commands at `level` from the actions (E, ...)."""
        raise NotImplementedError

    def evaluate(self, states, imu, actions):
        """(rewards (E,), terminated (E,) bool, infos dict of (E,) arrays) after a step. A task
        with several robots may give each robot's reward as infos["agent_rewards"] (E, R): what
        ParallelEnv hands each agent (else every robot gets its environment's)."""
        raise NotImplementedError

    def agent_terminations(self, states):
        """Per robot (E, R) bool, for ParallelEnv: crashed, tilted over or out of bounds."""
        return self._crashed(states)


class _Flight(Task):
    """What the quadrotor tasks share: a vehicle, a command level, actions in [-1, 1] scaled to
    it, crash, tilt and bounds checks."""

    def __init__(self, vehicle="crazyflie", level="attitude", robots=1, hover_height=1.0, spacing=1.0,
                 horizon_seconds=5.0, max_tilt=0.5, max_rate=4.0, max_yaw_rate=1.0, thrust_range=0.6, max_speed=1.0,
                 max_offset=0.5,
                 bounds=3.0, max_tilt_crash=70.0, timestep=0.002):
        if vehicle not in VEHICLES:
            raise ValueError(f"ssx.learn: vehicle must be one of {', '.join(VEHICLES)}, got {vehicle!r}")
        if level not in LEVELS:
            raise ValueError(f"ssx.learn: level must be one of {', '.join(LEVELS)}, got {level!r}")
        self.vehicle, self.level, self.robots = vehicle, level, int(robots)
        self.hover_height, self.spacing, self.timestep = hover_height, spacing, timestep
        self.horizon_seconds = horizon_seconds
        self.max_tilt, self.max_rate, self.max_yaw_rate = max_tilt, max_rate, max_yaw_rate
        self.thrust_range, self.max_speed, self.bounds = thrust_range, max_speed, bounds
        self.max_offset = max_offset
        self.cos_crash = math.cos(math.radians(max_tilt_crash))
        self.weight = vehicle_mass(vehicle) * GRAVITY
        self.rotor_count = 4
        if level == "rotors":
            # each rotor's speed: a = 0 holds the weight (thrust grows with the speed squared)
            coefficient, self.max_rotor_speed, self.rotor_count = vehicle_rotors(vehicle)
            self.hover_rotor_speed = math.sqrt(self.weight / (self.rotor_count * coefficient))
        self._commands = None

    def scene(self):
        return f"""<scene>
  <environment timestep="{self.timestep}" seed="1"/>
  <type name="{self.vehicle}" file="artifacts/{self.vehicle}.xml"/>
  <ground/>
  <swarm type="{self.vehicle}" count="{self.robots}" name="r{{i}}" spacing="{self.spacing}" xyz="0 0 0.05">
    <driver reference="external"/>
  </swarm>
</scene>"""

    def takeoff_commands(self, states, num_envs):
        c = np.zeros((num_envs, self.robots, 4))
        c[:, :, :2] = states[:, :, :2]
        c[:, :, 2] = self.hover_height
        return c

    def bind(self, num_envs, action_period, states):
        self.num_envs = num_envs
        self.horizon = max(1, int(round(self.horizon_seconds / action_period)))
        self.home = states[0, :, :3].copy()  # every copy hovers at the same place in the start state
        self._commands = np.zeros((num_envs, self.robots, self.rotor_count if self.level == "rotors" else 4))
        self._states = states  # the environment's, read in place after every step (position commands)

    def action_space(self, per_agent=False):
        n = self.rotor_count if self.level == "rotors" else 4
        shape = (n,) if per_agent or self.robots == 1 else (self.robots, n)
        return make_box(-1.0, 1.0, shape, np.float32)

    def commands(self, actions):
        c = self._commands
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(self.num_envs, self.robots, c.shape[-1]), -1.0, 1.0)
        c = c[: a.shape[0]]
        if self.level == "rotors":  # each rotor's thrust the weight's share times 1 + thrust_range a
            np.sqrt(np.maximum(1.0 + self.thrust_range * a, 0.0), out=c)
            c *= self.hover_rotor_speed
            np.minimum(c, self.max_rotor_speed, out=c)
        elif self.level == "position":  # a set-point up to max_offset m from where each robot is, and a heading
            c[..., :3] = self._states[: a.shape[0], :, 0:3] + a[..., :3] * self.max_offset
            c[..., 3] = a[..., 3] * np.pi
        elif self.level == "velocity":
            c[..., :3] = a[..., :3] * self.max_speed
            c[..., 3] = a[..., 3] * self.max_yaw_rate
        else:
            if self.level == "attitude":
                c[..., :2] = a[..., :2] * self.max_tilt
                c[..., 2] = a[..., 2] * self.max_yaw_rate
            else:
                c[..., :3] = a[..., :3] * self.max_rate
                c[..., 2] = a[..., 2] * self.max_yaw_rate
            c[..., 3] = self.weight * (1.0 + self.thrust_range * a[..., 3])
        return c

    def _crashed(self, states):
        """(E, R) bool: below 8 cm (on the ground), tilted beyond the crash angle, or out of bounds."""
        up_z = 1.0 - 2.0 * (states[..., 4] ** 2 + states[..., 5] ** 2)
        away = np.abs(states[..., :3] - self.home).max(axis=-1)
        return (states[..., 2] < 0.08) | (up_z < self.cos_crash) | (away > self.bounds)


class GoTo(_Flight):
    """One quadrotor (a Crazyflie by default) must reach a goal drawn per episode and hold there.

    Start: hovering within `start_range` m of its home (1 m up; half that vertically), moving at up
    to `start_speed` m/s along each axis.
    Goal: within `goal_range` m of home (half that vertically). Observation (16, float32): the goal
    relative to the robot (m), its velocity (m/s, / 2), its orientation (qw >= 0), the IMU's gyro
    (rad/s, / 10) and accelerometer (m/s^2, / 10). Action (4, in [-1, 1]): at `level` "position" a
    set-point (times max_offset m from where the robot is) and a heading (times pi rad); "attitude"
    roll and pitch (times max_tilt rad), yaw rate (times max_yaw_rate) and thrust (the weight times
    1 + thrust_range a); "rates": body rates (times max_rate rad/s, yaw max_yaw_rate) and thrust;
    "velocity": m/s (times max_speed) and yaw rate. Reward: exp(-distance / 0.5) per action, minus
    0.02 per rad/s of body rate; an episode ends (terminated) on a crash, a tilt over 70 degrees or
    leaving `bounds` m around home, and is truncated after horizon_seconds. infos: "distance" (m)
    and "success" (within success_radius)."""

    name = "goto"

    def __init__(self, vehicle="crazyflie", level="attitude", goal_range=1.0, start_range=0.3, start_speed=0.2,
                 success_radius=0.1, **options):
        super().__init__(vehicle=vehicle, level=level, robots=options.pop("robots", 1), **options)
        self.goal_range, self.start_range, self.start_speed = goal_range, start_range, start_speed
        self.success_radius = success_radius

    def bind(self, num_envs, action_period, states):
        super().bind(num_envs, action_period, states)
        self.goals = np.repeat(self.home[None], num_envs, axis=0)
        self._start_scale = np.array([self.start_range, self.start_range, 0.5 * self.start_range])
        self._goal_scale = np.array([self.goal_range, self.goal_range, 0.5 * self.goal_range])
        self._draw_scale = np.concatenate([self._start_scale, np.full(3, self.start_speed), self._goal_scale])

    def _goals(self, starts, u, scaled=False):
        """Goals for episodes starting at `starts` (k, R, 3) from uniform numbers u in [-1, 1) (k, R, 3)
        (`scaled`: u already times the goal range)."""
        goals = self.home + (u if scaled else u * self._goal_scale)
        np.maximum(goals[..., 2], 0.3, out=goals[..., 2])
        return goals

    def draw(self, ids, rngs):
        # one call per environment to its own generator (9 numbers a robot), the rest for all at once
        # (few numpy calls: a reset of one environment is a handful of small arrays)
        u = np.array([rng.random((self.robots, 9)) for rng in rngs])
        u *= 2.0
        u -= 1.0  # (k, R, 9) in [-1, 1)
        u *= self._draw_scale  # start offsets (m), start velocities (m/s), goals from home (m)
        self.goals[ids] = self._goals(self.home + u[..., 0:3], u[..., 6:9], scaled=True)
        return u[..., 0:3], u[..., 3:6]

    def observation_space(self, per_agent=False):
        shape = (16,) if per_agent or self.robots == 1 else (self.robots, 16)
        return make_box(-10.0, 10.0, shape, np.float32)

    def observe(self, states, imu, out):
        # (written in place: a thousand copies' temporaries cost more than the numbers)
        o = out.reshape(len(states), self.robots, 16)
        np.subtract(self.goals[: len(states)], states[..., 0:3], out=o[..., 0:3])
        np.multiply(states[..., 7:10], 0.5, out=o[..., 3:6])
        q = states[..., 3:7]
        np.multiply(q, np.where(q[..., :1] < 0, -1.0, 1.0), out=o[..., 6:10])
        np.multiply(imu[..., 3:6], 0.1, out=o[..., 10:13])
        np.multiply(imu[..., 0:3], 0.1, out=o[..., 13:16])
        np.clip(o, -10.0, 10.0, out=o)

    def evaluate(self, states, imu, actions):
        distance = np.linalg.norm(self.goals[: len(states)] - states[..., 0:3], axis=-1)  # (E, R)
        spin = np.linalg.norm(states[..., 10:13], axis=-1)
        crashed = self._crashed(states)
        reward = np.exp(-distance / 0.5) - 0.02 * spin
        reward = np.where(crashed, -1.0, reward).mean(axis=1)
        terminated = crashed.any(axis=1)
        infos = {"distance": distance.mean(axis=1), "success": (distance < self.success_radius).all(axis=1)}
        return reward, terminated, infos


class Hover(GoTo):
    """GoTo whose goal is where the episode starts: hold a hover against a random start velocity."""

    name = "hover"

    def __init__(self, vehicle="crazyflie", level="attitude", start_speed=0.5, **options):
        options.pop("goal_range", None)
        super().__init__(vehicle=vehicle, level=level, goal_range=0.0, start_speed=start_speed, **options)

    def _goals(self, starts, u, scaled=False):
        return starts


class Formation(_Flight):
    """A swarm of `robots` quadrotors (8 Crazyflies by default) must form a ring of `radius` m at
    their home height, turned by an angle drawn per episode, robot k at slot k, without collisions.

    Observation per robot (15): its slot relative to it (m), its velocity (/ 2), the positions of
    its 3 nearest neighbours relative to it (m). Action per robot (4, in [-1, 1]): a velocity
    command (times max_speed m/s; yaw rate times max_yaw_rate). Reward per robot: exp(-distance /
    0.5) minus `collision_penalty` while a neighbour is closer than `collision_distance` m; the
    environment's reward is the robots' mean. A robot that crashes ends the episode (VectorEnv) or
    leaves `agents` (ParallelEnv). infos: "distance" (mean, m), "collisions" (pairs closer than
    collision_distance at this step)."""

    name = "formation"
    reads_imu = False
    neighbours = 3

    def __init__(self, robots=8, vehicle="crazyflie", radius=1.0, start_range=0.2, collision_distance=0.15,
                 collision_penalty=1.0, horizon_seconds=10.0, **options):
        options.setdefault("level", "velocity")
        options.setdefault("spacing", 0.8)
        super().__init__(vehicle=vehicle, robots=robots, horizon_seconds=horizon_seconds, **options)
        if self.robots < self.neighbours + 1:
            raise ValueError(f"ssx.learn: a formation needs at least {self.neighbours + 1} robots")
        self.radius, self.start_range = radius, start_range
        self.collision_distance, self.collision_penalty = collision_distance, collision_penalty

    def bind(self, num_envs, action_period, states):
        super().bind(num_envs, action_period, states)
        self.centre = self.home.mean(axis=0)
        self.slots = np.repeat(self.home[None], num_envs, axis=0)
        # the pairs' arrays, component first (numpy's loops then run along rows of R, not of 3), filled
        # at every step: new ones each step cost more than the numbers in them
        r = self.robots
        self._p, self._rel = np.empty((3, num_envs, r)), np.empty((3, num_envs, r, r))
        self._dist, self._square = np.empty((num_envs, r, r)), np.empty((num_envs, r, r))
        self._diagonal = np.arange(r)
        self._first_pair = (np.arange(num_envs * r) * r).reshape(num_envs, r, 1)  # (copy, robot)'s first in a row of rel

    def draw(self, ids, rngs):
        u = np.array([rng.random(2 * self.robots + 1) for rng in rngs])  # (k, 2R + 1) in [0, 1)
        offsets = np.zeros((len(ids), self.robots, 3))
        offsets[..., :2] = (u[:, :-1].reshape(len(ids), self.robots, 2) * 2.0 - 1.0) * self.start_range
        phase = u[:, -1:] * 2 * np.pi + 2 * np.pi * np.arange(self.robots) / self.robots  # (k, R)
        self.slots[ids, :, 0] = self.centre[0] + self.radius * np.cos(phase)
        self.slots[ids, :, 1] = self.centre[1] + self.radius * np.sin(phase)
        self.slots[ids, :, 2] = self.centre[2]
        return offsets, np.zeros_like(offsets)

    def observation_space(self, per_agent=False):
        shape = (15,) if per_agent else (self.robots, 15)
        return make_box(-10.0, 10.0, shape, np.float32)

    def action_space(self, per_agent=False):
        return make_box(-1.0, 1.0, (4,) if per_agent else (self.robots, 4), np.float32)

    def _pairs(self, states, fresh=False):
        """(3, E, R, R) relative positions, [k, e, i, j] robot j's coordinate k less robot i's, and
        (E, R, R) distances, the diagonal at infinity, in arrays the next call fills again. observe()
        keeps them for the evaluate() that follows it on the same states (a step's two calls)."""
        kept, self._kept_pairs = getattr(self, "_kept_pairs", None), None
        if kept is not None and not fresh:
            return kept
        n = len(states)
        p, rel, dist, square = self._p[:, :n], self._rel[:, :n], self._dist[:n], self._square[:n]
        np.copyto(p, np.moveaxis(states[..., 0:3], -1, 0))
        np.subtract(p[:, :, None, :], p[:, :, :, None], out=rel)
        np.multiply(rel[0], rel[0], out=dist)
        for k in (1, 2):
            np.multiply(rel[k], rel[k], out=square)
            dist += square
        np.sqrt(dist, out=dist)
        dist[:, self._diagonal, self._diagonal] = np.inf
        return rel, dist

    def observe(self, states, imu, out):
        n = len(states)
        o = out.reshape(n, self.robots, 15)
        np.subtract(self.slots[:n], states[..., 0:3], out=o[..., 0:3])
        np.multiply(states[..., 7:10], 0.5, out=o[..., 3:6])
        rel, dist = self._pairs(states, fresh=True)
        self._kept_pairs = (rel, dist)  # for evaluate(), on these states
        nearest = np.argsort(dist, axis=-1, kind="stable")[..., : self.neighbours]  # (E, R, 3)
        nearest += self._first_pair[:n]  # where in rel's rows of one coordinate
        picked = rel.reshape(3, -1)[:, nearest]  # (3, E, R, 3): coordinate, copy, robot, neighbour
        o[..., 6:15] = np.moveaxis(picked, 0, -1).reshape(n, self.robots, 3 * self.neighbours)
        np.clip(o, -10.0, 10.0, out=o)

    def _agent_rewards(self, states):
        distance = np.linalg.norm(self.slots[: len(states)] - states[..., 0:3], axis=-1)
        _, dist = self._pairs(states)
        close = dist < self.collision_distance
        crashed = self._crashed(states)
        reward = np.exp(-distance / 0.5) - self.collision_penalty * close.any(axis=-1)
        return np.where(crashed, -1.0, reward), distance, close, crashed

    def evaluate(self, states, imu, actions):
        reward, distance, close, crashed = self._agent_rewards(states)
        infos = {"distance": distance.mean(axis=1), "collisions": close.sum(axis=(1, 2)) // 2, "agent_rewards": reward}
        return reward.mean(axis=1), crashed.any(axis=1), infos


class Coverage(Task):
    """Ground robots (`robots` e-pucks) cover a walled square arena of `arena` m together: the
    floor is cut into cells of `cell` m, and a cell counts once any robot's centre has been in it.

    Observation per robot (21, float32): its position (/ half the arena), heading (cos, sin), its 8
    proximity readings (0..1, batched from its own sensors), and the 3 x 3 cells around its own
    (1: covered or beyond the walls, 0: still to cover). Action per robot (2, in [-1, 1]): left and
    right wheel speeds (times max_wheel_speed rad/s; the `wheels` command level), or with
    level="velocity" a forward speed (times max_speed m/s) and a yaw rate (times max_yaw_rate rad/s).
    Reward per robot: `cell_reward` for each cell it is the first to reach, minus `bump_penalty`
    while a proximity reading is above `bump_reading` (a wall or a robot within about a centimetre); the environment's
    reward is the robots' sum. Nothing terminates an episode (a ground robot cannot crash); it is
    truncated after horizon_seconds. Start: the robots on a grid in the arena, each moved by up to
    `start_jitter` m. infos: "coverage" (the fraction of cells covered) and "bumps" (robots bumping)."""

    name = "coverage"
    level = "wheels"
    reads_imu = False
    sensors = (("proximity", 0),)
    takeoff_seconds = 0.2  # standing still: the proximity sensors' first readings

    def __init__(self, robots=4, arena=1.0, cell=0.1, horizon_seconds=30.0, max_wheel_speed=6.2832,
                 start_jitter=0.03, cell_reward=1.0, bump_penalty=0.05, bump_reading=0.8, timestep=0.002,
                 level="wheels", max_speed=0.128, max_yaw_rate=4.0):
        if level not in ("wheels", "velocity"):
            raise ValueError(f"ssx.learn: coverage's level must be 'wheels' or 'velocity', got {level!r}")
        self.level, self.max_speed, self.max_yaw_rate = level, max_speed, max_yaw_rate
        self.robots, self.arena, self.cell = int(robots), float(arena), float(cell)
        self.cells = int(math.ceil(self.arena / self.cell - 1e-9))
        side = int(math.ceil(math.sqrt(self.robots)))
        self.spacing = self.arena / (side + 1)
        if self.spacing < 0.1:
            raise ValueError(f"ssx.learn: {self.robots} e-pucks do not fit a {self.arena} m arena 10 cm apart")
        self.horizon_seconds, self.max_wheel_speed, self.start_jitter = horizon_seconds, max_wheel_speed, start_jitter
        self.cell_reward, self.bump_penalty, self.bump_reading = cell_reward, bump_penalty, bump_reading
        self.timestep = timestep
        self.readings = {}

    def scene(self):
        h, t = self.arena / 2, 0.02  # half the arena; the walls' thickness
        walls = "".join(
            f'<obstacle name="wall{k}" xyz="{x} {y} 0.05"><box size="{sx} {sy} 0.1"/></obstacle>'
            for k, (x, y, sx, sy) in enumerate([(h + t / 2, 0, t, self.arena + 2 * t), (-h - t / 2, 0, t, self.arena + 2 * t),
                                                (0, h + t / 2, self.arena, t), (0, -h - t / 2, self.arena, t)]))
        start = -h + self.spacing
        return f"""<scene>
  <environment timestep="{self.timestep}" seed="1"/>
  <type name="epuck" file="artifacts/epuck.xml"/>
  <ground/>
  {walls}
  <swarm type="epuck" count="{self.robots}" name="r{{i}}" layout="grid" spacing="{self.spacing}" xyz="{start} {start} 0"/>
</scene>"""

    def takeoff_commands(self, states, num_envs):
        return None  # nothing to take off: the robots stand where the scene puts them

    def bind(self, num_envs, action_period, states):
        self.num_envs = num_envs
        self.horizon = max(1, int(round(self.horizon_seconds / action_period)))
        self.covered = np.zeros((num_envs, self.cells + 2, self.cells + 2), dtype=bool)  # a border of walls
        self._border = np.ones_like(self.covered[0])
        self._border[1:-1, 1:-1] = False
        self.covered[:] = self._border
        self._commands = np.zeros((num_envs, self.robots, 2 if self.level == "wheels" else 4))
        self._states = states  # the environment's, read in place after every step (headings)
        self._offsets = np.array([(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)])

    def _cells(self, states):
        """(E, R, 2) each robot's cell, 1-based (0 and cells + 1 are the walls)."""
        ij = np.floor((states[..., 0:2] + self.arena / 2) / self.cell).astype(np.int64)
        return np.clip(ij, 0, self.cells - 1) + 1

    def draw(self, ids, rngs):
        u = np.array([rng.random((self.robots, 2)) for rng in rngs]) * 2.0 - 1.0
        offsets = np.zeros((len(ids), self.robots, 3))
        offsets[..., :2] = u * self.start_jitter
        self.covered[ids] = self._border
        return offsets, np.zeros_like(offsets)

    def observation_space(self, per_agent=False):
        return make_box(-1.5, 1.5, (21,) if per_agent else (self.robots, 21), np.float32)

    def action_space(self, per_agent=False):
        return make_box(-1.0, 1.0, (2,) if per_agent else (self.robots, 2), np.float32)

    def observe(self, states, imu, out):
        o = out.reshape(len(states), self.robots, 21)
        o[..., 0:2] = states[..., 0:2] / (self.arena / 2)
        w, x, y, z = (states[..., k] for k in range(3, 7))
        yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        o[..., 2], o[..., 3] = np.cos(yaw), np.sin(yaw)
        o[..., 4:12] = self.readings["proximity"]
        ij = self._cells(states)
        e = np.arange(len(states))[:, None, None]
        around = ij[:, :, None, :] + self._offsets  # (E, R, 9, 2)
        o[..., 12:21] = self.covered[e, around[..., 0], around[..., 1]]

    def commands(self, actions):
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(self.num_envs, self.robots, 2), -1.0, 1.0)
        c = self._commands[: a.shape[0]]
        if self.level == "wheels":
            np.multiply(a, self.max_wheel_speed, out=c)
            return c
        # velocity: a forward speed along each robot's heading now, and a yaw rate
        w, x, y, z = (self._states[: a.shape[0], :, k] for k in range(3, 7))
        yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        speed = a[..., 0] * self.max_speed
        c[..., 0], c[..., 1] = speed * np.cos(yaw), speed * np.sin(yaw)
        c[..., 3] = a[..., 1] * self.max_yaw_rate
        return c

    def evaluate(self, states, imu, actions):
        ij = self._cells(states)
        e = np.repeat(np.arange(len(states)), self.robots)
        flat_i, flat_j = ij[..., 0].ravel(), ij[..., 1].ravel()
        new = ~self.covered[e, flat_i, flat_j]
        # a cell two robots reach in one step goes to the first of them (robot order)
        key = (e * (self.cells + 2) + flat_i) * (self.cells + 2) + flat_j
        _, first = np.unique(key, return_index=True)
        firsts = np.zeros_like(new)
        firsts[first] = True
        new &= firsts
        self.covered[e, flat_i, flat_j] = True
        bumps = self.readings["proximity"].max(axis=-1) > self.bump_reading  # (E, R)
        reward = self.cell_reward * new.reshape(len(states), self.robots) - self.bump_penalty * bumps
        inside = self.covered[:, 1:-1, 1:-1]
        infos = {"coverage": inside.mean(axis=(1, 2)), "bumps": bumps.sum(axis=1), "agent_rewards": reward}
        return reward.sum(axis=1), np.zeros(len(states), dtype=bool), infos

    def agent_terminations(self, states):
        return np.zeros(states.shape[:2], dtype=bool)

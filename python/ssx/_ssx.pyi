"""Type stubs of the compiled module ssx._ssx (what an editor completes for `import ssx`).

tests/python/test_stubs.py checks that these name exactly what the module has."""
import os
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "os.PathLike[str]"]
_Rows = npt.ArrayLike
_Robots = Optional[Sequence[Union[str, int]]]

class Error(RuntimeError): ...
class ConfigError(Error): ...
class SceneError(Error): ...
class StepError(Error): ...
class StateError(Error): ...

class Contact(NamedTuple):
    """One pair touching in the last step (Environment.contact_list)."""
    artifact: str
    """A robot or item (a dynamic body's artifact)."""
    other: str
    """What it touched: another robot or item, or the static artifact (the ground, a wall)."""
    impulse: float
    """N s: the normal impulse over the step, summed over the pair's contact points."""
    position: npt.NDArray[np.float64]
    """m, world frame: the pair's deepest point."""
    normal: npt.NDArray[np.float64]
    """Unit, world frame: from other towards artifact."""
    static: bool
    """Whether other is static (the ground, walls, obstacles)."""

class Environment:
    """A loaded scene: step it, read its state as numpy arrays, command it (load_scene, load_scene_string)."""

    def step(self, n: int = 1) -> None:
        """Advances n timesteps (starting the environment first if needed); releases the GIL."""
    @property
    def time(self) -> float:
        """Simulated time, s."""
    @property
    def time_ns(self) -> int:
        """Simulated time, ns."""
    @property
    def timestep(self) -> float:
        """Physics timestep, s."""
    @property
    def step_count(self) -> int: ...
    @property
    def duration(self) -> Optional[float]:
        """<environment duration> in s, or None."""
    @property
    def seed(self) -> int: ...
    @property
    def threads(self) -> int:
        """Worker threads of the parallel phases (known once started)."""
    def artifact_names(self) -> List[str]:
        """Every artifact, in artifact order."""
    def dynamic_names(self) -> List[str]:
        """The artifacts with a dynamic root: the rows of positions() and the other state arrays."""
    def setpoint_names(self) -> List[str]:
        """The artifacts whose driver follows set-points: the rows of set_setpoints()."""
    def state_hash(self) -> int:
        """64-bit hash of every body's pose and velocities, bit for bit, and the time."""
    def body_names(self) -> List[str]:
        """Every moving body, as recordings and the viewer list them: each dynamic artifact's first root named as the artifact, then its other bodies as 'artifact/node' (static-rooted arms and doors too)."""
    def body_poses(self) -> npt.NDArray[np.float64]:
        """N x 7 poses of body_names() (x, y, z in m; qw, qx, qy, qz), world frame."""
    def positions(self) -> npt.NDArray[np.float64]:
        """N x 3 positions (m, world) of the dynamic artifacts' first roots."""
    def orientations(self) -> npt.NDArray[np.float64]:
        """N x 4 orientations as quaternions (w, x, y, z)."""
    def linear_velocities(self) -> npt.NDArray[np.float64]:
        """N x 3, m/s, world frame."""
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """N x 3, rad/s, world frame."""
    def set_setpoints(self, positions: _Rows, velocities: Optional[_Rows] = None, yaws: Optional[_Rows] = None,
                      accelerations: Optional[_Rows] = None, yaw_rates: Optional[_Rows] = None,
                      robots: _Robots = None) -> None:
        """One row per robot (setpoint_names(), or `robots`); held until the next call; every row checked first."""
    def set_commands(self, level: str, values: _Rows, robots: _Robots = None) -> None:
        """Commands at a level ('position', 'velocity', 'attitude', 'rates', 'rotors', 'wheels'), one row per robot."""
    def imu(self, artifact: str, sensor: Optional[int] = None) -> Dict[str, Any]:
        """The latest IMU measurement of an artifact, as a dict of numpy arrays."""
    def pose(self, artifact: str, sensor: Optional[int] = None) -> Dict[str, Any]:
        """The latest pose measurement of an artifact, as a dict."""
    def range(self, artifact: str, sensor: Optional[int] = None) -> Dict[str, Any]:
        """The latest range measurement of an artifact: detections as arrays, nearest first."""
    def flight_summary(self) -> Dict[str, Any]:
        """What happened to the robots so far: airborne, landed, on wheels, crashed, impacts, collisions, closest approach, distance flown."""
    def metrics(self) -> Dict[str, Dict[str, float]]:
        """Every metric the drivers and extensions publish now, as {artifact or extension: {metric: value}}."""
    def set_external_pose(self, artifact: str, position: _Rows, orientation: Optional[_Rows] = None,
                          stamp: Optional[float] = None) -> None:
        """A pose of ghost `artifact` (a real robot) measured at simulated time `stamp` (None: now); orientation (w, x, y, z)."""
    def ghost_status(self, artifact: str) -> Dict[str, Any]:
        """A ghost's status: lost, age (s) of its newest pose, samples kept."""
    def ghost_ages(self) -> Dict[str, float]:
        """The ages of the poses the ghosts were placed at, every step so far: count, median, p99, max (s)."""
    def operator_command(self, operator: str, velocity: _Rows, yaw_rate: float = 0.0) -> None:
        """Steers the robots of operator extension `operator` as one (m/s, rad/s in its frame); the dead-man rule stops them."""
    def operator_force(self, operator: str) -> npt.NDArray[np.float64]:
        """The force (N, world frame) operator `operator` should feel now, by its law."""
    def attach(self, holder: str, held: str) -> None:
        """Holds node `held` by node `holder` ('artifact' or 'artifact/node') with a fixed joint, as the two are now."""
    def release(self, holder: str) -> None:
        """Lets go of every body node `holder` holds."""
    def detach(self, node: str) -> None:
        """Frees node `node`'s body of every run-time joint on it, whoever made it."""
    def attachments(self, node: str) -> int:
        """How many run-time joints hold node `node`'s body or are held by it."""
    def joint_position(self, node: str) -> float:
        """The position (rad or m) of the joint joining node 'artifact/node' to its parent."""
    def joint_velocity(self, node: str) -> float:
        """That joint's velocity, rad/s or m/s."""
    def set_joint_velocity(self, node: str, velocity: float) -> None:
        """Drives that joint's motor toward a velocity, held until changed."""
    def set_joint_position(self, node: str, position: float) -> None:
        """Drives that joint's motor toward a position, held until changed."""
    def contacts(self) -> int:
        """Contact points the physics engine found in the last step."""
    def switch_physics(self, engine: str) -> None:
        """Continues the run on another physics engine ("ode", "bullet") from the next step: bodies, joints, attachments, ghosts and the robots' own state carry over, contacts are found again. Before the first step: the engine the run starts with. Raises for an unknown engine."""
    @property
    def physics_engine(self) -> str:
        """The physics engine stepping now."""
    @property
    def physics_switches(self) -> List[Tuple[float, str, str]]:
        """The switches of physics engine so far: (time s, from, to) each, in order."""
    def reseed(self, seed: int) -> None:
        """Restarts every random stream (sensor noise, wind gusts) as a scene loaded with this seed would start it."""
    def record_contacts(self, on: bool = True) -> None:
        """Keeps the contacts of every step from now on (off by default); contact_list() lists the last step's."""
    def read(self, kind: str, out: Optional[npt.NDArray[np.float64]] = None, slots: int = 0) -> npt.NDArray[np.float64]:
        """(robots, width): one kind of sensor of every robot (setpoint_names()), from its first sensor of the kind: pose, imu, proximity, ground, range, range_and_bearing or odometry (VectorEnvironment.read's layouts)."""
    def images(self, out: Optional[npt.NDArray[np.uint8]] = None) -> npt.NDArray[np.uint8]:
        """(robots, height, width, 3) uint8: every robot's latest camera image (setpoint_names()), RGB, rows from the top."""
    def contact_list(self) -> List[Contact]:
        """The last step's contacts, one per pair touching: Contact(artifact, other, impulse N s, position, normal, static); other names the static artifact (the ground, a wall) when static."""
    def variables(self, robot: str) -> List[Dict[str, Any]]:
        """The constants of a robot that vary() takes: dicts of name, neutral, min, max, doc."""
    def vary(self, robot: str, name: str, value: float) -> None:
        """Sets a constant of the robot from the next step on (domain randomisation); part of the saved state."""
    def variation(self, robot: str, name: str) -> float:
        """The value vary() set (the neutral one when never varied)."""
    def save_state(self) -> bytes:
        """Everything that determines the future."""
    def restore_state(self, state: bytes) -> None:
        """Continues from save_state() bytes: the next steps are bitwise those of the saving run."""
    def run(self, seconds: Optional[float] = None, realtime: bool = True, realtime_factor: Optional[float] = None,
            realtime_priority: Optional[int] = None, record: Optional[_Path] = None) -> Dict[str, Any]:
        """Runs `seconds` of simulated time, paced unless realtime=False; returns the timing summary.
        record=FILE records the run (summary under 'recording')."""
    def record(self, file: _Path, rate_hz: float = 25.0, state_every_s: float = 10.0,
               drop_when_behind: bool = False, foxglove: Optional[bool] = None, timing: bool = False,
               sensors: bool = False, commands: bool = False) -> None:
        """Records from the next step on into an MCAP file (read back with Recording); foxglove adds /tf and
        /scene (None: for up to 1,000 bodies), timing /ssx/timing, sensors /ssx/sensors, commands /ssx/commands."""
    def stop_recording(self) -> Dict[str, Any]:
        """Ends the recording; returns samples, dropped, states, bodies, bytes and a line of text."""
    @property
    def recording(self) -> bool:
        """Whether a recording is running."""
    def view(self, port: int = 8765, bind: str = "127.0.0.1", rate_hz: float = 30.0, max_clients: int = 4) -> str:
        """Serves a live 3D view to web browsers (as ssx run --view); returns its URL. Attaches to the run as it is
        (before the first step: starts the environment); changes nothing in the run."""
    def stop_view(self) -> None:
        """Takes the live view off the run; view() can attach one again."""
    def attach_renderer(self, *, snapshot: Optional[_Path] = None, video: Optional[_Path] = None,
                        frames: Optional[_Path] = None, rate_hz: Optional[float] = None, width: Optional[int] = None,
                        height: Optional[int] = None, engine: Optional[str] = None) -> None:
        """Draws the scene cameras' frames from the next step on (a camera framing the scene when it has none) into
        a PNG snapshot, an MP4 video and/or a directory of PNG frames; changes nothing in the run."""
    def detach_renderer(self) -> None:
        """Stops drawing frames: the outputs finished (a video closed, the snapshot written)."""
    @property
    def frame_count(self) -> int:
        """Frames drawn for the scene's cameras so far."""
    def close(self) -> None:
        """Stops the environment: a recording finished, plugins destroyed, files and videos finished."""
    def __enter__(self) -> "Environment": ...
    def __exit__(self, *args: Any) -> None: ...

class Recording:
    """A recording read back: names, times, every body's poses as numpy arrays, the scene, saved states."""

    def __init__(self, file: _Path) -> None:
        """Reads a recording; RuntimeError naming the file and the byte offset when it is not one."""
    @property
    def names(self) -> List[str]:
        """The recorded bodies, in the order of the arrays' rows."""
    @property
    def times(self) -> npt.NDArray[np.float64]:
        """Sample times, s."""
    def positions(self) -> npt.NDArray[np.float32]:
        """Every sample's positions: times x bodies x 3."""
    def orientations(self) -> npt.NDArray[np.float32]:
        """Every sample's orientations: times x bodies x 4 (w, x, y, z)."""
    def at(self, t: float) -> Any:
        """The sample at or before t: (time, positions bodies x 3, orientations bodies x 4)."""
    @property
    def scene_xml(self) -> str:
        """The recorded scene as scene XML."""
    @property
    def scene(self) -> str:
        """The scene's file name when it was recorded."""
    @property
    def version(self) -> str:
        """The ssx version that recorded it."""
    @property
    def seed(self) -> int:
        """The recorded run's seed."""
    @property
    def complete(self) -> bool:
        """False for a file cut short (a killed run)."""
    @property
    def size(self) -> int:
        """Bytes in the file."""
    @property
    def physics_switches(self) -> List[Tuple[float, str, str]]:
        """The switches of physics engine made while recording: (time s, from, to) each, in order."""
    @property
    def state_times(self) -> List[float]:
        """Times of the saved states, s."""
    def channel(self, name: str) -> List[Any]:
        """The messages of a channel as (time in s, message): JSON channels decoded, others as bytes."""
    def snapshot(self, t: float, plugin_path: Sequence[_Path] = ...) -> Any:
        """The state at t: (t, bytes for Environment.restore_state); between saved states, re-simulated from the one before."""
    def channels(self) -> Dict[str, int]:
        """Every channel's topic and message count."""
    def __len__(self) -> int: ...

class VectorEnvironment:
    """num_envs copies of one scene, each a world of its own, stepped together on a pool of threads
    (the GIL released): the core of ssx.learn.VectorEnv (C++: ssx::VectorEnvironment)."""

    def __init__(self, xml: str, num_envs: int, base_dir: _Path = ..., seed: Optional[int] = None,
                 threads: Optional[int] = None, label: str = "<string>", plugin_path: Sequence[_Path] = ...,
                 physics: Optional[str] = None) -> None:
        """Reads the scene once and builds num_envs copies of it, each on one thread, started."""
    @property
    def num_envs(self) -> int:
        """How many copies."""
    @property
    def robot_names(self) -> List[str]:
        """The robots of every copy (drivers that take set-points), in artifact order."""
    @property
    def timestep(self) -> float:
        """Physics timestep, s."""
    @property
    def threads(self) -> int:
        """Threads stepping the copies."""
    def step(self, n: int = 1, active: Optional[npt.ArrayLike] = None, level: Optional[str] = None,
             commands: Optional[npt.ArrayLike] = None, states: Optional[npt.NDArray[np.float64]] = None,
             imu: Optional[npt.NDArray[np.float64]] = None) -> None:
        """Steps every copy n times (or only those flagged in active, one flag per copy); with commands= (and
        level=), states= and imu=, a learning step in one pass over each copy (rows of copies not active not sent)."""
    def check_commands(self, level: str, values: npt.ArrayLike) -> None:
        """Checks commands as set_commands does, sending none."""
    def robot_states(self, out: Optional[npt.NDArray[np.float64]] = None) -> npt.NDArray[np.float64]:
        """(num_envs, robots, 13): x y z, qw qx qy qz, vx vy vz, wx wy wz (world frame), into out= when given."""
    def imu(self, out: Optional[npt.NDArray[np.float64]] = None) -> npt.NDArray[np.float64]:
        """(num_envs, robots, 6): each robot's first IMU, accelerometer (m/s^2) then gyroscope (rad/s)."""
    def set_commands(self, level: str, values: npt.ArrayLike) -> None:
        """One command level for every robot of every copy: values (num_envs, robots, columns), checked whole."""
    def save_state(self, index: int = 0) -> bytes:
        """Copy index's state."""
    def reset(self, indices: Sequence[int], state: bytes, seeds: Sequence[int]) -> None:
        """Restores the copies named to state and reseeds their random streams, one seed each."""
    def move_robots(self, indices: Sequence[int], offsets: npt.ArrayLike, velocities: Optional[npt.ArrayLike] = None) -> None:
        """Moves every robot of the copies named by offsets (len(indices), robots, 3), at velocities (or at rest)."""
    def read(self, kind: str, out: Optional[npt.NDArray[np.float64]] = None, slots: int = 0) -> npt.NDArray[np.float64]:
        """(num_envs, robots, width): one kind of sensor of every robot (pose, imu, proximity, ground, range, range_and_bearing, odometry)."""
    def record_contacts(self, on: bool = True) -> None:
        """Every copy keeps the contacts of its steps from now on (off by default)."""
    def images(self, out: Optional[npt.NDArray[np.uint8]] = None) -> npt.NDArray[np.uint8]:
        """Every robot's latest camera image, (num_envs, robots, height, width, 3) uint8 RGB, rows from the top, from its first camera sensor (into out when given)."""
    def set_command_delays(self, indices: Sequence[int], steps: npt.ArrayLike) -> None:
        """Actuation latency: robot r of environment indices[k] takes each later set_commands steps[k, r] physics steps into the steps that follow (0: at once), holding the one before until then. Not in saved states; reset drops the commands waiting."""
    def contact_list(self, index: int) -> List[Contact]:
        """Copy index's last-step contacts: Contact(artifact, other, impulse N s, position, normal, static)."""
    def contact_impulses(self, out: Optional[npt.NDArray[np.float64]] = None) -> npt.NDArray[np.float64]:
        """(num_envs, robots, 2): each robot's normal impulse (N s) in the last step from the static world and from other bodies."""
    def variables(self, robot: int = 0) -> List[Dict[str, Any]]:
        """What vary takes for robot index robot: dicts of name, neutral, min, max, doc."""
    def vary(self, indices: Sequence[int], name: str, values: npt.ArrayLike) -> None:
        """Sets constant name of every robot of the copies named to values (len(indices), robots), checked whole first."""
    def state_hashes(self) -> npt.NDArray[np.uint64]:
        """Each copy's state hash."""
    def times(self) -> npt.NDArray[np.float64]:
        """Each copy's simulated time, s."""
    def close(self) -> None:
        """Stops and frees every copy."""

def load_scene(path: _Path, seed: Optional[int] = None, threads: Optional[int] = None,
               plugin_path: Sequence[_Path] = ..., physics: Optional[str] = None) -> Environment:
    """Loads a scene file; raises SceneError (every file:line: error: line) before anything starts."""
def load_scene_string(xml: str, base_dir: _Path = ..., seed: Optional[int] = None, threads: Optional[int] = None,
                      label: str = "<string>", plugin_path: Sequence[_Path] = ...,
                      physics: Optional[str] = None) -> Environment:
    """Loads a scene from text; relative files resolve against base_dir, messages name `label`."""
def physics_engines() -> List[str]:
    """The physics engines of this build ("ode", "bullet")."""
def data_directory() -> "os.PathLike[str]":
    """Where the installed artifact types (artifacts/) and example scenes (scenes/) are."""

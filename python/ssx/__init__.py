"""ssx: real-time simulation of robot swarms in 3D, from Python.

    import ssx
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "formation_sphere.xml", seed=1)
    env.step(100)
    p = env.positions()          # N x 3 numpy array, one row per env.dynamic_names()

The simulation runs in libssx (C++); stepping releases the GIL. See docs/python.md.
"""
from ._ssx import (
    ConfigError,
    Contact,
    Environment,
    Error,
    Recording,
    SceneError,
    StateError,
    StepError,
    __version__,
    data_directory,
    load_scene,
    load_scene_string,
    physics_engines,
)

__all__ = [
    "ConfigError",
    "Contact",
    "Environment",
    "Error",
    "Recording",
    "SceneError",
    "StateError",
    "StepError",
    "__version__",
    "data_directory",
    "load_scene",
    "load_scene_string",
    "physics_engines",
]

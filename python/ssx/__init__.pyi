from ._ssx import (
    ConfigError as ConfigError,
    Contact as Contact,
    Environment as Environment,
    Error as Error,
    SceneError as SceneError,
    StateError as StateError,
    StepError as StepError,
    __version__ as __version__,
    data_directory as data_directory,
    load_scene as load_scene,
    load_scene_string as load_scene_string,
    physics_engines as physics_engines,
)

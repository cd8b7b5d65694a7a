"""roslaunch.config: ROSLaunchConfig and loading launch files into one (minros.launch.rosmodel)."""

from minros.launch.rosmodel import (  # noqa: F401
    ROSLaunchConfig,
    _summary_name,
    calculate_env_loader,
    get_roscore_filename,
    load_config_default,
    load_roscore,
    namespaces_of,
)
from roslaunch.core import Master, RLException, is_machine_local, local_machine  # noqa: E402, F401

DEFAULT_MASTER_PORT = 11311

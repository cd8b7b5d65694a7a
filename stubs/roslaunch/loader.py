"""roslaunch.loader: what launch loading shares (minros.launch.rosmodel, substitution)."""

from minros.launch.rosmodel import LoadException  # noqa: F401
from minros.launch.substitution import convert_value  # noqa: F401

"""resource_retriever stand-in (see minros.resource_retriever)."""

from minros.resource_retriever import *  # noqa: F401,F403
from minros.resource_retriever import __all__ as __all__  # noqa: PLC0414


def __getattr__(name: str):
    if name == "r":  # ROS's module keeps a rospkg.RosPack: one over minros's package roots
        from minros import packages

        globals()["r"] = packages.rospack()
        return globals()["r"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

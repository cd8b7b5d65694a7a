"""nodelet stand-in: the srv package, and minros's Python nodelet API (Nodelet, Loader) on
first use (minros.nodelet imports nodelet.srv, so it is not imported here)."""

from typing import Any


def __getattr__(name: str) -> Any:
    if name in ("Nodelet", "Loader", "LoaderROS"):
        import minros.nodelet

        return getattr(minros.nodelet, name)
    raise AttributeError(f"module 'nodelet' has no attribute {name!r}")

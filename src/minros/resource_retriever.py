"""resource_retriever: read ``package://pkg/path``, ``file://`` (and other URLs urllib
opens) as ROS's Python resource_retriever does, with minros's package lookup
(ROS_PACKAGE_PATH, then the packages minros bundles)."""

from __future__ import annotations

from urllib.error import URLError
from urllib.request import urlopen

from minros import packages

__all__ = ["PACKAGE_PREFIX", "get_filename", "get", "ResourceRetrieverError"]

PACKAGE_PREFIX = "package://"


class ResourceRetrieverError(Exception):
    """A URL that names no readable resource (an Exception, as ROS raises)."""


def get_filename(url: str, use_protocol: bool = True) -> str:
    """``package://pkg/rest`` as ``file:///path/of/pkg/rest`` (without ``file://`` when
    ``use_protocol`` is False); other URLs unchanged."""
    if not url.startswith(PACKAGE_PREFIX):
        return url
    rest = url[len(PACKAGE_PREFIX):]
    package, slash, path = rest.partition("/")
    if not slash:
        raise ResourceRetrieverError(
            f"Could not parse package:// format into file:// format for {url}")
    package_dir = packages.find_package(package)
    if package_dir is None:
        raise ResourceRetrieverError(
            f"package '{package}' not found (for {url}): is it on ROS_PACKAGE_PATH?")
    return ("file://" if use_protocol else "") + str(package_dir) + "/" + path


def get(url: str) -> bytes:
    """The bytes ``url`` names."""
    filename = get_filename(url)
    try:
        with urlopen(filename) as response:  # noqa: S310 - any URL the user names, as ROS
            return response.read()
    except (URLError, ValueError, OSError) as exc:
        raise ResourceRetrieverError(f"Invalid URL: {filename} ({exc})") from None

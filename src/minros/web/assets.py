"""Files of ROS packages served to browsers: robot meshes and textures, by ``package://`` URL.

Two clients read them: the page's 3D view (``GET /pkg/<package>/<path>``, the URL of
``package://<package>/<path>``) and Foxglove clients (the ``assets`` capability's
``fetchAsset``, as foxglove_bridge serves it to Lichtblick's 3D panel). Both go through
:func:`resolve`, which applies foxglove_bridge's rules and two more:

* the URI must match one of the allow-list's regular expressions as a whole (foxglove_bridge's
  ``~asset_uri_allowlist``, ``std::regex_match``; ASCII ``\\w``) and must not hold ``..``;
* the default list is foxglove_bridge's (``package://`` URLs of meshes, textures and robot
  descriptions), its extensions taken in any case (``.STL`` is what CAD exporters write), plus
  the same for ``file://`` URLs;
* the file must lie inside the folder of a package minros's package lookup finds
  (``ROS_PACKAGE_PATH``, then the bundled packages), after percent-decoding and after
  symbolic links are followed: ``%2e%2e`` and a link out of the package are refused too;
* at most :data:`MAX_ASSET_BYTES` are served.

Files are sent as they are read, :data:`CHUNK_BYTES` at a time (:func:`chunks`), never held
whole: each connection holds one chunk, and a :class:`Budget` bounds the chunks in memory
across all connections (:data:`BUDGET_BYTES`, of which one peer address may hold
``peer_share``, as :mod:`minros.wire.admission` shares a server's memory): a reader waits for
room, and one that finds none within the server's send timeout is refused. So thirty
unread downloads of a 46 MB mesh hold thirty chunks, not thirty meshes, and nothing after
they close.

Errors are :class:`AssetError` with the reason and, where there is one, the fix.
"""

from __future__ import annotations

import os
import re
import threading
import time
import urllib.parse
from pathlib import Path
from typing import (
    BinaryIO,
    Callable,
    Dict,
    Iterable,
    Iterator,
    List,
    Optional,
    Pattern,
    Sequence,
    Tuple,
)

from minros import packages

#: the file types of meshes, their textures and robot descriptions (foxglove_bridge's list)
ASSET_EXTENSIONS = "dae|fbx|glb|gltf|jpeg|jpg|mtl|obj|png|stl|tif|tiff|urdf|webp|xacro"
DEFAULT_ALLOWLIST = (
    r"^package://(?:[-\w%]+/)*[-\w%.]+\.(?i:" + ASSET_EXTENSIONS + r")$",
    r"^file:///(?:[-\w%.]+/)*[-\w%.]+\.(?i:" + ASSET_EXTENSIONS + r")$",
)
#: the largest file served (a detailed mesh is tens of MB; a Foxglove client's replies wait
#: in a queue of 64 MB)
MAX_ASSET_BYTES = 48 << 20

#: bytes read from a file at a time (and held, per connection, until the kernel has them)
CHUNK_BYTES = 64 << 10
#: chunks of asset files in memory at once, all connections together (512 connections, the
#: web server's cap, at one chunk each)
BUDGET_BYTES = 32 << 20
#: the fraction of the budget one peer address may hold (admission's default share)
PEER_SHARE = 0.75

PACKAGE_PREFIX = "package://"
FILE_PREFIX = "file://"


class AssetError(Exception):
    """A URI that is not served; ``status`` is the HTTP status that says why."""

    def __init__(self, text: str, status: int = 403) -> None:
        super().__init__(text)
        self.status = status


def compile_allowlist(patterns: Iterable[str]) -> List[Pattern[str]]:
    """The allow-list's expressions compiled; ValueError naming the one that does not parse."""
    compiled = []
    for pattern in patterns:
        try:
            compiled.append(re.compile(str(pattern), re.ASCII))
        except re.error as exc:
            raise ValueError(f"asset_uri_allowlist: {pattern!r} is not a regular expression "
                             f"({exc})") from None
    return compiled


DEFAULT_PATTERNS = compile_allowlist(DEFAULT_ALLOWLIST)


def allowed(uri: str, patterns: Sequence[Pattern[str]] = DEFAULT_PATTERNS) -> bool:
    """foxglove_bridge's test: no ``..`` anywhere, and one expression matching the whole URI."""
    return ".." not in uri and any(p.fullmatch(uri) for p in patterns)


def resolve(uri: str, patterns: Sequence[Pattern[str]] = DEFAULT_PATTERNS,
            find_package: Callable[[str], Optional[Path]] = packages.find_package,
            package_dirs: Optional[Callable[[], Iterable[Path]]] = None) -> Path:
    """The file ``uri`` names, checked (see the module doc); AssetError otherwise."""
    if ".." in uri:
        raise AssetError(f"{uri}: '..' is not allowed in an asset URI (it could climb out of "
                         "the package)")
    if not any(p.fullmatch(uri) for p in patterns):
        raise AssetError(f"{uri} is not on the asset allow-list (package:// or file:// URLs of "
                         f"meshes and textures: {ASSET_EXTENSIONS.replace('|', ', ')}); "
                         "minros web's ~asset_uri_allowlist parameter sets the list")
    if uri.startswith(PACKAGE_PREFIX):
        package, slash, rest = uri[len(PACKAGE_PREFIX):].partition("/")
        package = urllib.parse.unquote(package)
        folder = find_package(package) if slash and package else None
        if folder is None:
            raise AssetError(f"{uri}: package '{package}' not found: is it on ROS_PACKAGE_PATH?",
                             404)
        roots = [folder]
        target = Path(folder) / _relative(urllib.parse.unquote(rest), uri)
    elif uri.startswith(FILE_PREFIX):
        path = urllib.parse.unquote(urllib.parse.urlsplit(uri).path)
        if not path.startswith("/"):
            raise AssetError(f"{uri}: a file:// URL needs an absolute path (file:///...)")
        _relative(path.lstrip("/"), uri)
        roots = list(package_dirs() if package_dirs else packages.list_packages().values())
        target = Path(path)
    else:
        raise AssetError(f"{uri}: only package:// and file:// URLs are served")
    try:
        real = target.resolve()
        inside = any(_within(real, Path(root).resolve()) for root in roots)
        is_file = real.is_file()
    except (OSError, ValueError, RuntimeError):  # a name too long, a symlink loop
        inside, is_file = False, False
    if not inside:
        raise AssetError(f"{uri} is not inside a ROS package's folder: only files of the "
                         "packages on ROS_PACKAGE_PATH (and minros's own) are served")
    if not is_file:
        raise AssetError(f"{uri}: no such file ({target})", 404)
    return real


class Budget:
    """Bytes of asset files in memory (read, not yet handed to the kernel), all connections
    together and per peer address. Thread-safe; ``report`` gets one line when readers first
    have to wait, then at most one a minute."""

    def __init__(self, total: int = BUDGET_BYTES, peer_share: float = PEER_SHARE,
                 report: Optional[Callable[[str], None]] = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.total = max(CHUNK_BYTES, total)
        self.peer_limit = max(CHUNK_BYTES, int(self.total * peer_share))
        self.used = 0
        self.by_peer: Dict[str, int] = {}
        self.waiting = 0
        self._cond = threading.Condition(threading.Lock())
        self._report = report
        self._reported = -float("inf")
        self._clock = clock

    def _fits(self, peer: str, n: int) -> bool:
        return (self.used + n <= self.total
                and self.by_peer.get(peer, 0) + n <= self.peer_limit)

    def acquire(self, peer: str, n: int, timeout: float) -> bool:
        """Take ``n`` bytes for ``peer``, waiting up to ``timeout`` seconds for room; False
        when there was none."""
        deadline = self._clock() + timeout
        with self._cond:
            if not self._fits(peer, n):
                self.waiting += 1
                try:
                    self._note_full(peer)
                    while not self._fits(peer, n):
                        left = deadline - self._clock()
                        if left <= 0:
                            return False
                        self._cond.wait(left)
                finally:
                    self.waiting -= 1
            self.used += n
            self.by_peer[peer] = self.by_peer.get(peer, 0) + n
            return True

    def release(self, peer: str, n: int) -> None:
        with self._cond:
            self.used -= n
            left = self.by_peer.get(peer, 0) - n
            if left > 0:
                self.by_peer[peer] = left
            else:
                self.by_peer.pop(peer, None)
            self._cond.notify_all()

    def _note_full(self, peer: str) -> None:
        now = self._clock()
        if self._report is None or now - self._reported < 60.0:
            return
        self._reported = now
        whose = (f"{peer} holds its share, {self.peer_limit >> 20} MB"
                 if self.by_peer.get(peer, 0) >= self.peer_limit - CHUNK_BYTES
                 else f"all {self.total >> 20} MB are taken")
        self._report(f"package files in memory are at their bound ({whose}): downloads wait "
                     "for room (clients that do not read theirs are closed after the send "
                     "timeout)")


def open_file(path: Path, uri: str, max_bytes: int = MAX_ASSET_BYTES) -> Tuple[BinaryIO, int]:
    """The open file and its size, checked against ``max_bytes``; AssetError otherwise."""
    try:
        stream = open(path, "rb")
    except OSError as exc:
        raise AssetError(f"{uri}: cannot read {path}: {exc.strerror or exc}", 404) from None
    try:
        size = os.fstat(stream.fileno()).st_size
    except OSError as exc:
        stream.close()
        raise AssetError(f"{uri}: cannot read {path}: {exc.strerror or exc}", 404) from None
    if size > max_bytes:
        stream.close()
        raise AssetError(f"{uri} is {size} bytes, more than the {max_bytes} served", 413)
    return stream, size


def chunks(stream: BinaryIO, size: int, budget: Budget, peer: str, timeout: float,
           chunk: int = CHUNK_BYTES) -> Iterator[memoryview]:
    """The file's first ``size`` bytes, ``chunk`` at a time, each taken from ``budget`` for
    ``peer`` and given back when the next is asked for (the caller has sent it by then: the
    view is of one buffer, reused). AssetError (503) when no room is found in ``timeout``
    seconds; a file that shrank ends early."""
    buffer = bytearray(min(chunk, max(1, size)))
    view = memoryview(buffer)
    left = size
    while left > 0:
        n = min(len(buffer), left)
        if not budget.acquire(peer, n, timeout):
            raise AssetError(f"no room for package files in memory for {timeout:.0f} s "
                             f"({budget.total >> 20} MB, shared by every download): "
                             "try again", 503)
        try:
            got = stream.readinto(view[:n])
            if not got:
                return
            yield view[:got]
        finally:
            budget.release(peer, n)
        left -= got


class Fragments:
    """One WebSocket message made of fragments produced while it is sent (the writer sends
    each before it asks for the next, so the message is never whole in memory)."""

    def __init__(self, make: Callable[[], Iterator[bytes]]) -> None:
        self.make = make

    def __iter__(self) -> Iterator[bytes]:
        return self.make()


def read(uri: str, patterns: Sequence[Pattern[str]] = DEFAULT_PATTERNS,
         find_package: Callable[[str], Optional[Path]] = packages.find_package,
         max_bytes: int = MAX_ASSET_BYTES) -> bytes:
    """The bytes of the file ``uri`` names (see :func:`resolve`)."""
    path = resolve(uri, patterns, find_package)
    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise AssetError(f"{uri} is {size} bytes, more than the {max_bytes} served", 413)
        with open(path, "rb") as stream:
            return stream.read(max_bytes)
    except OSError as exc:
        raise AssetError(f"{uri}: cannot read {path}: {exc.strerror or exc}", 404) from None


def page_url(uri: str, find_package: Callable[[str], Optional[Path]] = packages.find_package
             ) -> Tuple[Optional[str], Optional[str]]:
    """``(url, problem)``: the page's URL of a mesh or texture URI (``/pkg/<package>/<path>``
    for package:// and for file:// inside a package; http(s) as it is), or None and why not."""
    if uri.startswith(PACKAGE_PREFIX):
        rest = uri[len(PACKAGE_PREFIX):]
        package = rest.partition("/")[0]
        if find_package(urllib.parse.unquote(package)) is None:
            return None, f"package '{package}' not found (for {uri}): is it on ROS_PACKAGE_PATH?"
        return "/pkg/" + rest, None
    if uri.startswith(FILE_PREFIX):
        path = Path(urllib.parse.unquote(urllib.parse.urlsplit(uri).path))
        for name, folder in packages.list_packages().items():
            try:
                relative = path.resolve().relative_to(Path(folder).resolve())
            except (ValueError, OSError):
                continue
            return "/pkg/" + urllib.parse.quote(name) + "/" + urllib.parse.quote(relative.as_posix()), None
        return None, (f"{uri} is not inside a ROS package: the page loads meshes from "
                      "packages only (use a package:// URL)")
    if uri.startswith(("http://", "https://")):
        return uri, None
    return None, f"{uri!r} is not a package://, file:// or http(s):// URL"


def _relative(path: str, uri: str) -> str:
    """``path`` (percent-decoded) if none of its parts climbs up; AssetError otherwise."""
    if any(part == ".." for part in path.replace("\\", "/").split("/")) or "\x00" in path:
        raise AssetError(f"{uri}: '..' is not allowed in an asset URI (it could climb out of "
                         "the package)")
    return path.lstrip("/")


def _within(path: Path, root: Path) -> bool:
    return path == root or root in path.parents

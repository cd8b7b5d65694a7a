"""rosbag2 recordings on disk: which paths are one, opening them, and what is wrong when they break.

A rosbag2 recording is a directory with ``metadata.yaml`` and its storage files (``.mcap`` or
``.db3``), or one storage file on its own. rosbags (Ternaris) reads the storage files: its
MCAP and SQLite readers keep to rosbag2's layouts of every version, read the index of an MCAP
file (or scan one without), and decompress zstd. minros checks the metadata and each file
first, so that a damaged recording is reported in one line naming the file and the damage,
which rosbags' own exceptions (several lines of YAML parser context, or a bare "File end magic
is invalid.") do not do.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from typing import Any, Dict, Iterator, List, Optional, Tuple

from minros.bag.errors import ROSBagFormatException

MCAP_MAGIC = b"\x89MCAP0\r\n"
SQLITE_MAGIC = b"SQLite format 3\x00"
METADATA = "metadata.yaml"
STORAGES = ("mcap", "sqlite3")
#: the newest metadata version minros reads (rosbag2 Jazzy and Kilted write 9)
NEWEST_VERSION = 9


class Rosbag2Error(ROSBagFormatException):
    """A rosbag2 recording that cannot be read; the message names the file and what is wrong."""


def _head(path: str, size: int = 64) -> bytes:
    try:
        with open(path, "rb") as f:
            return f.read(size)
    except OSError:
        return b""


def mcap_profile(head: bytes) -> Optional[str]:
    """The profile of the MCAP header record at the start of ``head`` (None if not MCAP)."""
    if not head.startswith(MCAP_MAGIC) or len(head) < 21 or head[8] != 0x01:
        return None
    (length,) = struct.unpack_from("<I", head, 17)
    return head[21:21 + length].decode("utf-8", "replace")


def kind(path: str) -> Optional[str]:
    """``"dir"``, ``"mcap"`` or ``"db3"`` when ``path`` is a rosbag2 recording (a directory, a
    ROS 2 MCAP file, a rosbag2 SQLite file), else None (a ROS 1 bag or MCAP, or nothing)."""
    if os.path.isdir(path):
        return "dir"
    head = _head(path)
    if head.startswith(SQLITE_MAGIC):
        return "db3"
    if mcap_profile(head) == "ros2":
        return "mcap"
    return None


def _show(path: Path) -> str:
    return os.fspath(path)


class Rosbag2:
    """An opened rosbag2 recording: its topics (rosbags ``Connection`` objects), the metadata,
    and its messages as (connection, time ns, CDR bytes)."""

    def __init__(self, path: str) -> None:
        from rosbags.rosbag2.reader import DirectoryReader

        self.path = Path(path)
        self.kind = kind(path)
        #: rosbag2_bagfile_information of metadata.yaml (None for a storage file on its own)
        self.metadata: Optional[Dict[str, Any]] = None
        self.files: List[Path] = []
        self._reader: Any = None
        if self.kind == "dir":
            self.metadata = self._read_metadata()
            self.files = [self.path / Path(p).name for p in self.metadata["relative_file_paths"]]
            storage = self.metadata["storage_identifier"]
            compressed = (self.metadata.get("compression_mode") or "").lower() == "file"
            for f in self.files:
                if not f.exists():
                    raise Rosbag2Error(f"{_show(f)} is missing ({_show(self.path / METADATA)} "
                                       f"lists it as one of the recording's files)")
                if not compressed:
                    self._check_file(f, "mcap" if storage == "mcap" else "db3")
            self._reader = DirectoryReader(self.path)
        elif self.kind in ("mcap", "db3"):
            self.files = [self.path]
            self._check_file(self.path, self.kind)
            from rosbags.rosbag2.storage_mcap import McapReader
            from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader

            self._reader = (McapReader if self.kind == "mcap" else Sqlite3Reader)(self.path)
        else:
            raise Rosbag2Error(f"{path} is not a rosbag2 recording (a directory with "
                               f"{METADATA}, a ROS 2 .mcap or a .db3 file)")
        try:
            self._reader.open()
        except Exception as exc:  # noqa: BLE001 - whatever rosbags or SQLite say of a damaged file
            raise Rosbag2Error(self._damage(exc)) from None
        self.connections: List[Any] = list(self._reader.connections)
        meta = self._reader.metadata
        self.message_count: int = meta.message_count
        #: (first, last) message time in ns, None when there are none
        self.time_range: Optional[Tuple[int, int]] = \
            (meta.start_time, meta.end_time - 1) if meta.message_count else None
        self.ros_distro: Optional[str] = meta.ros_distro if self.metadata is not None else None
        self.custom_data: Dict[str, str] = dict(meta.custom or {}) \
            if self.metadata is not None else {}
        self.version: Optional[int] = self.metadata["version"] if self.metadata else None
        self.storage_id = self.metadata["storage_identifier"] if self.metadata else \
            ("mcap" if self.kind == "mcap" else "sqlite3")

    @property
    def size(self) -> int:
        """Bytes on disk (the storage files and the metadata)."""
        paths = self.files + ([self.path / METADATA] if self.kind == "dir" else [])
        return sum(p.stat().st_size for p in paths if p.exists())

    # -- checks ----------------------------------------------------------------------------------

    def _read_metadata(self) -> Dict[str, Any]:
        import yaml

        meta_path = self.path / METADATA
        where = _show(meta_path)
        if not meta_path.exists():
            found = sorted(p.name for p in self.path.iterdir()
                           if p.suffix in (".mcap", ".db3")) if self.path.is_dir() else []
            hint = (f": read its storage file on its own instead (rosbag info "
                    f"{_show(self.path / found[0])})") if found else ""
            raise Rosbag2Error(f"{where} is missing: {_show(self.path)} is not a rosbag2 "
                               f"recording, or its recorder did not finish{hint}")
        try:
            text = meta_path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise Rosbag2Error(f"cannot read {where}: {getattr(exc, 'strerror', None) or exc}") \
                from None
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
            at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
            raise Rosbag2Error(f"{where} is not valid YAML ({problem}{at})") from None
        info = data.get("rosbag2_bagfile_information") if isinstance(data, dict) else None
        if not isinstance(info, dict):
            raise Rosbag2Error(f"{where} is not rosbag2 metadata (it has no "
                               f"rosbag2_bagfile_information mapping)")

        def need(mapping: Any, key: str, kinds: Any, path: str) -> Any:
            value = mapping.get(key) if isinstance(mapping, dict) else None
            if value is None:
                raise Rosbag2Error(f"{where}: {path}{key} is missing")
            if not isinstance(value, kinds) or isinstance(value, bool):
                raise Rosbag2Error(f"{where}: {path}{key} is {value!r}, not "
                                   f"{'a list' if kinds is list else 'a number' if kinds is int else 'a ' + kinds.__name__}")
            return value

        top = "rosbag2_bagfile_information."
        version = need(info, "version", int, top)
        if version > NEWEST_VERSION:
            raise Rosbag2Error(f"{where}: metadata version {version} is newer than minros "
                               f"reads (up to {NEWEST_VERSION})")
        storage = need(info, "storage_identifier", str, top)
        if storage not in STORAGES:
            raise Rosbag2Error(f"{where}: storage {storage!r} is not one minros reads "
                               f"({', '.join(STORAGES)})")
        need(info, "relative_file_paths", list, top)
        need(info, "message_count", int, top)
        need(need(info, "duration", dict, top), "nanoseconds", int, top + "duration.")
        need(need(info, "starting_time", dict, top), "nanoseconds_since_epoch", int,
             top + "starting_time.")
        for i, entry in enumerate(need(info, "topics_with_message_count", list, top)):
            at = f"{top}topics_with_message_count[{i}]."
            topic = need(entry, "topic_metadata", dict, at)
            for key in ("name", "type", "serialization_format"):
                need(topic, key, str, at + "topic_metadata.")
            need(entry, "message_count", int, at)
            if topic["serialization_format"] != "cdr":
                raise Rosbag2Error(f"{where}: topic {topic['name']} is stored as "
                                   f"{topic['serialization_format']!r}, not CDR")
        mode = (info.get("compression_mode") or "").lower()
        if mode not in ("", "none") and (info.get("compression_format") or "") != "zstd":
            raise Rosbag2Error(f"{where}: compression {info.get('compression_format')!r} is not "
                               f"one minros reads (zstd)")
        return info

    def _check_file(self, path: Path, kind_: str) -> None:
        try:
            size = path.stat().st_size
            with open(path, "rb") as f:
                head = f.read(32)
                f.seek(max(size - 8, 0))
                tail = f.read(8)
        except OSError as exc:
            raise Rosbag2Error(f"cannot read {_show(path)}: {exc.strerror or exc}") from None
        if size == 0:
            raise Rosbag2Error(f"{_show(path)} is empty")
        if kind_ == "db3":
            if not head.startswith(SQLITE_MAGIC):
                raise Rosbag2Error(f"{_show(path)} is not an SQLite database (a rosbag2 .db3 "
                                   f"file starts with {SQLITE_MAGIC[:-1].decode()!r})")
            return
        if not head.startswith(MCAP_MAGIC):
            raise Rosbag2Error(f"{_show(path)} is not an MCAP file (it does not start with "
                               f"MCAP's magic bytes)")
        profile = mcap_profile(head)
        if profile not in (None, "ros2", ""):
            raise Rosbag2Error(f"{_show(path)} is an MCAP file of profile {profile!r}, not "
                               f"ros2")
        if tail != MCAP_MAGIC:
            raise Rosbag2Error(f"{_show(path)} is cut short: it ends after {size} bytes without "
                               f"MCAP's footer (its recorder did not finish writing it, or the "
                               f"copy is incomplete)")

    def _damage(self, exc: BaseException) -> str:
        """One line for what rosbags or SQLite raised on opening or reading the recording."""
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        where = _show(self.files[0]) if len(self.files) == 1 else _show(self.path)
        return f"{where} is damaged: {text.rstrip('.')}"

    # -- messages --------------------------------------------------------------------------------

    def messages(self, connections: List[Any], start: Optional[int] = None,
                 stop: Optional[int] = None) -> Iterator[Tuple[Any, int, bytes]]:
        """(connection, time ns, CDR bytes) of ``connections`` in time order, start <= t < stop."""
        if not connections:
            return
        try:
            yield from self._reader.messages(connections, start, stop)
        except Exception as exc:  # noqa: BLE001 - damage found while reading: one line
            raise Rosbag2Error(self._damage(exc)) from None

    def close(self) -> None:
        if self._reader is not None:
            reader, self._reader = self._reader, None
            try:
                reader.close()
            except Exception:  # noqa: BLE001, S110 - closing what failed half-way to open
                pass

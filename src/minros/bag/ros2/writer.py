"""Writing a rosbag2 recording: the storage file, and minros's metadata.yaml.

rosbags (Ternaris) writes the SQLite3 storage (rosbag2's schema 4 tables); the MCAP storage is
:mod:`.mcapwriter`'s (rosbags' layout, one copy of each message where rosbags' writer makes
four: most of a conversion's time). rosbags' ``Writer`` also writes metadata.yaml, but only in
versions 8 and 9 and always with a type hash, so minros drives the storage writers itself and
writes the metadata as the
distro's rosbag2 does: version 9 for Jazzy and Kilted (``type_description_hash`` on each
topic, QoS as a list, ``ros_distro``; the layout rosbags-convert writes), version 5 for Humble
(no type hashes, QoS as a YAML string). ``custom_data`` (a version 6 key that Humble's reader
ignores) keeps what minros needs to convert the recording back exactly.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any, Dict, List, Optional

from minros.bag.errors import ROSBagException

#: rosbags-convert's QoS for a latched ROS 1 topic: reliable, transient local, rmw's
#: "infinite" durations (what rosbag2 itself records for a latched publisher)
_INFINITE = (2147483647, 4294967295)


def latch_qos() -> List[Any]:
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    forever = QosTime(*_INFINITE)
    return [Qos(QosHistory.UNKNOWN, 0, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
                forever, forever, QosLiveliness.AUTOMATIC, forever,
                avoid_ros_namespace_conventions=False)]


def metadata_version(distro: str) -> int:
    """The metadata version the distro's rosbag2 writes."""
    return 5 if distro == "humble" else 9


class Rosbag2Writer:
    """A new rosbag2 directory being written (``storage`` "mcap" or "sqlite3")."""

    def __init__(self, path: str, storage: str = "mcap", distro: str = "jazzy") -> None:
        from rosbags.rosbag2.enums import CompressionMode
        from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer

        from minros.bag.ros2.mcapwriter import McapStorageWriter

        if storage not in ("mcap", "sqlite3"):
            raise ValueError(f"storage {storage!r}: expected mcap or sqlite3")
        self.path = Path(path)
        self.storage_id = storage
        self.distro = distro
        self.version = metadata_version(distro)
        self.custom_data: Dict[str, str] = {}
        try:
            self.path.mkdir(parents=True)
        except FileExistsError:
            raise ROSBagException(f"{path} exists already: remove it, or give another output "
                                  f"name") from None
        except OSError as exc:
            raise ROSBagException(f"cannot create {path}: {exc.strerror or exc}") from None
        try:
            plugin = McapStorageWriter if storage == "mcap" else Sqlite3Writer
            self.storage: Any = plugin(self.path, CompressionMode.NONE)
        except BaseException:
            shutil.rmtree(self.path, ignore_errors=True)
            raise
        self.connections: List[Any] = []
        self.counts: Dict[int, int] = {}
        self._types: set = set()
        self.start = 2**63 - 1
        self.end = 0

    def add_topic(self, topic: str, ros2_type: str, definition: str, type_hash: str,
                  qos: Optional[List[Any]] = None) -> Any:
        """Register a topic; returns the connection to :meth:`write` its messages to."""
        from rosbags.interfaces import (
            Connection,
            ConnectionExtRosbag2,
            MessageDefinition,
            MessageDefinitionFormat,
        )

        ext = ConnectionExtRosbag2("cdr", list(qos or []))
        conn = Connection(len(self.connections) + 1, topic, ros2_type,
                          MessageDefinition(MessageDefinitionFormat.MSG, definition),
                          type_hash, 0, ext, self)
        if ros2_type not in self._types:
            self.storage.add_msgtype(conn)
            self._types.add(ros2_type)
        self.storage.add_connection(conn, self._qos_text(ext.offered_qos_profiles))
        self.connections.append(conn)
        self.counts[conn.id] = 0
        return conn

    def _qos_text(self, qos: List[Any]) -> str:
        from rosbags.rosbag2.metadata import dump_qos_v8, dump_qos_v9

        if self.version >= 9:
            import yaml

            return yaml.safe_dump(dump_qos_v9(qos), default_flow_style=False).strip()
        return dump_qos_v8(qos)

    def write(self, conn: Any, t_ns: int, data: Any) -> None:
        self.storage.write(conn, t_ns, data)
        self.counts[conn.id] += 1
        if t_ns < self.start:
            self.start = t_ns
        if t_ns > self.end:
            self.end = t_ns

    def metadata(self) -> Dict[str, Any]:
        """rosbag2_bagfile_information, as the distro's rosbag2 writes it."""
        from rosbags.rosbag2.metadata import dump_qos_v8, dump_qos_v9

        count = sum(self.counts.values())
        start = self.start if count else 0
        duration = max(0, self.end - self.start) if count else 0
        name = self.storage.path.name
        topics = []
        for c in self.connections:
            qos = c.ext.offered_qos_profiles
            meta: Dict[str, Any] = {"name": c.topic, "type": c.msgtype,
                                    "serialization_format": "cdr"}
            if self.version >= 9:
                meta["offered_qos_profiles"] = dump_qos_v9(qos)
                meta["type_description_hash"] = c.digest
            else:
                meta["offered_qos_profiles"] = dump_qos_v8(qos)
            topics.append({"topic_metadata": meta, "message_count": self.counts[c.id]})
        files = [{"path": name, "starting_time": {"nanoseconds_since_epoch": start},
                  "duration": {"nanoseconds": duration}, "message_count": count}]
        info: Dict[str, Any] = {
            "version": self.version,
            "storage_identifier": self.storage_id,
            "relative_file_paths": [name],
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": count,
            "topics_with_message_count": topics,
            "compression_format": "",
            "compression_mode": "",
            "files": files,
        }
        if self.version >= 9:
            info["custom_data"] = dict(self.custom_data) or None
            info["ros_distro"] = self.distro
        elif self.custom_data:
            info["custom_data"] = dict(self.custom_data)
        return info

    def close(self) -> None:
        """Finish the storage file (its index and summary) and write metadata.yaml."""
        import yaml

        info = self.metadata()
        self.storage.close(self.version, yaml.safe_dump(info, default_flow_style=False,
                                                        sort_keys=False).strip())
        text = yaml.safe_dump({"rosbag2_bagfile_information": info}, default_flow_style=False,
                              sort_keys=False)
        tmp = self.path / "metadata.yaml.tmp"
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(self.path / "metadata.yaml")

    def abort(self) -> None:
        """Stop writing and remove the directory (a conversion that failed leaves nothing)."""
        try:
            self.storage.abort()
        finally:
            shutil.rmtree(self.path, ignore_errors=True)

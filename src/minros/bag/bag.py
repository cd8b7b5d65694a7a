"""The ``rosbag.Bag`` API over bag v2.0 files (rosbags) and MCAP files (mcap).

Messages come back as minros message classes: the installed class when its md5 sum matches
the bag's, else one generated from the definition stored in the bag, so types nobody installed
read all the same. Timestamps are ``rospy.Time`` (``minros.Time``), as in rosbag.
"""

from __future__ import annotations

import collections
import io
import os
import sys
import time
from typing import Any, BinaryIO, Callable, Dict, Iterator, List, Optional, Union

from minros.bag import bag1
from minros.bag.bag1 import ConnInfo
from minros.bag.errors import (
    COMPRESSIONS,
    Compression,
    ROSBagDeserializationException,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)
from minros.bag.scan import rebuild
from minros.msgs import reader_for
from minros.names import canonicalize_name

BagMessage = collections.namedtuple("BagMessage", "topic message timestamp")
BagMessageWithConnectionHeader = collections.namedtuple(
    "BagMessageWithConnectionHeader", "topic message timestamp connection_header")
TopicTuple = collections.namedtuple("TopicTuple", ["msg_type", "message_count", "connections", "frequency"])
TypesAndTopicsTuple = collections.namedtuple("TypesAndTopicsTuple", ["msg_types", "topics"])
CompressionTuple = collections.namedtuple("CompressionTuple", ["compression", "uncompressed", "compressed"])


def _to_nsec(t: Any) -> int:
    if t is None:
        return time.time_ns()
    if isinstance(t, int):
        return t * 1_000_000_000
    if isinstance(t, float):
        return int(round(t * 1e9))
    return int(t.to_nsec())


def _time(ns: int) -> Any:
    from minros import Time

    return Time(ns // 1_000_000_000, ns % 1_000_000_000)


def _str(value: Any) -> str:
    return value.decode() if isinstance(value, (bytes, bytearray)) else str(value)


class Bag:
    """A bag file opened for reading ('r'), writing ('w') or appending ('a')."""

    def __init__(self, f: Union[str, os.PathLike, BinaryIO], mode: str = "r",
                 compression: str = Compression.NONE, chunk_threshold: int = 768 * 1024,
                 allow_unindexed: bool = False, options: Optional[dict] = None,
                 skip_index: bool = False) -> None:
        if options is not None:
            if type(options) is not dict:
                raise ValueError("options must be of type dict")
            compression = options.get("compression", compression)
            chunk_threshold = options.get("chunk_threshold", chunk_threshold)
        if compression not in COMPRESSIONS:
            raise ValueError("compression must be one of: " + ", ".join(COMPRESSIONS))
        if chunk_threshold < 0:
            raise ValueError("chunk_threshold must be greater than or equal to zero")
        if not f:
            raise ValueError("filename (or stream) is invalid")
        if mode not in ("r", "w", "a"):
            raise ValueError(f'mode "{mode}" is invalid')
        #: a file object the bag was given (rosbag reads and writes those as it does files,
        #: and closes them on close(); but not an io.BytesIO, which rosbag does not take and
        #: which would lose the bag just written); None when it was given a file name
        self._stream: Optional[BinaryIO] = None
        if isinstance(f, (str, os.PathLike)):
            self._filename: Optional[str] = os.fspath(f)
        else:
            _check_stream(f, mode)
            self._stream, self._filename = f, None
        self._mode = mode
        self._compression = compression
        self._chunk_threshold = chunk_threshold
        self._skip_index = skip_index
        self._reader: Any = None
        self._writer: Any = None
        self._pending_scan = False
        self._classes: Dict[int, Any] = {}
        self._topic_conn: Dict[str, int] = {}
        self._closed = False
        target = self._target
        if mode == "r":
            self._reader = open_reader(target, allow_unindexed, self._keep_open)
            self._version = self._reader.version
        elif mode == "w":
            self._version = 200
            self._writer = open_writer(target, compression, chunk_threshold, self._keep_open)
        else:
            self._version = 200
            self._open_append(allow_unindexed)

    @property
    def _keep_open(self) -> bool:
        return isinstance(self._stream, io.BytesIO)

    @property
    def _target(self) -> Union[str, BinaryIO]:
        """What the bag reads and writes: its file object, else its file name."""
        return self._stream if self._stream is not None else self._filename  # type: ignore[return-value]

    def _open_append(self, allow_unindexed: bool) -> None:
        target = self._target
        if (not os.path.exists(target) if self._stream is None
                else self._stream.seek(0, os.SEEK_END) == 0):
            self._writer = bag1.Bag1Writer(target, self._compression, self._chunk_threshold,
                                           keep_open=self._keep_open)
            return
        if is_mcap(target):
            raise ROSBagException("appending to MCAP files is not supported")
        try:
            scan = bag1.summary_scan(target)
        except ROSBagUnindexedException:
            if not allow_unindexed:
                raise
            self._pending_scan = True  # reindex() or the first write scans the chunks
            return
        except OSError as exc:
            raise ROSBagException(str(exc.strerror or exc)) from None
        self._writer = bag1.Bag1Writer.append(target, self._compression, self._chunk_threshold, scan,
                                              self._keep_open)
        self._topic_conn = {c.topic: c.id for c in self._writer.connections.values()}

    # -- context manager, properties ------------------------------------------------------

    def __iter__(self) -> Iterator[BagMessage]:
        return self.read_messages()

    def __enter__(self) -> Bag:
        return self

    def __exit__(self, exc_type: Any, exc_value: Any, traceback: Any) -> None:
        self.close()

    # rosbag's internals, which tools and tests reach for: the open file and where the file
    # header record starts (after the version line)
    @property
    def _file(self) -> Optional[BinaryIO]:
        handle = self._writer if self._writer is not None else self._reader
        return getattr(handle, "file", None)

    @property
    def _file_header_pos(self) -> Optional[int]:
        return len(bag1.MAGIC) if self._version // 100 == 2 else None

    @property
    def options(self) -> dict:
        return {"compression": self._compression, "chunk_threshold": self._chunk_threshold}

    @property
    def filename(self) -> Optional[str]:
        """The file name (None for a bag opened on a file object, as in rosbag)."""
        return self._filename

    @property
    def version(self) -> Any:
        return self._version

    @property
    def mode(self) -> str:
        return self._mode

    @property
    def size(self) -> int:
        self._check_open()
        if self._writer is not None:
            return self._writer.tell()
        if hasattr(self._reader, "size"):  # a rosbag2 directory: its files
            return int(self._reader.size)
        if self._stream is not None:
            pos = self._stream.tell()
            size = self._stream.seek(0, os.SEEK_END)
            self._stream.seek(pos)
            return size
        return os.path.getsize(self._filename)  # type: ignore[arg-type]

    def _get_compression(self) -> str:
        return self._compression

    def _set_compression(self, compression: str) -> None:
        if compression not in COMPRESSIONS:
            raise ValueError("compression must be one of: " + ", ".join(COMPRESSIONS))
        if isinstance(self._writer, bag1.Bag1Writer):
            self._writer.flush_chunk()  # as rosbag: the chunks after this one use the new one
            self._writer.set_compression(compression)
        elif self._writer is not None and compression != self._compression:  # MCAP
            if self._writer.connections:
                raise ROSBagException("set the compression before writing the first message")
            self._writer.abort()
            self._writer = open_writer(self._target, compression, self._chunk_threshold)
        self._compression = compression

    compression = property(_get_compression, _set_compression)

    def _get_chunk_threshold(self) -> int:
        return self._chunk_threshold

    def _set_chunk_threshold(self, chunk_threshold: int) -> None:
        if chunk_threshold < 0:
            raise ValueError("chunk_threshold must be greater than or equal to zero")
        self.flush()
        self._chunk_threshold = chunk_threshold
        if isinstance(self._writer, bag1.Bag1Writer):
            self._writer._w.chunk_threshold = chunk_threshold

    chunk_threshold = property(_get_chunk_threshold, _set_chunk_threshold)

    # -- the index as seen by readers ----------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise ValueError("I/O operation on closed bag")

    def _source(self) -> Any:
        """The reader (in 'w'/'a' mode: a summary of what was written so far)."""
        self._check_open()
        if self._reader is None:
            raise ROSBagException(f"bag {self._filename} is open for writing; "
                                  "reopen it in mode 'r' to read it")
        return self._reader

    @property
    def _connections(self) -> Dict[int, ConnInfo]:
        if self._reader is not None:
            return self._reader.connections
        return self._writer.connections if self._writer is not None else {}

    def _chunk_summaries(self) -> List[bag1.ChunkSummary]:
        if self._reader is not None:
            return getattr(self._reader, "chunks", [])
        return self._writer.chunk_summaries() if self._writer is not None else []

    def _counts(self) -> Dict[int, int]:
        if self._reader is not None and hasattr(self._reader, "counts"):
            return dict(self._reader.counts)
        counts: Dict[int, int] = {}
        for chunk in self._chunk_summaries():
            for cid, n in chunk.counts.items():
                counts[cid] = counts.get(cid, 0) + n
        return counts

    def _time_range(self) -> Optional[tuple]:
        if self._reader is not None:
            return self._reader.time_range()
        return bag1.chunks_time_range(self._chunk_summaries())

    def _get_connections(self, topics: Any = None,
                         connection_filter: Optional[Callable] = None) -> Iterator[ConnInfo]:
        if topics:
            # rosbag matches topics after roslib.names.canonicalize_name
            wanted = {canonicalize_name(t) for t in ([topics] if isinstance(topics, str) else topics)}
        for c in self._connections.values():
            if topics and c.topic not in wanted and canonicalize_name(c.topic) not in wanted:
                continue
            if connection_filter and not connection_filter(c.topic, c.datatype, c.md5sum,
                                                           c.msg_def, c.header):
                continue
            yield c

    def _class_for(self, conn: ConnInfo) -> Any:
        cls = self._classes.get(conn.id)
        if cls is None:
            from minros.tools.decode import DecodeError, load_class

            try:
                cls = load_class(conn.datatype, conn.md5sum, conn.msg_def)
            except DecodeError as exc:
                raise ROSBagException(str(exc)) from None
            except Exception as exc:  # noqa: BLE001 - a definition damaged in the bag
                raise ROSBagFormatException(f"the message definition of {conn.datatype} on "
                                            f"{conn.topic} does not parse: {exc}") from None
            if conn.md5sum not in ("", "*") and cls._md5sum != conn.md5sum:
                print(f"WARNING: For type [{conn.datatype}] stored md5sum [{conn.md5sum}] does not "
                      f"match message definition [{cls._md5sum}].", file=sys.stderr)
            self._classes[conn.id] = cls
        return cls

    # -- reading -------------------------------------------------------------------------

    def read_messages(self, topics: Any = None, start_time: Any = None, end_time: Any = None,
                      connection_filter: Optional[Callable] = None, raw: bool = False,
                      return_connection_header: bool = False) -> Iterator[Any]:
        """Messages in time order, optionally of some topics, within [start_time, end_time].

        Yields ``BagMessage(topic, message, timestamp)``; with ``raw=True`` the message is
        ``(datatype, serialized bytes, md5sum, position, class)``."""
        source = self._source()
        conns = {c.id: c for c in self._get_connections(topics, connection_filter)}
        if not conns:
            return iter(())
        start = None if start_time is None else _to_nsec(start_time)
        end = None if end_time is None else _to_nsec(end_time)
        return self._read(source, conns, start, end, raw, return_connection_header)

    def _read(self, source: Any, conns: Dict[int, ConnInfo], start: Optional[int],
              end: Optional[int], raw: bool, with_header: bool) -> Iterator[Any]:
        from minros import Time

        classes = {cid: self._class_for(c) for cid, c in conns.items()}
        readers = {cid: reader_for(cls) for cid, cls in classes.items()}
        ids = None if len(conns) == len(source.connections) else list(conns)
        new_time = Time.__new__
        cid = t = -1
        try:
            if not raw and not with_header:
                # the common case in one lean loop: about 8% of a read of many small messages
                topic_readers = {cid: (conns[cid].topic, read) for cid, read in readers.items()}
                new_tuple = tuple.__new__  # BagMessage(...) runs a Python-level __new__
                for cid, t, data, _pos in source.messages(ids, start, end):
                    topic, read = topic_readers[cid]
                    msg = read(data)
                    stamp = new_time(Time)  # filled in directly: two __init__ calls add up
                    stamp.secs, stamp.nsecs = divmod(t, 1_000_000_000)
                    yield new_tuple(BagMessage, (topic, msg, stamp))
                return
            headers = {cid: c.header for cid, c in conns.items()} if with_header else {}
            for cid, t, data, pos in source.messages(ids, start, end):
                conn = conns[cid]
                cls = classes[cid]
                if raw:
                    msg: Any = (conn.datatype, bytes(data), conn.md5sum, pos, cls)
                else:
                    msg = readers[cid](data)
                stamp = new_time(Time)  # filled in directly: two __init__ calls per message add up
                stamp.secs, stamp.nsecs = divmod(t, 1_000_000_000)
                if with_header:
                    yield BagMessageWithConnectionHeader(conn.topic, msg, stamp, headers[cid])
                else:
                    yield BagMessage(conn.topic, msg, stamp)
        except ROSBagException:
            raise
        except Exception as exc:  # noqa: BLE001 - whatever a damaged message makes a reader raise
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            if cid not in conns:
                raise ROSBagFormatException(f"the bag could not be read: {reason}") from None
            conn = conns[cid]
            raise ROSBagDeserializationException(
                f"the {conn.datatype} message of {conn.topic} at {t // 1_000_000_000}."
                f"{t % 1_000_000_000:09d} does not deserialize ({reason}): the bag is damaged "
                "there, or its message definition is wrong") from None

    def get_message_count(self, topic_filters: Any = None) -> int:
        counts = self._counts()
        if topic_filters is None:
            return sum(counts.values())
        return sum(counts.get(c.id, 0) for c in self._get_connections(topic_filters))

    def get_start_time(self) -> float:
        rng = self._time_range()
        if rng is None:
            raise ROSBagException("Bag contains no message")
        return rng[0] / 1e9

    def get_end_time(self) -> float:
        rng = self._time_range()
        if rng is None:
            raise ROSBagException("Bag contains no message")
        return rng[1] / 1e9

    def _frequencies(self, topics: List[str]) -> Dict[str, float]:
        out: Dict[str, float] = {}
        if self._reader is None:
            return out
        for topic in topics:
            ids = [c.id for c in self._get_connections(topic)]
            stamps = self._reader.index_times(ids)
            if len(stamps) > 1:
                periods = sorted(b - a for a, b in zip(stamps, stamps[1:]))
                n = len(periods)
                med = periods[n // 2] if n % 2 else (periods[n // 2 - 1] + periods[n // 2]) / 2
                if med > 0:
                    out[topic] = 1e9 / med
        return out

    def _topic_table(self, topic_filters: Any = None, with_freq: bool = False) -> dict:
        counts = self._counts()
        if topic_filters is not None:
            names = [topic_filters] if not isinstance(topic_filters, list) else topic_filters
        else:
            names = [c.topic for c in self._connections.values()]
        table = {}
        for topic in sorted(set(names)):
            conns = [c for c in self._get_connections(topic) if counts.get(c.id, 0) or self._writer]
            if not conns:
                continue
            table[topic] = (conns[0].datatype, sum(counts.get(c.id, 0) for c in conns), len(conns))
        freqs = self._frequencies(list(table)) if with_freq else {}
        return {t: TopicTuple(d, n, k, freqs.get(t)) for t, (d, n, k) in table.items()}

    def _datatypes(self) -> Dict[str, tuple]:
        seen: Dict[str, tuple] = {}
        counts = self._counts()
        for c in self._connections.values():
            if c.datatype not in seen and (counts.get(c.id, 0) or self._writer):
                seen[c.datatype] = (c.md5sum, c.msg_def)
        return dict(sorted(seen.items()))

    def get_type_and_topic_info(self, topic_filters: Any = None) -> TypesAndTopicsTuple:
        types = {name: md5 for name, (md5, _d) in self._datatypes().items()}
        topics = self._topic_table(topic_filters, with_freq=self._reader is not None and not self._skip_index)
        return TypesAndTopicsTuple(msg_types=types, topics=topics)

    def get_compression_info(self) -> CompressionTuple:
        chunks = self._chunk_summaries()
        if not chunks:
            return CompressionTuple(self._compression, 0, 0)
        by: Dict[str, int] = collections.Counter(c.compression for c in chunks)
        main = sorted(((n, k) for k, n in by.items()), reverse=True)[0][1]
        return CompressionTuple(main, sum(c.uncompressed_size for c in chunks),
                                sum(c.compressed_size for c in chunks))

    @property
    def _uncompressed_size(self) -> int:
        chunks = self._chunk_summaries()
        return sum(c.uncompressed_size for c in chunks) if chunks else self.size

    # -- writing -------------------------------------------------------------------------

    def _ensure_writer(self) -> None:
        if self._writer is None and self._pending_scan:
            for _ in self.reindex():
                pass

    def write(self, topic: str, msg: Any, t: Any = None, raw: bool = False,
              connection_header: Optional[dict] = None) -> None:
        """Add a message (or, with ``raw``, a (type, bytes, md5sum[, position], class) tuple)."""
        self._check_open()
        if self._mode == "r":
            raise ValueError("bag is open for reading; open it with mode 'w' or 'a' to write")
        if not topic:
            raise ValueError("topic is invalid")
        if msg is None or (raw and not msg):
            raise ValueError("msg is invalid")
        self._ensure_writer()
        t_ns = _to_nsec(t)
        header = {_str(k): _str(v) for k, v in (connection_header or {}).items()}
        if raw:
            if len(msg) == 5:
                msg_type, data, md5sum, _pos, pytype = msg
            elif len(msg) == 4:
                msg_type, data, md5sum, pytype = msg
            else:
                raise ValueError("msg must be of length 4 or 5")
        else:
            buff = getattr(msg, "_buff", None)
            if buff is not None and getattr(msg, "_type", "") == "*":  # AnyMsg: bytes as received
                data = bytes(buff)
                header = header or {_str(k): _str(v) for k, v in
                                    (getattr(msg, "_connection_header", None) or {}).items()}
                msg_type, md5sum, pytype = header.get("type", ""), header.get("md5sum", ""), None
                if not msg_type:
                    raise ROSBagException("cannot write an AnyMsg without its connection header")
            else:
                out = io.BytesIO()
                msg.serialize(out)
                data = out.getvalue()
                msg_type, md5sum, pytype = msg._type, msg._md5sum, type(msg)
        cid = self._topic_conn.get(topic)
        if cid is None:
            if not header:
                if pytype is None:
                    from minros.tools.decode import DecodeError, load_class

                    try:
                        pytype = load_class(msg_type, md5sum, "")
                    except DecodeError:
                        raise ROSBagException("cannot locate message class and no message class "
                                              f"provided for [{msg_type}]") from None
                header = {"topic": topic, "type": msg_type, "md5sum": md5sum,
                          "message_definition": pytype._full_text}
            cid = self._writer.connection(
                topic, header.get("type", msg_type), header.get("md5sum", md5sum),
                header.get("message_definition", ""), header.get("callerid"), header.get("latching"))
            self._topic_conn[topic] = cid
        self._writer.write(cid, t_ns, data)

    def flush(self) -> None:
        """Write the open chunk to disk."""
        self._check_open()
        if self._writer is not None:
            self._writer.flush_chunk()

    def reindex(self) -> Iterator[int]:
        """Rebuild the index from the chunks; yields the offset of each chunk (for progress)."""
        self._check_open()
        if self._mode == "r":
            positions: List[int] = []
            if not isinstance(self._reader, bag1.Bag1Reader):
                return iter(())
            self._reader.reindex(positions.append)
            return iter(positions)
        return self._reindex_for_append()

    def _reindex_for_append(self) -> Iterator[int]:
        if self._writer is not None:
            self._writer.abort()
            self._writer = None
        if self._stream is not None:
            scan = bag1.ScanResult()
            yield from bag1.iter_scan(self._stream, scan)
            rebuild(self._stream, scan)
        else:
            with open(self._filename, "r+b") as f:  # type: ignore[arg-type]
                scan = bag1.ScanResult()
                yield from bag1.iter_scan(f, scan)
                rebuild(f, scan)
        self._writer = bag1.Bag1Writer.append(self._target, self._compression, self._chunk_threshold,
                                              keep_open=self._keep_open)
        self._topic_conn = {c.topic: c.id for c in self._writer.connections.values()}
        self._pending_scan = False

    def close(self) -> None:
        """Close the bag (writing the index when writing). Closing twice does nothing."""
        if self._closed:
            return
        self._closed = True
        try:
            if self._writer is not None:
                self._writer.close()
        finally:
            if self._reader is not None:
                self._reader.close()

    # -- rosbag info ---------------------------------------------------------------------

    def __str__(self) -> str:
        from minros.bag.info import info_text

        return info_text(self, with_freq=not self._skip_index)

    def _get_yaml_info(self, key: Optional[str] = None) -> Optional[str]:
        from minros.bag.info import info_yaml

        return info_yaml(self, key, with_freq=not self._skip_index)


MCAP_MAGIC = b"\x89MCAP0\r\n"


def is_mcap(source: Union[str, BinaryIO]) -> bool:
    """Whether ``source`` starts with MCAP's magic bytes (else it is taken for a bag)."""
    try:
        if not isinstance(source, str):
            source.seek(0)
            return source.read(len(MCAP_MAGIC)) == MCAP_MAGIC
        with open(source, "rb") as f:
            return f.read(len(MCAP_MAGIC)) == MCAP_MAGIC
    except OSError:
        return False


def _check_stream(f: Any, mode: str) -> None:
    """A file object to read or write a bag in: binary, and able to seek (rosbag's demands)."""
    if isinstance(f, io.TextIOBase) or "b" not in getattr(f, "mode", "b"):
        raise ROSBagException("In Python 3 the bag file must be opened in binary mode")
    if not all(hasattr(f, name) for name in ("read", "write", "seek", "tell")):
        raise ValueError("filename (or stream) is invalid")
    if getattr(f, "closed", False):
        raise ValueError("I/O operation on closed file")


def open_reader(source: Union[str, BinaryIO], allow_unindexed: bool, keep_open: bool = False) -> Any:
    """The reader of a bag v2.0 or MCAP file (by its first bytes), or of a ROS 2 recording (a
    rosbag2 directory, a ROS 2 MCAP or SQLite file), whose messages it converts to ROS 1."""
    if isinstance(source, str) and not os.path.exists(source):
        raise ROSBagException(f"[Errno 2] No such file or directory: '{source}'")
    if isinstance(source, str):
        from minros.bag.ros2.storage import kind  # a few bytes read: which reader

        if kind(source):
            from minros.bag.ros2.reader import Rosbag2Reader

            return Rosbag2Reader(source, allow_unindexed)
    if is_mcap(source):
        if not isinstance(source, str):
            raise ROSBagException("minros reads MCAP files by name: pass the file's name, not a file object")
        from minros.bag import mcapfile  # imported only for MCAP files: rosbag info starts faster

        return mcapfile.McapReader(source, allow_unindexed)
    return bag1.Bag1Reader(source, allow_unindexed, keep_open)


def open_writer(path: Union[str, BinaryIO], compression: str, chunk_threshold: int,
                keep_open: bool = False) -> Any:
    """A new file's writer: MCAP when the name ends in .mcap (or .mcap.active), else bag v2.0
    (always for a file object)."""
    if isinstance(path, str) and (path.endswith(".mcap") or path.endswith(".mcap.active")):
        from minros.bag import mcapfile

        return mcapfile.McapWriter(path, compression, chunk_threshold)
    return bag1.Bag1Writer(path, compression, chunk_threshold, keep_open=keep_open)

"""``rosbag record``: subscribe with AnyMsg and write the bytes each publisher sent.

Nothing is deserialized: a message arrives as the publisher's TCPROS bytes with its connection
header (type, md5sum, message_definition, callerid, latching), goes into a bounded queue (``-b``
megabytes, the oldest message dropped and counted per topic when full) and a writer thread
puts it in the bag. The writer closes a chunk at least every :data:`FLUSH_INTERVAL` seconds and
hands it to the kernel, so a recorder killed with SIGKILL loses at most that much: the
``.bag.active`` file it leaves is recovered by ``rosbag reindex``.

``--duration`` and ``--size`` are rosbag's: the recording ends at the first message received
more than DURATION after it began (ROS time, checked also every quarter second while nothing
arrives), or bigger than SIZE MB; with ``--split`` a new file begins instead, at every
DURATION from the start (empty files too, as ROS's recorder makes them).
"""

from __future__ import annotations

import collections
import errno
import os
import re
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Deque, Dict, List, Optional, Tuple

from minros.bag import bag1
from minros.bag.bag import open_writer
from minros.bag.errors import Compression

#: a chunk is closed and written out at least this often (seconds) while messages arrive
FLUSH_INTERVAL = 0.5
#: topics of -a/-e/--node are looked for this often (seconds), as rosbag's recorder does
MASTER_POLL_INTERVAL = 1.0
#: the buffer-overflow warning is repeated at most this often (seconds)
WARN_INTERVAL = 5.0


@dataclass
class RecordOptions:
    topics: List[str] = field(default_factory=list)
    record_all: bool = False
    regex: bool = False
    exclude: Optional[str] = None
    quiet: bool = False
    prefix: Optional[str] = None
    name: Optional[str] = None
    split: bool = False
    max_splits: int = 0
    size_mb: int = 0
    duration: Optional[str] = None
    buffsize_mb: int = 256
    chunksize_kb: int = 768
    limit: int = 0
    node: Optional[str] = None
    compression: str = Compression.NONE
    tcpnodelay: bool = False
    udp: bool = False
    repeat_latched: bool = False
    publish: bool = False


#: a number as ROS's recorder reads one (C++ stream extraction of a double), then a unit
_DURATION = re.compile(r"\s*(\+?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*([smh]?)\s*")


def parse_duration(text: str) -> float:
    """``--duration``: seconds, or minutes/hours with an ``m``/``h`` suffix."""
    m = _DURATION.fullmatch(text)
    if not m:
        raise ValueError(f"Duration '{text}' is not a number of seconds, optionally followed by "
                         "'s', 'm' or 'h' (e.g. --duration 30, --duration 1.5m)")
    value = float(m.group(1)) * {"": 1, "s": 1, "m": 60, "h": 3600}[m.group(2)]
    if value <= 0:
        raise ValueError(f"Duration '{text}' must be greater than 0")
    return value


def bag_filename(prefix: Optional[str], name: Optional[str], split_index: Optional[int],
                 now: Optional[float] = None) -> str:
    """The file rosbag's recorder writes: ``NAME[_N].bag``, ``PREFIX_DATE[_N].bag`` or
    ``DATE[_N].bag``; ``.mcap`` instead of ``.bag`` when the name asks for MCAP."""
    base = name if name is not None else (prefix or "")
    ext = ".bag"
    if base.endswith(".mcap"):
        base, ext = base[:-5], ".mcap"
    elif base.endswith(".bag"):
        base = base[:-4]
    parts = [base] if base else []
    if name is None:
        parts.append(time.strftime("%Y-%m-%d-%H-%M-%S", time.localtime(now)))
    if split_index is not None:
        parts.append(str(split_index))
    return "_".join(parts) + ext


def topic_matches(topic: str, patterns: List[re.Pattern], exclude: Optional[re.Pattern]) -> bool:
    if exclude is not None and exclude.fullmatch(topic):
        return False
    return any(p.fullmatch(topic) for p in patterns)


#: a message waiting to be written: (topic, receive time ns, bytes, connection header)
Item = Tuple[str, int, bytes, Dict[str, str]]


class RecordQueue:
    """Messages between the subscribers and the writer, bounded in bytes (0 = unbounded);
    when full the oldest message is dropped and counted against its topic."""

    def __init__(self, limit_bytes: int) -> None:
        self.limit = limit_bytes
        self.items: Deque[Item] = collections.deque()
        self.bytes = 0
        self.cond = threading.Condition()
        self.closed = False
        self.drops: Dict[str, int] = collections.Counter()
        self.new_drops = 0

    def push(self, item: Item) -> None:
        with self.cond:
            self.items.append(item)
            self.bytes += len(item[2])
            while self.limit and self.bytes > self.limit and len(self.items) > 1:
                old = self.items.popleft()
                self.bytes -= len(old[2])
                self.drops[old[0]] += 1
                self.new_drops += 1
            self.cond.notify()

    def pop(self, timeout: float) -> Optional[Item]:
        with self.cond:
            if not self.items and not self.closed:
                self.cond.wait(timeout)
            if not self.items:
                return None
            item = self.items.popleft()
            self.bytes -= len(item[2])
            return item

    def close(self) -> None:
        with self.cond:
            self.closed = True
            self.cond.notify_all()

    def take_new_drops(self) -> int:
        with self.cond:
            n, self.new_drops = self.new_drops, 0
            return n


class WriteFailed(Exception):
    pass


class BagSink:
    """The writer thread's state: the open bag, its connections, splitting and flushing."""

    def __init__(self, opts: RecordOptions, log: Callable[[str, str], None],
                 on_open: Optional[Callable[[str], None]] = None,
                 clock: Optional[Callable[[], int]] = None) -> None:
        self.opts = opts
        self.log = log
        self.on_open = on_open
        #: the node's ROS time in ns, read while no message arrives (--duration)
        self.clock = clock
        self.writer: Any = None
        self.target = ""
        self.active = ""
        self.split_index = 0 if opts.split else None
        self.conn_ids: Dict[tuple, int] = {}
        self.opened_at = 0.0
        self.chunk_started = 0.0
        self.split_files: Deque[str] = collections.deque()
        self.latched: Dict[Tuple[str, str], Item] = {}
        self.max_size = opts.size_mb * 1048576
        self.max_duration = round(parse_duration(opts.duration) * 1e9) if opts.duration else 0
        #: ROS time (ns) the recording began, then of the current split's period
        self.start_ns: Optional[int] = None
        #: --duration or --size reached without --split: the recording is over
        self.finished = False
        self.error: Optional[str] = None

    # the file --------------------------------------------------------------------------

    def open_next(self) -> None:
        self.target = bag_filename(self.opts.prefix, self.opts.name, self.split_index)
        self.active = self.target + ".active"
        if os.path.exists(self.active):
            os.unlink(self.active)
        self.writer = open_writer(self.active, self.opts.compression, self.opts.chunksize_kb * 1024)
        self.conn_ids = {}
        self.opened_at = self.chunk_started = time.monotonic()
        self.log("info", f"Recording to '{self.target}'.")
        if self.on_open is not None:
            self.on_open(self.target)
        if self.opts.repeat_latched:
            for item in list(self.latched.values()):
                self._write(item)

    def close_current(self) -> None:
        writer, self.writer = self.writer, None
        if writer is None:
            return
        writer.close()
        os.replace(self.active, self.target)
        if self.split_index is not None:
            self.split_files.append(self.target)
            while self.opts.max_splits and len(self.split_files) > self.opts.max_splits:
                old = self.split_files.popleft()
                try:
                    os.unlink(old)
                except OSError:
                    pass

    # messages --------------------------------------------------------------------------

    def _write(self, item: Item) -> None:
        topic, t_ns, data, header = item
        key = (topic, header.get("type"), header.get("md5sum"), header.get("callerid"),
               header.get("latching"))
        cid = self.conn_ids.get(key)
        if cid is None:
            cid = self.writer.connection(topic, header.get("type", ""), header.get("md5sum", ""),
                                         header.get("message_definition", ""),
                                         header.get("callerid"), header.get("latching"))
            self.conn_ids[key] = cid
        self.writer.write(cid, t_ns, data)

    def start(self, start_ns: int) -> None:
        """The recording begins at ROS time ``start_ns`` (--duration counts from here)."""
        self.start_ns = start_ns

    def write(self, item: Item) -> None:
        """Write one message, unless the bag's size or the message's time ends the recording
        (as ROS's recorder: the size is looked at first, then the time)."""
        if self.writer is None:
            self.open_next()
        if self.start_ns is None:
            self.start_ns = item[1]
        if self.finished or self.check_size() or self.check_duration(item[1]):
            return
        if self.opts.repeat_latched and item[3].get("latching") == "1":
            self.latched[(item[0], item[3].get("callerid", ""))] = item
        self._write(item)

    def _next_split(self) -> None:
        self.close_current()
        self.split_index = (self.split_index or 0) + 1
        self.open_next()

    def check_size(self) -> bool:
        """--size: past it, the next split begins, or without --split the recording ends
        (True)."""
        if not self.max_size or self.writer is None or self.writer.tell() <= self.max_size:
            return False
        if self.opts.split:
            self._next_split()
            return False
        self.finished = True
        return True

    def check_duration(self, t_ns: int) -> bool:
        """--duration at ROS time ``t_ns``: more than DURATION after the start, the next split
        begins, or without --split the recording ends (True)."""
        if not self.max_duration or self.start_ns is None or \
                t_ns - self.start_ns <= self.max_duration:
            return False
        if not self.opts.split:
            self.finished = True
            return True
        # the period that holds t_ns; ROS's recorder writes one empty file for each period
        # skipped, which a clock leaping ahead would turn into millions: one file here
        self.start_ns += (t_ns - self.start_ns - 1) // self.max_duration * self.max_duration
        self._next_split()
        return False

    def maybe_flush(self, now: float) -> None:
        if self.writer is not None and now - self.chunk_started >= FLUSH_INTERVAL:
            self.writer.flush_chunk()
            self.chunk_started = now

    def run(self, queue: RecordQueue) -> None:
        """The writer thread: until the queue is closed and empty, the recording is over
        (--duration, --size) or writing fails. The bag is there from the start, as ROS's."""
        try:
            if self.writer is None:
                self.open_next()
            while not self.finished:
                item = queue.pop(FLUSH_INTERVAL / 2)
                if item is not None:
                    self.write(item)
                elif queue.closed:
                    break
                elif self.clock is not None:
                    self.check_duration(self.clock())
                self.maybe_flush(time.monotonic())
            self.close_current()
        except OSError as exc:
            self._fail(exc)
            queue.close()

    def _fail(self, exc: OSError) -> None:
        """Writing failed (disk full, file too large, ...): keep what the bag already holds."""
        reason = os.strerror(exc.errno) if exc.errno else str(exc)
        path, writer, self.writer = self.active, self.writer, None
        try:
            if writer is not None:
                writer.abort()
        except OSError:
            pass
        kept = ""
        if path.endswith(".bag.active") and os.path.exists(path):
            try:
                # cut the half-written chunk (that frees room) and write the index
                scan = bag1.reindex_in_place(path)
                os.replace(path, self.target)
                kept = (f"; the {sum(sum(c.counts.values()) for c in scan.chunks)} messages "
                        f"written before are in {self.target}")
            except (OSError, Exception):
                kept = f"; run 'rosbag reindex {path}' to recover what was written"
        hint = " (free some disk space, or record to another disk)" if exc.errno in (
            errno.ENOSPC, errno.EFBIG, errno.EDQUOT) else ""
        self.error = f"Error writing to {path}: {reason}{hint}{kept}"


class Recorder:
    """The recording node: subscriptions, the queue and the writer thread."""

    def __init__(self, opts: RecordOptions) -> None:
        self.opts = opts
        self.queue = RecordQueue(opts.buffsize_mb * 1048576)
        self.subscribers: Dict[str, Any] = {}
        self.counts: Dict[str, int] = collections.Counter()
        self.limit_reached: set = set()
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.last_warn = 0.0
        self.begin_write_pub: Any = None
        self.sink = BagSink(opts, self._log, self._on_open, self._ros_time_ns)
        self.patterns = [re.compile(t) for t in opts.topics] if opts.regex else []
        self.exclude = re.compile(opts.exclude) if opts.exclude else None

    def _log(self, level: str, text: str) -> None:
        import minros

        {"info": minros.loginfo, "warn": minros.logwarn, "error": minros.logerr}[level](text)

    @staticmethod
    def _ros_time_ns() -> int:
        import minros

        t = minros.get_rostime()
        return t.secs * 1_000_000_000 + t.nsecs

    def _wait_for_valid_time(self) -> Optional[int]:
        """ROS time once it is valid (on simulated time, the first /clock), as ROS's recorder
        waits for it before it begins; None if the node shuts down first."""
        began = time.monotonic()
        warned = False
        while not self.stop.is_set():
            now = self._ros_time_ns()
            if now:
                return now
            if not warned and time.monotonic() - began >= 2.0:
                self._log("warn", "/use_sim_time set to true and no clock published.  Still "
                                  "waiting for valid time...")
                warned = True
            self.stop.wait(0.05)
        return None

    def _on_open(self, target: str) -> None:
        if self.begin_write_pub is not None:
            from std_msgs.msg import String

            self.begin_write_pub.publish(String(target))

    def _callback(self, topic: str) -> Callable[[Any], None]:
        import minros

        queue = self.queue
        limit = self.opts.limit
        counts = self.counts
        get_rostime = minros.get_rostime

        def on_message(msg: Any) -> None:
            t = get_rostime()
            if limit:
                if counts[topic] >= limit:
                    return
                counts[topic] += 1
                if counts[topic] >= limit:
                    self.limit_reached.add(topic)
            # the receive buffer is reused after this callback returns: copy the bytes now
            queue.push((topic, t.secs * 1_000_000_000 + t.nsecs, bytes(msg._buff),
                        msg._connection_header))

        return on_message

    def subscribe(self, topic: str) -> None:
        import minros

        with self.lock:
            if topic in self.subscribers:
                return
            self._log("info", f"Subscribing to {topic}")
            self.subscribers[topic] = minros.Subscriber(
                topic, minros.AnyMsg, self._callback(topic), queue_size=100,
                tcp_nodelay=self.opts.tcpnodelay)

    def _poll_master(self) -> None:
        """-a, -e and --node: subscribe to the topics that appeared since the last look."""
        import minros

        try:
            if self.opts.node:
                topics = self._node_subscriptions()
            else:
                topics = [t for t, _type in minros.get_published_topics()]
        except Exception:  # the master is away for a moment: look again later
            return
        for topic in sorted(topics):
            if topic in self.subscribers:
                continue
            if self.opts.node or self.opts.record_all:
                if self.exclude is not None and self.exclude.fullmatch(topic):
                    continue
                self.subscribe(topic)
            elif topic_matches(topic, self.patterns, self.exclude):
                self.subscribe(topic)

    def _node_subscriptions(self) -> List[str]:
        import minros
        from minros import names
        from minros.tools.master import Master, MasterException
        from minros.wire.rosapi import RemoteError
        from minros.wire.slaveapi import SlaveClient

        node = names.script_resolve_name("rosbag", self.opts.node or "")
        master = Master(minros.get_caller_id())
        try:
            uri = master.lookup_node(node)
        except MasterException:
            return []
        finally:
            master.close()
        try:
            with SlaveClient(uri, minros.get_caller_id(), 5.0) as client:
                subs = client.get_subscriptions()
        except RemoteError:
            return []
        return [t for t, _type in subs]

    def _warn_drops(self, now: float) -> None:
        if self.queue.new_drops and now - self.last_warn >= WARN_INTERVAL:
            self.queue.take_new_drops()
            self.last_warn = now
            self._log("warn", "rosbag record buffer exceeded.  Dropping oldest queued message. "
                              f"(dropped so far: {self._drops_per_topic()})")

    def _drops_per_topic(self) -> str:
        return ", ".join(f"{t}: {n}" for t, n in sorted(self.queue.drops.items()))

    def run(self) -> int:
        import minros

        minros.on_shutdown(self.stop.set)
        if self.opts.publish:
            from std_msgs.msg import String

            self.begin_write_pub = minros.Publisher("begin_write", String, queue_size=1, latch=True)
        if self.opts.udp:
            self._log("warn", "--udp: minros speaks TCPROS only; recording over TCP")
        discover = self.opts.record_all or self.opts.regex or bool(self.opts.node)
        if not discover:
            for topic in self.opts.topics:
                self.subscribe(topic)
        start = self._wait_for_valid_time()
        if start is None:
            return 0
        self.sink.start(start)
        writer = threading.Thread(target=self.sink.run, args=(self.queue,), name="bag-writer",
                                  daemon=True)
        writer.start()
        next_poll = 0.0
        explicit = set(self.opts.topics)
        while not self.stop.is_set() and writer.is_alive():
            now = time.monotonic()
            if discover and now >= next_poll:
                self._poll_master()
                next_poll = now + MASTER_POLL_INTERVAL
            self._warn_drops(now)
            if self.limit_reached:
                self._drop_finished()
                if not discover and explicit and explicit <= set(self.counts) and \
                        all(self.counts[t] >= self.opts.limit for t in explicit):
                    break
            self.stop.wait(0.1)
        for sub in list(self.subscribers.values()):
            sub.unregister()
        self.queue.close()
        writer.join()
        if self.queue.drops:
            total = sum(self.queue.drops.values())
            self._log("warn", f"Dropped {total} messages because the buffer (-b {self.opts.buffsize_mb} MB) "
                              f"was full: {self._drops_per_topic()}")
        if self.sink.error:
            self._log("error", self.sink.error)
            return 1
        return 0

    def _drop_finished(self) -> None:
        with self.lock:
            for topic in list(self.limit_reached):
                sub = self.subscribers.get(topic)
                if sub is not None and getattr(sub, "impl", None) is not None:
                    sub.unregister()


def record(opts: RecordOptions, argv: Optional[List[str]] = None) -> int:
    """Run the recorder until Ctrl-C (or -l); returns the exit status."""
    import minros

    if opts.duration:
        parse_duration(opts.duration)  # a bad value is reported before anything starts
    minros.init_node("record", argv=[sys.argv[0]] + [a for a in (argv or []) if ":=" in a],
                     anonymous=True)
    try:
        return Recorder(opts).run()
    finally:
        minros.signal_shutdown("recording done")


"""``rosbag play``: publish the stored bytes of one or more bags at their recorded pace.

ROS 2 recordings (rosbag2 directories, ROS 2 MCAP) play too: their reader
(:mod:`minros.bag.ros2.reader`) hands over each message converted to ROS 1 bytes, under the
ROS 1 type ros1_bridge's rules give it, so ROS 1 nodes can be fed from ROS 2 recordings.

Each topic is advertised with the type, md5sum, definition and latching of the connection it
was recorded from, and a message is sent as the bytes in the bag, so types nobody installed
play all the same. Send times follow the bag's receive times, scaled by ``-r``: the player
sleeps until a millisecond before each send and waits the rest in short naps.
"""

from __future__ import annotations

import heapq
import itertools
import os
import select
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Optional, Tuple

from minros.bag.bag import open_reader
from minros.bag.bag1 import ConnInfo
from minros.bag.errors import ROSBagException

#: the status line is rewritten at most this often (seconds)
STATUS_INTERVAL = 0.1


@dataclass
class PlayOptions:
    bags: List[str] = field(default_factory=list)
    prefix: str = ""
    quiet: bool = False
    immediate: bool = False
    pause: bool = False
    queue: int = 100
    clock: bool = False
    hz: float = 100.0
    delay: float = 0.2
    rate: float = 1.0
    start: float = 0.0
    duration: Optional[float] = None
    skip_empty: Optional[float] = None
    loop: bool = False
    keep_alive: bool = False
    topics: List[str] = field(default_factory=list)
    pause_topics: List[str] = field(default_factory=list)
    wait_for_subscribers: bool = False
    rate_control_topic: str = ""
    rate_control_max_delay: float = 1.0


class RawMessage:
    """Stored bytes sent as they are; subclasses carry the connection's type and md5sum."""

    __slots__ = ("_buff",)
    _type = ""
    _md5sum = ""
    _full_text = ""
    _has_header = False

    def __init__(self, buff: bytes = b"") -> None:
        self._buff = buff

    def serialize(self, buff: Any) -> None:
        buff.write(self._buff)


def raw_class(conn: ConnInfo) -> type:
    """A message class that publishes ``conn``'s bytes under its type and md5sum."""
    return type("RawMessage", (RawMessage,), {"__slots__": (), "_type": conn.datatype,
                                              "_md5sum": conn.md5sum, "_full_text": conn.msg_def})


class TimeTranslator:
    """Bag time -> wall time: ``real = real_start + (bag - bag_start) / rate``, shifted by
    pauses and skipped gaps."""

    def __init__(self, rate: float) -> None:
        self.rate = rate
        self.bag_start = 0
        self.real_start = 0.0

    def set(self, bag_ns: int, real: float) -> None:
        self.bag_start = bag_ns
        self.real_start = real

    def shift(self, seconds: float) -> None:
        self.real_start += seconds

    def real(self, bag_ns: int) -> float:
        return self.real_start + (bag_ns - self.bag_start) / 1e9 / self.rate


class Keyboard:
    """Space toggles pause, ``s`` steps (stdin in cbreak mode while playing, when a terminal)."""

    def __init__(self) -> None:
        self.fd: Optional[int] = None
        self.saved: Any = None
        try:
            if sys.stdin is not None and sys.stdin.isatty():
                import termios
                import tty

                self.fd = sys.stdin.fileno()
                self.saved = termios.tcgetattr(self.fd)
                tty.setcbreak(self.fd)
        except (OSError, ValueError, ImportError):
            self.fd = None

    def read(self) -> str:
        if self.fd is None:
            return ""
        ready, _, _ = select.select([self.fd], [], [], 0)
        return os.read(self.fd, 16).decode("ascii", "ignore") if ready else ""

    def restore(self) -> None:
        if self.fd is not None and self.saved is not None:
            import termios

            termios.tcsetattr(self.fd, termios.TCSADRAIN, self.saved)


class Player:
    def __init__(self, opts: PlayOptions) -> None:
        self.opts = opts
        self.readers: List[Any] = []
        self.publishers: Dict[str, Any] = {}
        #: (bag index, connection id) -> (publisher, message class, output topic)
        self.routes: Dict[Tuple[int, int], Tuple[Any, type, str]] = {}
        self.paused = opts.pause
        self.step = False
        self.stop = threading.Event()
        self.last_status = 0.0
        self.clock_pub: Any = None
        self.last_rate_control = time.monotonic()
        self.out = sys.stdout

    def open(self) -> None:
        import minros

        for path in self.opts.bags:
            minros.loginfo(f"Opening {path}")
            try:
                reader = open_reader(path, allow_unindexed=False)
            except ROSBagException as exc:
                raise ROSBagException(f"Error opening file: {path}: {exc}") from None
            self.readers.append(reader)
            # a ROS 2 recording plays converted to ROS 1: what does not convert is named
            for topic, (ros2_type, reason) in sorted(getattr(reader, "skipped", {}).items()):
                if self._selected_topic(topic):
                    minros.logwarn(f"{topic} [{ros2_type}] is not played: {reason}")

    def _selected(self, conn: ConnInfo) -> bool:
        return self._selected_topic(conn.topic)

    def _selected_topic(self, topic: str) -> bool:
        if not self.opts.topics:
            return True
        wanted = {t if t.startswith("/") else "/" + t for t in self.opts.topics}
        return (topic if topic.startswith("/") else "/" + topic) in wanted

    def advertise(self) -> None:
        import minros

        for i, reader in enumerate(self.readers):
            for conn in reader.connections.values():
                if not self._selected(conn):
                    continue
                topic = self.opts.prefix + conn.topic if self.opts.prefix else conn.topic
                pub = self.publishers.get(topic)
                if pub is None:
                    cls = raw_class(conn)
                    pub = minros.Publisher(topic, cls, queue_size=self.opts.queue,
                                           latch=conn.latching == "1")
                    self.publishers[topic] = pub
                self.routes[(i, conn.id)] = (pub, pub.data_class, topic)
        if self.opts.clock:
            from rosgraph_msgs.msg import Clock

            self.clock_pub = minros.Publisher("/clock", Clock, queue_size=self.opts.queue)
        if self.opts.rate_control_topic:
            minros.Subscriber(self.opts.rate_control_topic, minros.AnyMsg, self._rate_control)

    def _rate_control(self, _msg: Any) -> None:
        self.last_rate_control = time.monotonic()

    # -- the message stream -------------------------------------------------------------

    def time_range(self) -> Tuple[int, int]:
        ranges = [r for r in (reader.time_range() for reader in self.readers) if r is not None]
        if not ranges:
            return 0, 0
        return min(r[0] for r in ranges), max(r[1] for r in ranges)

    def messages(self, start: int, end: Optional[int]) -> Iterator[Tuple[int, int, int, bytes]]:
        """(time, bag index, connection id, bytes) of every selected message, in time order."""
        streams = []
        for i, reader in enumerate(self.readers):
            ids = [cid for (b, cid) in self.routes if b == i]
            if ids:
                streams.append(((t, i, cid, data) for cid, t, data, _pos in reader.messages(ids, start, end)))
        return heapq.merge(*streams, key=lambda m: m[0])

    # -- output -------------------------------------------------------------------------

    def status(self, bag_ns: int, bag_start: int, bag_end: int, force: bool = False) -> None:
        if self.opts.quiet:
            return
        now = time.monotonic()
        if not force and now - self.last_status < STATUS_INTERVAL:
            return
        self.last_status = now
        state = "PAUSED " if self.paused else "RUNNING"
        self.out.write(f"\r [{state}]  Bag Time: {bag_ns / 1e9:13.6f}   Duration: "
                       f"{(bag_ns - bag_start) / 1e9:.6f} / {(bag_end - bag_start) / 1e9:.6f}"
                       "               \r")
        self.out.flush()

    def publish_clock(self, bag_ns: int) -> None:
        if self.clock_pub is not None:
            import minros
            from rosgraph_msgs.msg import Clock

            self.clock_pub.publish(Clock(minros.Time(bag_ns // 1_000_000_000, bag_ns % 1_000_000_000)))

    # -- waiting ------------------------------------------------------------------------

    def _keys(self, keyboard: Keyboard) -> None:
        for key in keyboard.read():
            if key == " ":
                self.paused = not self.paused
            elif key == "s" and self.paused:
                self.step = True

    def wait_until(self, target: float, bag_ns: int, tr: TimeTranslator, keyboard: Keyboard,
                   span: Tuple[int, int]) -> bool:
        """Sleep until wall time ``target`` (monotonic seconds), publishing the clock and
        honouring pause; returns False when shutdown came first."""
        clock_period = 1.0 / self.opts.hz if self.clock_pub is not None and self.opts.hz > 0 else None
        next_clock = time.monotonic()
        while True:
            if self.stop.is_set():
                return False
            self._keys(keyboard)
            now = time.monotonic()
            held = self.paused or (self.opts.rate_control_topic and
                                   now - self.last_rate_control > self.opts.rate_control_max_delay)
            if held:
                if self.step:
                    self.step = False
                    return True
                self.status(bag_ns, *span)
                pause_start = now
                self.stop.wait(0.01)
                tr.shift(time.monotonic() - pause_start)
                target += time.monotonic() - pause_start
                continue
            remaining = target - now
            if clock_period is not None and now >= next_clock:
                self.publish_clock(min(bag_ns, tr.bag_start + int((now - tr.real_start) * tr.rate * 1e9)))
                next_clock = now + clock_period
            if remaining <= 0:
                return True
            self.status(bag_ns, *span)
            if remaining > 0.002:
                nap = remaining - 0.001
                if clock_period is not None:
                    nap = min(nap, max(next_clock - now, 0.0))
                self.stop.wait(min(nap, 0.05))
            elif remaining > 0.0002:
                time.sleep(remaining / 2)
            # else: the last fraction of a millisecond is waited out in this loop

    # -- the run --------------------------------------------------------------------------

    def play_once(self, keyboard: Keyboard) -> bool:
        """One pass over the bags; False when shut down before the end."""
        bag_start, bag_end = self.time_range()
        start = bag_start + int(self.opts.start * 1e9)
        end = start + int(self.opts.duration * 1e9) if self.opts.duration else None
        span = (bag_start, bag_end)
        stream = self.messages(start, end)
        first = next(stream, None)  # reading the index and the first chunk is not playing time
        if first is None:
            return True
        tr = TimeTranslator(self.opts.rate)
        tr.set(start, time.monotonic())
        last_t: Optional[int] = None
        pause_topics = {t if t.startswith("/") else "/" + t for t in self.opts.pause_topics}
        routes = self.routes
        for t, i, cid, data in itertools.chain((first,), stream):
            if last_t is not None and self.opts.skip_empty is not None and \
                    (t - last_t) / 1e9 > self.opts.skip_empty:
                tr.shift(-((t - last_t) / 1e9 / self.opts.rate))
            last_t = t
            if not self.opts.immediate:
                if not self.wait_until(tr.real(t), t, tr, keyboard, span):
                    return False
            elif self.stop.is_set():
                return False
            self.publish_clock(t)
            pub, cls, topic = routes[(i, cid)]
            pub.publish(cls(data))
            if topic in pause_topics:
                self.paused = True
            self.status(t, *span)
        if last_t is not None:
            self.status(last_t, *span, force=True)
        return True

    def run(self) -> int:
        import minros

        minros.on_shutdown(self.stop.set)
        self.advertise()
        # rosbag's player prints these even with -q, which hides only the status line
        self.out.write(f"\nWaiting {self.opts.delay:.1f} seconds after advertising topics...")
        self.out.flush()
        if self.stop.wait(max(self.opts.delay, 0.0)):
            return 0
        self.out.write(" done.\n\n")
        if self.opts.wait_for_subscribers:
            self.out.write("Waiting for subscribers.\n")
            self.out.flush()
            while not all(p.get_num_connections() > 0 for p in self.publishers.values()):
                if self.stop.wait(0.05):
                    return 0
        self.out.write("Hit space to toggle paused, or 's' to step.\n")
        self.out.flush()
        keyboard = Keyboard()
        try:
            while True:
                if not self.play_once(keyboard):
                    break
                if not self.opts.loop:
                    break
            if not self.stop.is_set():
                self.out.write("\nDone.\n")
                self.out.flush()
            if self.opts.keep_alive:
                while not self.stop.wait(0.1):
                    pass
        finally:
            keyboard.restore()
        return 0


def play(opts: PlayOptions, argv: Optional[List[str]] = None) -> int:
    """Play the bags until their end (or Ctrl-C); returns the exit status."""
    import minros

    minros.init_node("play", argv=[sys.argv[0]] + [a for a in (argv or []) if ":=" in a],
                     anonymous=True)
    try:
        player = Player(opts)
        player.open()
        return player.run()
    finally:
        minros.signal_shutdown("playback done")


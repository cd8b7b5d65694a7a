"""tf2's transform buffer (``tf2::BufferCore``) in pure Python: no sockets, no threads.

The semantics are tf2's (geometry2 0.7, ROS Noetic), checked against Debian's C++ core:

* every child frame has one cache of (stamp, parent, translation, rotation) samples, kept
  sorted; samples older than the newest minus ``cache_time`` (10 s) are dropped; a frame set
  through ``set_transform_static`` gets a static cache whose one sample is valid at any time;
* ``lookup_transform(target, source, t)`` walks from both frames up to their common parent,
  interpolating every link at ``t`` (lerp of translation, slerp of rotation); a link with a
  single sample only matches its exact stamp; time 0 means the latest time for which every
  link of the chain has data (the "latest common time");
* errors are tf2's classes with tf2's texts (``LookupException``, ``ConnectivityException``,
  ``ExtrapolationException`` "...extrapolation into the past/future...",
  ``InvalidArgumentException``); a chain deeper than 1000 links is reported as a loop;
* insert checks: ``TF_SELF_TRANSFORM``, ``TF_NO_FRAME_ID``/``TF_NO_CHILD_FRAME_ID``,
  ``TF_NAN_INPUT``, ``TF_DENORMALIZED_QUATERNION`` (errors), ``TF_OLD_DATA`` and
  ``TF_REPEATED_DATA`` (warnings), each rate-limited per frame so that a misbehaving
  broadcaster does not flood the console.

Differences from tf2_py, on purpose: stamps are kept as integer nanoseconds (tf2_py converts
them through a float and loses up to ~100 ns on current wall-clock stamps, geometry2#543),
a cache keeps at most ``MAX_CACHE_LENGTH`` samples however fast a peer sends, and
``can_transform_full`` names a missing fixed frame (0.7.6 named the source frame twice).

Times given to the public methods are anything with ``secs``/``nsecs`` (rospy/genpy Time or
Duration) or with ``to_sec()``; results carry ``rospy.Time`` stamps.
"""

from __future__ import annotations

import logging
import math
import threading
import time as _time
from bisect import bisect_left, bisect_right
from typing import Any, Callable, Dict, Iterable, List, Optional, Tuple

from .exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)

NSEC_PER_SEC = 1_000_000_000
#: seconds of history a frame keeps (tf2::BufferCore::DEFAULT_CACHE_TIME)
DEFAULT_CACHE_TIME = 10
#: deeper chains are taken for a loop in the tree (tf2::BufferCore::MAX_GRAPH_DEPTH)
MAX_GRAPH_DEPTH = 1000
#: |q|^2 may differ from 1 by this much before a rotation is refused
QUATERNION_NORMALIZATION_TOLERANCE = 10e-3
#: samples one frame keeps at most, whatever the rate (tf2's MAX_LENGTH_LINKED_LIST)
MAX_CACHE_LENGTH = 1_000_000
#: seconds between two reports of the same insert problem for the same frame
WARNING_INTERVAL = 10.0

_TIME_MAX = 2 ** 64  # above any stamp: tf2's ros::TIME_MAX plays this role

# Result codes of a walk (tf2_msgs/TF2Error values).
NO_ERROR, LOOKUP_ERROR, CONNECTIVITY_ERROR, EXTRAPOLATION_ERROR = 0, 1, 2, 3
_ERROR_CLASSES = {LOOKUP_ERROR: LookupException, CONNECTIVITY_ERROR: ConnectivityException,
                  EXTRAPOLATION_ERROR: ExtrapolationException}

_OLD_DATA = ("TF_OLD_DATA ignoring data from the past (Possible reasons are listed at "
             "http://wiki.ros.org/tf/Errors%20explained)")
_REPEATED_DATA = "TF_REPEATED_DATA ignoring data with redundant timestamp"

# A sample is a tuple (parent_id, x, y, z, qx, qy, qz, qw): one allocation per insert.
Sample = Tuple[int, float, float, float, float, float, float, float]


def to_nsec(t: Any) -> int:
    """Integer nanoseconds of a rospy/genpy Time or Duration (or anything with ``to_sec``)."""
    try:
        return t.secs * NSEC_PER_SEC + t.nsecs
    except AttributeError:
        pass
    to_sec = getattr(t, "to_sec", None)
    if to_sec is None:
        raise TypeError("time must have a to_sec method, e.g. rospy.Time or rospy.Duration")
    return round(to_sec() * 1e9)


def _sec(ns: int) -> float:
    """``ros::Time::toSec()`` of a stamp: the same double C++ computes, for identical texts."""
    secs, nsecs = divmod(ns, NSEC_PER_SEC)
    return secs + nsecs * 1e-9


def _slerp(a: Sample, b: Sample, ratio: float) -> Tuple[float, float, float, float]:
    """tf2's slerp from a's rotation to b's: shortest path, inputs not renormalised."""
    ax, ay, az, aw = a[4], a[5], a[6], a[7]
    bx, by, bz, bw = b[4], b[5], b[6], b[7]
    dot = ax * bx + ay * by + az * bz + aw * bw
    s = math.sqrt((ax * ax + ay * ay + az * az + aw * aw) * (bx * bx + by * by + bz * bz + bw * bw))
    c = (-dot if dot < 0 else dot) / s
    theta = math.acos(1.0 if c > 1.0 else (-1.0 if c < -1.0 else c))
    if theta == 0.0:
        return ax, ay, az, aw
    d = 1.0 / math.sin(theta)
    s0 = math.sin((1.0 - ratio) * theta)
    s1 = math.sin(ratio * theta)
    if dot < 0:
        s1 = -s1
    return ((ax * s0 + bx * s1) * d, (ay * s0 + by * s1) * d,
            (az * s0 + bz * s1) * d, (aw * s0 + bw * s1) * d)


def _interpolate(a: Sample, b: Sample, ratio: float) -> Sample:
    s = 1.0 - ratio
    qx, qy, qz, qw = _slerp(a, b, ratio)
    return (a[0], s * a[1] + ratio * b[1], s * a[2] + ratio * b[2], s * a[3] + ratio * b[3],
            qx, qy, qz, qw)


class TimeCache:
    """The samples of one frame, oldest first (tf2::TimeCache)."""

    __slots__ = ("stamps", "samples", "max_storage")
    is_static = False

    def __init__(self, max_storage_ns: int) -> None:
        #: stamps in nanoseconds, ascending, no duplicates
        self.stamps: List[int] = []
        #: samples[i] was taken at stamps[i]
        self.samples: List[Sample] = []
        self.max_storage = max_storage_ns

    def insert(self, stamp: int, sample: Sample) -> Optional[str]:
        """Add a sample; return why it was refused (tf2's TF_OLD_DATA/TF_REPEATED_DATA text)."""
        stamps = self.stamps
        if not stamps:
            stamps.append(stamp)
            self.samples.append(sample)
            return None
        newest = stamps[-1]
        if newest > stamp + self.max_storage:
            return _OLD_DATA
        if stamp > newest:  # the usual case: data arrives in order
            stamps.append(stamp)
            self.samples.append(sample)
        else:
            i = bisect_left(stamps, stamp)
            if stamps[i] == stamp:
                return _REPEATED_DATA
            stamps.insert(i, stamp)
            self.samples.insert(i, sample)
        horizon = stamps[-1] - self.max_storage
        if stamps[0] < horizon:
            k = bisect_left(stamps, horizon)
            del stamps[:k]
            del self.samples[:k]
        if len(stamps) > MAX_CACHE_LENGTH:
            del stamps[:-MAX_CACHE_LENGTH]
            del self.samples[:-MAX_CACHE_LENGTH]
        return None

    def sample_at(self, t: int) -> Optional[Sample]:
        """The sample at time ``t`` (0: the newest), interpolated between neighbours; None
        when ``t`` is outside the buffered span (``explain`` says why)."""
        stamps = self.stamps
        n = len(stamps)
        if not n:
            return None
        if not t:
            return self.samples[-1]
        if n == 1:
            return self.samples[0] if stamps[0] == t else None
        newest = stamps[-1]
        if t == newest:
            return self.samples[-1]
        oldest = stamps[0]
        if t == oldest:
            return self.samples[0]
        if t > newest or t < oldest:
            return None
        i = bisect_right(stamps, t)
        samples = self.samples
        a = samples[i - 1]
        b = samples[i]
        if a[0] != b[0]:  # the parent changed between the two: no interpolation across it
            return a
        t0 = stamps[i - 1]
        return _interpolate(a, b, (t - t0) / (stamps[i] - t0))

    def parent_at(self, t: int) -> int:
        """The parent frame id at ``t`` without interpolating (0 when out of span)."""
        stamps = self.stamps
        n = len(stamps)
        if not n:
            return 0
        if not t or t == stamps[-1]:
            return self.samples[-1][0]
        if n == 1:
            return self.samples[0][0] if stamps[0] == t else 0
        if t > stamps[-1] or t < stamps[0]:
            return 0
        return self.samples[bisect_right(stamps, t) - 1][0]

    def explain(self, t: int) -> str:
        """tf2's extrapolation text for a ``t`` that ``sample_at`` refused ("" when empty)."""
        stamps = self.stamps
        if not stamps or not t:
            return ""
        if len(stamps) == 1:
            return (f"Lookup would require extrapolation at time {_sec(t):.9f}, but only time "
                    f"{_sec(stamps[0]):.9f} is in the buffer")
        if t > stamps[-1]:
            return (f"Lookup would require extrapolation {_sec(t - stamps[-1]):.9f}s into the "
                    f"future.  Requested time {_sec(t):.9f} but the latest data is at time "
                    f"{_sec(stamps[-1]):.9f}")
        if t < stamps[0]:
            return (f"Lookup would require extrapolation {_sec(stamps[0] - t):.9f}s into the "
                    f"past.  Requested time {_sec(t):.9f} but the earliest data is at time "
                    f"{_sec(stamps[0]):.9f}")
        return ""

    def latest(self) -> Tuple[int, int]:
        """(newest stamp, its parent), (0, 0) when empty."""
        if not self.stamps:
            return 0, 0
        return self.stamps[-1], self.samples[-1][0]

    def latest_stamp(self) -> int:
        return self.stamps[-1] if self.stamps else 0

    def oldest_stamp(self) -> int:
        return self.stamps[0] if self.stamps else 0

    def __len__(self) -> int:
        return len(self.stamps)

    def clear(self) -> None:
        self.stamps.clear()
        self.samples.clear()


class StaticCache:
    """The one sample of a frame from ``/tf_static``: valid at every time (tf2::StaticCache)."""

    __slots__ = ("sample",)
    is_static = True

    def __init__(self) -> None:
        self.sample: Sample = (0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)

    def insert(self, stamp: int, sample: Sample) -> Optional[str]:
        self.sample = sample
        return None

    def sample_at(self, t: int) -> Optional[Sample]:
        return self.sample

    def parent_at(self, t: int) -> int:
        return self.sample[0]

    def explain(self, t: int) -> str:
        return ""

    def latest(self) -> Tuple[int, int]:
        return 0, self.sample[0]

    def latest_stamp(self) -> int:
        return 0

    def oldest_stamp(self) -> int:
        return 0

    def __len__(self) -> int:
        return 1

    def clear(self) -> None:
        """Static data survives a clear, as in tf2."""


def _rotate(qx: float, qy: float, qz: float, qw: float,
            vx: float, vy: float, vz: float) -> Tuple[float, float, float]:
    """q v q* (tf2's quatRotate): for |q| != 1 the result is scaled by |q|^2, as in tf2."""
    k = qw * qw - (qx * qx + qy * qy + qz * qz)
    m = 2.0 * (qx * vx + qy * vy + qz * vz)
    w2 = 2.0 * qw
    return (k * vx + m * qx + w2 * (qy * vz - qz * vy),
            k * vy + m * qy + w2 * (qz * vx - qx * vz),
            k * vz + m * qz + w2 * (qx * vy - qy * vx))


def _matrix(q: Tuple[float, float, float, float]) -> List[List[float]]:
    """Rotation matrix of q, normalised on the way (tf2::Matrix3x3::setRotation)."""
    x, y, z, w = q
    s = 2.0 / (x * x + y * y + z * z + w * w)
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return [[1.0 - (yy + zz), xy - wz, xz + wy],
            [xy + wz, 1.0 - (xx + zz), yz - wx],
            [xz - wy, yz + wx, 1.0 - (xx + yy)]]


def _quaternion(m: List[List[float]]) -> Tuple[float, float, float, float]:
    """Quaternion of a rotation matrix with tf2's sign choice (Matrix3x3::getRotation):
    w > 0 when the trace is positive, else the component of the largest diagonal entry."""
    trace = m[0][0] + m[1][1] + m[2][2]
    q = [0.0, 0.0, 0.0, 0.0]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0)
        q[3] = s * 0.5
        s = 0.5 / s
        q[0] = (m[2][1] - m[1][2]) * s
        q[1] = (m[0][2] - m[2][0]) * s
        q[2] = (m[1][0] - m[0][1]) * s
    else:
        if m[0][0] < m[1][1]:
            i = 2 if m[1][1] < m[2][2] else 1
        else:
            i = 2 if m[0][0] < m[2][2] else 0
        j, k = (i + 1) % 3, (i + 2) % 3
        s = math.sqrt(m[i][i] - m[j][j] - m[k][k] + 1.0)
        q[i] = s * 0.5
        s = 0.5 / s
        q[3] = (m[k][j] - m[j][k]) * s
        q[j] = (m[j][i] + m[i][j]) * s
        q[k] = (m[k][i] + m[i][k]) * s
    return q[0], q[1], q[2], q[3]


class _Throttle:
    """At most one report per (problem, frame) per interval; the rest are counted."""

    def __init__(self, interval: float, clock: Callable[[], float]) -> None:
        self.interval = interval
        self.clock = clock
        self.last: Dict[Tuple[str, str], Tuple[float, int]] = {}

    def admit(self, key: Tuple[str, str]) -> Optional[int]:
        """None to stay silent, else how many reports were suppressed before this one."""
        now = self.clock()
        entry = self.last.get(key)
        if entry is not None and now - entry[0] < self.interval:
            self.last[key] = (entry[0], entry[1] + 1)
            return None
        self.last[key] = (now, 0)
        return 0 if entry is None else entry[1]


def _default_log(level: int, text: str) -> None:
    logging.getLogger("tf2").log(level, text)


class BufferCore:
    """tf2's BufferCore: the frame tree over time, thread-safe, no I/O of its own.

    ``log(level, text)`` receives tf2's insert warnings and errors (``logging`` levels);
    by default they go to the ``tf2`` logger. ``warning_interval`` rate-limits them per
    frame and problem (0 reports every one).
    """

    def __init__(self, cache_time: Any = None, *, log: Callable[[int, str], None] | None = None,
                 warning_interval: float = WARNING_INTERVAL,
                 clock: Callable[[], float] = _time.monotonic) -> None:
        if cache_time is None:
            cache_ns = DEFAULT_CACHE_TIME * NSEC_PER_SEC
        elif isinstance(cache_time, (int, float)):
            cache_ns = round(cache_time * 1e9)
        else:
            cache_ns = to_nsec(cache_time)
        self.cache_time_ns = cache_ns
        self.log = log or _default_log
        self._throttle = _Throttle(warning_interval, clock)
        self._reports: List[Tuple[int, str]] = []
        self._lock = threading.Lock()
        # Frame 0 is "NO_PARENT", the parent of nothing; caches[i] is None for a frame that
        # has only been seen as a parent.
        self._ids: Dict[str, int] = {"NO_PARENT": 0}
        self._names: List[str] = ["NO_PARENT"]
        self._caches: List[Any] = [None]
        self._authority: Dict[int, str] = {}
        self._time_class: Any = None
        self._msg_classes: Any = None

    # ------------------------------------------------------------------ inserting

    def set_transform(self, transform: Any, authority: str, is_static: bool = False) -> bool:
        """Insert a geometry_msgs/TransformStamped; False (and a log line) if refused."""
        with self._lock:
            ok = self._insert(transform, authority, is_static)
        if self._reports:
            self._emit_reports()
        return ok

    def set_transform_static(self, transform: Any, authority: str) -> bool:
        """Insert a transform valid at any time (what ``/tf_static`` carries)."""
        return BufferCore.set_transform(self, transform, authority, True)

    def set_transforms(self, transforms: Iterable[Any], authority: str, is_static: bool = False) -> None:
        """Insert every transform of a tf2_msgs/TFMessage under one lock (the listener's path)."""
        insert = self._insert
        with self._lock:
            for transform in transforms:
                insert(transform, authority, is_static)
        if self._reports:
            self._emit_reports()

    def _report(self, level: int, code: str, frame: str, text: str) -> None:
        """Queue a diagnostic unless rate-limited; ``_emit_reports`` logs it after the lock is
        released, so a slow log sink never holds up lookups."""
        suppressed = self._throttle.admit((code, frame))
        if suppressed is None:
            return
        if suppressed:
            text += (f" ({suppressed} more like this in the last "
                     f"{self._throttle.interval:g} s not shown)")
        self._reports.append((level, text))

    def _emit_reports(self) -> None:
        with self._lock:
            reports, self._reports = self._reports, []
        for level, text in reports:
            try:
                self.log(level, text)
            except Exception:  # a broken log sink must not break the receive thread
                pass

    def _insert(self, transform: Any, authority: str, is_static: bool) -> bool:
        header = transform.header
        parent = header.frame_id
        child = transform.child_frame_id
        if parent[:1] == "/":
            parent = parent[1:]
        if child[:1] == "/":
            child = child[1:]
        try:
            tr = transform.transform
            v = tr.translation
            x, y, z = float(v.x), float(v.y), float(v.z)
        except AttributeError:
            raise TypeError("transform.translation must have members x, y, z") from None
        try:
            r = tr.rotation
            qx, qy, qz, qw = float(r.x), float(r.y), float(r.z), float(r.w)
        except AttributeError:
            raise TypeError("transform.rotation must have members w, x, y, z") from None
        stamp = to_nsec(header.stamp)

        ok = True
        if child == parent:
            self._report(logging.ERROR, "TF_SELF_TRANSFORM", child,
                         f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" with '
                         f'frame_id and child_frame_id  "{child}" because they are the same')
            ok = False
        if not child:
            self._report(logging.ERROR, "TF_NO_CHILD_FRAME_ID", child,
                         f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" '
                         'because child_frame_id not set ')
            ok = False
        if not parent:
            self._report(logging.ERROR, "TF_NO_FRAME_ID", child,
                         f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child}"  from '
                         f'authority "{authority}" because frame_id not set')
            ok = False
        if x != x or y != y or z != z or qx != qx or qy != qy or qz != qz or qw != qw:
            self._report(logging.ERROR, "TF_NAN_INPUT", child,
                         f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child}" from '
                         f'authority "{authority}" because of a nan value in the transform '
                         f'({x:f} {y:f} {z:f}) ({qx:f} {qy:f} {qz:f} {qw:f})')
            ok = False
        if not abs(qw * qw + qx * qx + qy * qy + qz * qz - 1.0) < QUATERNION_NORMALIZATION_TOLERANCE:
            self._report(logging.ERROR, "TF_DENORMALIZED_QUATERNION", child,
                         f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id '
                         f'"{child}" from authority "{authority}" because of an invalid quaternion '
                         f'in the transform ({qx:f} {qy:f} {qz:f} {qw:f})')
            ok = False
        if not ok:
            return False

        ids = self._ids
        cid = ids.get(child)
        if cid is None:
            cid = self._add_frame(child)
        cache = self._caches[cid]
        if cache is None:
            cache = self._caches[cid] = (StaticCache() if is_static
                                         else TimeCache(self.cache_time_ns))
        pid = ids.get(parent)
        if pid is None:
            pid = self._add_frame(parent)
        problem = cache.insert(stamp, (pid, x, y, z, qx, qy, qz, qw))
        if problem is None:
            self._authority[cid] = authority
            return True
        code = problem.split(" ", 1)[0]
        self._report(logging.WARNING, code, child,
                     f"{problem} for frame {child} (parent {parent}) at time {_sec(stamp):f} "
                     f"according to authority {authority}")
        return False

    def _add_frame(self, name: str) -> int:
        fid = len(self._names)
        self._ids[name] = fid
        self._names.append(name)
        self._caches.append(None)
        return fid

    def clear(self) -> None:
        """Forget every non-static sample (frames and static data stay)."""
        with self._lock:
            for cache in self._caches:
                if cache is not None:
                    cache.clear()

    # ------------------------------------------------------------------ frame ids

    def _validate(self, function: str, frame: str) -> int:
        if not frame:
            raise InvalidArgumentException(
                f"Invalid argument passed to {function} in tf2 frame_ids cannot be empty")
        if frame[0] == "/":
            raise InvalidArgumentException(
                f'Invalid argument "{frame}" passed to {function} in tf2 frame_ids cannot start '
                "with a '/' like: ")
        fid = self._ids.get(frame, 0)
        if not fid:
            raise LookupException(f'"{frame}" passed to {function} does not exist. ')
        return fid

    def _warn_frame_id(self, function: str, frame: str) -> bool:
        """tf2's warnFrameId: True (after a warning) if ``frame`` is empty or starts with '/'."""
        if not frame:
            self._report(logging.WARNING, "INVALID_FRAME_ID", frame,
                         f"Invalid argument passed to {function} in tf2 frame_ids cannot be empty")
            return True
        if frame[0] == "/":
            self._report(logging.WARNING, "INVALID_FRAME_ID", frame,
                         f'Invalid argument "{frame}" passed to {function} in tf2 frame_ids '
                         "cannot start with a '/' like: ")
            return True
        return False

    # ------------------------------------------------------------------ walking the tree

    def _latest_common_time(self, target_id: int, source_id: int) -> Tuple[int, int, str]:
        """(code, time, error): the newest time at which the whole chain has data."""
        if not source_id or not target_id:
            return LOOKUP_ERROR, 0, ""
        caches = self._caches
        if source_id == target_id:
            cache = caches[source_id]
            return NO_ERROR, (cache.latest_stamp() if cache is not None else 0), ""
        # source to root: the (time, parent) of every link
        links: List[Tuple[int, int]] = []
        frame = source_id
        common = _TIME_MAX
        depth = 0
        while frame:
            cache = caches[frame]
            if cache is None:
                break
            stamp, parent = cache.latest()
            if not parent:
                break
            if stamp and stamp < common:
                common = stamp
            links.append((stamp, parent))
            frame = parent
            if frame == target_id:
                return NO_ERROR, (0 if common == _TIME_MAX else common), ""
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, 0, self._loop_text()
        # target to root, until a parent the source side also reached
        parents = {p for _, p in links}
        frame = target_id
        common = _TIME_MAX
        common_parent = 0
        depth = 0
        while True:
            cache = caches[frame]
            if cache is None:
                break
            stamp, parent = cache.latest()
            if not parent:
                break
            if stamp and stamp < common:
                common = stamp
            if parent in parents:
                common_parent = parent
                break
            frame = parent
            if frame == source_id:
                return NO_ERROR, (0 if common == _TIME_MAX else common), ""
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, 0, self._loop_text()
        if not common_parent:
            return CONNECTIVITY_ERROR, 0, self._connectivity_text(source_id, target_id)
        for stamp, parent in links:
            if stamp and stamp < common:
                common = stamp
            if parent == common_parent:
                break
        return NO_ERROR, (0 if common == _TIME_MAX else common), ""

    def _walk_transform(self, t: int, target_id: int, source_id: int):
        """Compose the chain source -> target at ``t`` (ids valid, different).

        Returns (NO_ERROR, t, (x, y, z, qx, qy, qz, qw)) or (code, 0, error text).
        """
        if not t:
            code, t, error = self._latest_common_time(target_id, source_id)
            if code:
                return code, 0, error
        caches = self._caches
        # source -> top, accumulating source-to-top
        sx = sy = sz = sqx = sqy = sqz = 0.0
        sqw = 1.0
        first = True
        frame = top = source_id
        failed = None  # the cache that could not serve t on the source side
        depth = 0
        while frame:
            if frame == target_id:
                return NO_ERROR, t, (sx, sy, sz, sqx, sqy, sqz, sqw)
            cache = caches[frame]
            if cache is None:
                top = frame
                break
            s = cache.sample_at(t)
            if s is None:
                top = frame
                failed = cache
                break
            _, x, y, z, ax, ay, az, aw = s
            if first:
                sx, sy, sz, sqx, sqy, sqz, sqw = x, y, z, ax, ay, az, aw
                first = False
            else:
                # v' = q v q* + t ; q' = q_link * q (written out here and in the target loop:
                # calling _rotate costs ~15 % more per link on a 10-link chain)
                k = aw * aw - (ax * ax + ay * ay + az * az)
                m = 2.0 * (ax * sx + ay * sy + az * sz)
                w2 = 2.0 * aw
                sx, sy, sz = (k * sx + m * ax + w2 * (ay * sz - az * sy) + x,
                              k * sy + m * ay + w2 * (az * sx - ax * sz) + y,
                              k * sz + m * az + w2 * (ax * sy - ay * sx) + z)
                sqx, sqy, sqz, sqw = (aw * sqx + ax * sqw + ay * sqz - az * sqy,
                                      aw * sqy + ay * sqw + az * sqx - ax * sqz,
                                      aw * sqz + az * sqw + ax * sqy - ay * sqx,
                                      aw * sqw - ax * sqx - ay * sqy - az * sqz)
            top = frame
            frame = s[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, 0, self._loop_text()
        # target -> top, accumulating target-to-top
        tx = ty = tz = tqx = tqy = tqz = 0.0
        tqw = 1.0
        first = True
        frame = target_id
        depth = 0
        while frame != top:
            if frame == source_id:
                sx = sy = sz = sqx = sqy = sqz = 0.0
                sqw = 1.0
                break
            cache = caches[frame]
            if cache is None:
                break
            s = cache.sample_at(t)
            if s is None:
                return EXTRAPOLATION_ERROR, 0, self._extrapolation(cache, t, source_id, target_id)
            _, x, y, z, ax, ay, az, aw = s
            if first:
                tx, ty, tz, tqx, tqy, tqz, tqw = x, y, z, ax, ay, az, aw
                first = False
            else:
                k = aw * aw - (ax * ax + ay * ay + az * az)
                m = 2.0 * (ax * tx + ay * ty + az * tz)
                w2 = 2.0 * aw
                tx, ty, tz = (k * tx + m * ax + w2 * (ay * tz - az * ty) + x,
                              k * ty + m * ay + w2 * (az * tx - ax * tz) + y,
                              k * tz + m * az + w2 * (ax * ty - ay * tx) + z)
                tqx, tqy, tqz, tqw = (aw * tqx + ax * tqw + ay * tqz - az * tqy,
                                      aw * tqy + ay * tqw + az * tqx - ax * tqz,
                                      aw * tqz + az * tqw + ax * tqy - ay * tqx,
                                      aw * tqw - ax * tqx - ay * tqy - az * tqz)
            frame = s[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, 0, self._loop_text()
        if frame != top and frame != source_id:
            if failed is not None:  # the source side stopped early: that is the real cause
                return EXTRAPOLATION_ERROR, 0, self._extrapolation(failed, t, source_id, target_id)
            return CONNECTIVITY_ERROR, 0, self._connectivity_text(source_id, target_id)
        # result = inverse(target-to-top) * source-to-top
        ix, iy, iz = -tqx, -tqy, -tqz
        vx, vy, vz = _rotate(ix, iy, iz, tqw, -tx, -ty, -tz)
        rx, ry, rz = _rotate(ix, iy, iz, tqw, sx, sy, sz)
        return NO_ERROR, t, (rx + vx, ry + vy, rz + vz,
                             tqw * sqx + ix * sqw + iy * sqz - iz * sqy,
                             tqw * sqy + iy * sqw + iz * sqx - ix * sqz,
                             tqw * sqz + iz * sqw + ix * sqy - iy * sqx,
                             tqw * sqw - ix * sqx - iy * sqy - iz * sqz)

    def _extrapolation(self, cache: Any, t: int, source_id: int, target_id: int) -> str:
        """tf2's ExtrapolationException text: why ``cache`` cannot serve ``t``, and the lookup."""
        return (f"{cache.explain(t)}, when looking up transform from frame "
                f"[{self._names[source_id]}] to frame [{self._names[target_id]}]")

    def _loop_text(self) -> str:
        return ("The tf tree is invalid because it contains a loop.\n"
                + self._frames_as_string() + "\n")

    def _connectivity_text(self, source_id: int, target_id: int) -> str:
        return (f"Could not find a connection between '{self._names[target_id]}' and "
                f"'{self._names[source_id]}' because they are not part of the same tree."
                "Tf has two or more unconnected trees.")

    def _walk_parents(self, t: int, target_id: int, source_id: int,
                      chain: Optional[List[int]] = None) -> Tuple[int, str]:
        """tf2's walk with parents only (canTransform), optionally recording the frame chain
        source ... target the way ``_chain`` reports it."""
        if chain is not None:
            chain.clear()
        if source_id == target_id:
            return NO_ERROR, ""
        if not t:
            code, t, error = self._latest_common_time(target_id, source_id)
            if code:
                return code, error
        caches = self._caches
        frame = top = source_id
        failed = None
        depth = 0
        while frame:
            cache = caches[frame]
            if chain is not None:
                chain.append(frame)
            if cache is None:
                top = frame
                break
            parent = cache.parent_at(t)
            if not parent:
                top = frame
                failed = cache
                break
            if frame == target_id:
                return NO_ERROR, ""
            top = frame
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, self._loop_text()
        frame = target_id
        depth = 0
        reverse: List[int] = []
        while frame != top:
            cache = caches[frame]
            if chain is not None:
                reverse.append(frame)
            if cache is None:
                break
            parent = cache.parent_at(t)
            if not parent:
                return EXTRAPOLATION_ERROR, self._extrapolation(cache, t, source_id, target_id)
            if frame == source_id:
                if chain is not None:
                    chain[:] = reverse[::-1]
                return NO_ERROR, ""
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return LOOKUP_ERROR, self._loop_text()
        if frame != top:
            if failed is not None:
                return EXTRAPOLATION_ERROR, self._extrapolation(failed, t, source_id, target_id)
            return CONNECTIVITY_ERROR, self._connectivity_text(source_id, target_id)
        if chain is not None:
            # both walks end at the common parent: keep it once, drop the shared tail
            reverse.append(frame)
            m, n = len(reverse) - 1, len(chain) - 1
            while m >= 0 and n >= 0 and chain[n] == reverse[m]:
                m -= 1
                n -= 1
            if n > 0:
                del chain[n + 2:]
            chain.extend(reverse[m::-1] if m >= 0 else [])
        return NO_ERROR, ""

    # ------------------------------------------------------------------ lookups

    def _result(self, target: str, source: str, t: int, r: Tuple[float, ...]) -> Any:
        """A geometry_msgs/TransformStamped (stamp a rospy.Time) from a walk's result."""
        classes = self._msg_classes
        if classes is None:
            import minros
            from geometry_msgs.msg import Quaternion, Transform, TransformStamped, Vector3
            from std_msgs.msg import Header

            classes = self._msg_classes = (TransformStamped, Header, Transform, Vector3,
                                           Quaternion, minros.Time)
        stamped, header, transform, vector3, quaternion, time_class = classes
        secs, nsecs = divmod(t, NSEC_PER_SEC)
        return stamped(header(0, time_class(secs, nsecs), target), source,
                       transform(vector3(r[0], r[1], r[2]), quaternion(r[3], r[4], r[5], r[6])))

    def _lookup(self, target_frame: str, source_frame: str, t: int) -> Tuple[int, Tuple[float, ...]]:
        """(stamp, (x, y, z, qx, qy, qz, qw)) of source in target at t; raises tf2's errors.
        Caller holds the lock."""
        if target_frame == source_frame:
            if not t:
                cache = self._caches[self._ids.get(target_frame, 0)]
                t = cache.latest_stamp() if cache is not None else 0
            return t, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        target_id = self._validate("lookupTransform argument target_frame", target_frame)
        source_id = self._validate("lookupTransform argument source_frame", source_frame)
        code, t, result = self._walk_transform(t, target_id, source_id)
        if code:
            raise _ERROR_CLASSES[code](result)
        return t, result

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """The transform taking data in ``source_frame`` to ``target_frame`` at ``time``
        (0: latest common time), as a geometry_msgs/TransformStamped."""
        t = to_nsec(time)
        with self._lock:
            t, r = self._lookup(target_frame, source_frame, t)
        return self._result(target_frame, source_frame, t, r)

    def lookup_transform_full_core(self, target_frame: str, target_time: Any, source_frame: str,
                                   source_time: Any, fixed_frame: str) -> Any:
        """Source at ``source_time`` to target at ``target_time``, through a frame that is
        fixed in time (tf2's advanced API)."""
        tt, st = to_nsec(target_time), to_nsec(source_time)
        with self._lock:
            self._validate("lookupTransform argument target_frame", target_frame)
            self._validate("lookupTransform argument source_frame", source_frame)
            self._validate("lookupTransform argument fixed_frame", fixed_frame)
            _, first = self._lookup(fixed_frame, source_frame, st)
            stamp, second = self._lookup(target_frame, fixed_frame, tt)
        # second * first through rotation matrices, as tf2::Transform composes them
        m2 = _matrix(second[3:])
        m1 = _matrix(first[3:])
        m = [[sum(m2[i][k] * m1[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
        v = first[:3]
        origin = tuple(m2[i][0] * v[0] + m2[i][1] * v[1] + m2[i][2] * v[2] + second[i]
                       for i in range(3))
        return self._result(target_frame, source_frame, stamp, origin + _quaternion(m))

    def can_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Tuple[bool, str]:
        """(possible, why not) for lookup_transform_core with the same arguments."""
        t = to_nsec(time)
        if target_frame == source_frame:
            return True, ""
        with self._lock:
            bad = (self._warn_frame_id("canTransform argument target_frame", target_frame)
                   or self._warn_frame_id("canTransform argument source_frame", source_frame))
        if bad:
            self._emit_reports()
            return False, ""
        with self._lock:
            target_id = self._ids.get(target_frame, 0)
            source_id = self._ids.get(source_frame, 0)
            if not target_id or not source_id:
                parts = []
                if not target_id:
                    parts.append(f"canTransform: target_frame {target_frame} does not exist.")
                if not source_id:
                    parts.append(f"canTransform: source_frame {source_frame} does not exist.")
                return False, " ".join(parts)
            code, error = self._walk_parents(t, target_id, source_id)
        return code == NO_ERROR, error

    def can_transform_full_core(self, target_frame: str, target_time: Any, source_frame: str,
                                source_time: Any, fixed_frame: str) -> Tuple[bool, str]:
        """(possible, why not) for lookup_transform_full_core with the same arguments."""
        tt, st = to_nsec(target_time), to_nsec(source_time)
        with self._lock:
            bad = any(self._warn_frame_id(f"canTransform argument {name}", frame)
                      for name, frame in (("target_frame", target_frame),
                                          ("source_frame", source_frame),
                                          ("fixed_frame", fixed_frame)))
        if bad:
            self._emit_reports()
            return False, ""
        with self._lock:
            target_id = self._ids.get(target_frame, 0)
            source_id = self._ids.get(source_frame, 0)
            fixed_id = self._ids.get(fixed_frame, 0)
            if not target_id or not source_id or not fixed_id:
                parts = []
                if not target_id:
                    parts.append(f"canTransform: target_frame {target_frame} does not exist.")
                if not source_id:
                    parts.append(f"canTransform: source_frame {source_frame} does not exist.")
                if not fixed_id:
                    parts.append(f"fixed_frame: {fixed_frame} does not exist.")
                return False, " ".join(parts)
            code, error = self._walk_parents(tt, target_id, fixed_id)
            if code == NO_ERROR:
                code, error = self._walk_parents(st, fixed_id, source_id)
        return code == NO_ERROR, error

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        """The newest time at which a lookup between the two frames can be answered."""
        import minros

        with self._lock:
            target_id = self._validate("get_latest_common_time", target_frame)
            source_id = self._validate("get_latest_common_time", source_frame)
            code, t, error = self._latest_common_time(target_id, source_id)
        if code:
            raise TransformException(error)
        return minros.Time(*divmod(t, NSEC_PER_SEC))

    # ------------------------------------------------------------------ introspection

    def _frames(self):
        """(id, name, cache, parent name) of every frame that has data."""
        names = self._names
        for cid in range(1, len(self._caches)):
            cache = self._caches[cid]
            if cache is None:
                continue
            sample = cache.sample_at(0)
            if sample is None:
                continue
            yield cid, names[cid], cache, names[sample[0]]

    def _frames_as_string(self) -> str:
        lines = []
        for cid in range(1, len(self._caches)):
            cache = self._caches[cid]
            if cache is None:
                continue
            sample = cache.sample_at(0)
            parent = self._names[sample[0]] if sample is not None else "NO_PARENT"
            lines.append(f"Frame {self._names[cid]} exists with parent {parent}.\n")
        return "".join(lines)

    def all_frames_as_string(self) -> str:
        """One line per frame: "Frame F exists with parent P."."""
        with self._lock:
            return self._frames_as_string()

    def all_frames_as_yaml(self, current_time: float = 0.0) -> str:
        """Every frame with its parent, broadcaster, rate and buffered span, as YAML."""
        out = []
        with self._lock:
            if len(self._caches) == 1:
                out.append("{}")
            for cid, name, cache, parent in self._frames():
                latest, oldest = cache.latest_stamp(), cache.oldest_stamp()
                rate = len(cache) / max(_sec(latest) - _sec(oldest), 0.0001)
                out.append(f"{name}: \n  parent: '{parent}'\n"
                           f"  broadcaster: '{self._authority.get(cid, 'no recorded authority')}'\n"
                           f"  rate: {rate:.3f}\n  most_recent_transform: {_sec(latest):.3f}\n"
                           f"  oldest_transform: {_sec(oldest):.3f}\n")
                if current_time > 0:
                    out.append(f"  transform_delay: {current_time - _sec(latest):.3f}\n")
                out.append(f"  buffer_length: {_sec(latest - oldest):.3f}\n")
        return "".join(out)

    def _allFramesAsDot(self, time: Any = None) -> str:  # noqa: N802 (tf2_py's name)
        """The frame tree in Graphviz's dot language (what tf's view_frames draws)."""
        current = _sec(to_nsec(time)) if time is not None else 0.0
        out = ["digraph G {\n"]
        legend = ('edge [style=invis];\n subgraph cluster_legend { style=bold; color=black; '
                  'label ="view_frames Result";\n')
        with self._lock:
            if len(self._caches) == 1:
                out.append('"no tf data recieved"')
            for cid, name, cache, parent in self._frames():
                latest, oldest = cache.latest_stamp(), cache.oldest_stamp()
                rate = len(cache) / max(_sec(latest) - _sec(oldest), 0.0001)
                out.append(f'"{parent}" -> "{name}"[label="Broadcaster: '
                           f'{self._authority.get(cid, "no recorded authority")}\\n'
                           f"Average rate: {rate:.3f} Hz\\nMost recent transform: {_sec(latest):.3f} ")
                if current > 0:
                    out.append(f"( {current - _sec(latest):.3f} sec old)")
                out.append(f'\\nBuffer length: {_sec(latest - oldest):.3f} sec\\n"];\n')
            for cid in range(1, len(self._caches)):
                cache = self._caches[cid]
                name = self._names[cid]
                if cache is None:
                    if current > 0:
                        out.append(f'{legend}"Recorded at time: {current:.3f}"[ shape=plaintext ] ;\n'
                                   f' }}->"{name}";\n')
                    continue
                sample = cache.sample_at(0)
                if sample is None or sample[0] == 0:
                    out.append(legend)
                    if current > 0:
                        out.append(f'"Recorded at time: {current:.3f}"[ shape=plaintext ] ;\n ')
                    out.append(f'}}->"{name}";\n')
        out.append("}")
        return "".join(out)

    def _chain(self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
               fixed_frame: str) -> List[str]:
        """The frames a full lookup passes through, source first."""
        tt, st = to_nsec(target_time), to_nsec(source_time)
        with self._lock:
            ids = self._ids
            source_id = ids.get(source_frame, 0)
            fixed_id = ids.get(fixed_frame, 0)
            target_id = ids.get(target_frame, 0)
            source_chain: List[int] = []
            code, error = self._walk_parents(st, fixed_id, source_id, source_chain)
            if code:
                raise _ERROR_CLASSES[code](error)
            target_chain: List[int] = []
            code, error = self._walk_parents(tt, target_id, fixed_id, target_chain)
            if code:
                raise _ERROR_CLASSES[code](error)
            if source_chain and target_chain and source_chain[-1] == target_chain[0]:
                source_chain.pop()
            return [self._names[i] for i in source_chain + target_chain]

    def _frameExists(self, frame_id: str) -> bool:  # noqa: N802 (tf2_py's name)
        with self._lock:
            return frame_id in self._ids

    def _getFrameStrings(self) -> List[str]:  # noqa: N802 (tf2_py's name)
        with self._lock:
            return self._names[1:]

    def frame_parent(self, frame_id: str, time: Any = None) -> Optional[str]:
        """The parent of ``frame_id`` at ``time`` (latest when None), None for a root or
        unknown frame."""
        t = to_nsec(time) if time is not None else 0
        with self._lock:
            cache = self._caches[self._ids.get(frame_id, 0)]
            parent = cache.parent_at(t) if cache is not None else 0
            return self._names[parent] if parent else None

"""The server side of the page's 3D view: tf into the fixed frame, and displays of topics.

:class:`SceneHub` (one per server, owned by the :class:`~minros.web.page.PageHub`) keeps tf:
one tap each on ``/tf`` and ``/tf_static`` while a page shows the view, a
:class:`~minros.tf.core.BufferCore`, and when each frame was last heard of (a frame not
refreshed for :data:`STALE_SECONDS` is drawn faded). :class:`SceneSession` (one per page) adds
the view's ops to the page's session:

=================  ==========================================================================
``scene_watch``    ``{fixed}``: ``scene_frames`` now and whenever tf changes (at most 20 a
                   second): every frame's pose in the fixed frame, its parent and age
``display_add``    ``{id, topic, kind?, max_points?}`` or ``{id, kind: "robot", param}``: reply
                   ``{kind, type}``, then the display's data (``scene_data`` JSON, or binary
                   frames for clouds, scans and grids) and ``scene_status`` when its status
                   changes; a topic not published yet is waited for when the page says its
                   kind; a cloud is sent thinned to ``max_points`` (0 or none: all its points)
``display_remove`` ``{id}``
``im_feedback``    ``{id, marker, control, event, pose}``: an interactive marker moved or
                   clicked in the page (pose in the fixed frame): published on the server's
                   ``feedback`` topic in the marker's own frame
=================  ==========================================================================

Every item of data carries the frame it is in (``frame``), that frame's pose in the fixed
frame at the message's stamp (``T``, looked up here with tf; the latest transform when the
data came before tf, or older than tf's 10 s) and ``fixed``, the fixed frame of ``T``; items
``locked`` to their frame (stamp 0, ``frame_locked`` markers, maps, interactive markers) follow
the frame's latest pose from ``scene_frames`` instead. A message that cannot be shown (unknown
frame, malformed cloud) gives its display an error status; nothing else changes.

Messages are decoded, converted (:mod:`minros.web.scenedata`) and placed in the page's writer
thread, when the display's slot is sent: the receive thread only queues, and a display the
page cannot keep up with keeps its newest message.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Dict, Hashable, List, Optional, Tuple

import minros
from minros.tf.core import BufferCore
from minros.tf.exceptions import ExtrapolationException, TransformException
from minros.web import assets, scenedata
from minros.web.rosbridge import OpError, _check
from minros.web.scenedata import DisplayError, json_text, pack
from minros.web.state import Incoming

#: a frame not refreshed for this long is stale (drawn faded); static frames never are
STALE_SECONDS = 5.0
#: frames sent to a page at most (a tf tree is tens to hundreds)
MAX_FRAMES = 2000
FRAMES_INTERVAL = 0.05
#: a /tf stamp this far older than the newest means time went back (a restarted simulation, a
#: looping bag): the buffer is cleared, as tf2_ros's listener clears its own when the clock
#: goes back
TIME_JUMP_NS = 1_000_000_000
#: displays one page may have
MAX_DISPLAYS = 64
TF_TOPIC, TF_STATIC_TOPIC, TF_TYPE = "/tf", "/tf_static", "tf2_msgs/TFMessage"
DEFAULT_ROBOT_PARAM = "/robot_description"

#: message types the view shows, and the kind of display for each
KINDS = {
    "visualization_msgs/Marker": "markers",
    "visualization_msgs/MarkerArray": "markers",
    "sensor_msgs/LaserScan": "scan",
    "sensor_msgs/PointCloud2": "cloud",
    "nav_msgs/OccupancyGrid": "grid",
    "nav_msgs/Path": "path",
    "geometry_msgs/PoseStamped": "pose",
    "geometry_msgs/PoseWithCovarianceStamped": "pose",
    "geometry_msgs/PoseArray": "pose_array",
    "nav_msgs/Odometry": "odometry",
    "geometry_msgs/PolygonStamped": "polygon",
    "visualization_msgs/InteractiveMarkerUpdate": "imarkers",
}
IM_UPDATE = "visualization_msgs/InteractiveMarkerUpdate"
#: messages a display's slot keeps for a page that does not read fast enough
QUEUE = {"markers": 1000, "odometry": 20}


@dataclass
class FrameInfo:
    parent: str
    received: float  # time.monotonic() of the last transform
    static: bool


def _tf_log(level: int, text: str) -> None:
    minros.logdebug(f"[web] tf: {text}")


class SceneHub:
    """tf for every page's 3D view (see the module doc)."""

    def __init__(self, state: Any, clock: Callable[[], float] = time.monotonic) -> None:
        self.state = state
        self.clock = clock
        self.buffer = BufferCore(log=_tf_log)
        self.frames: Dict[str, FrameInfo] = {}
        self.watchers: Dict[Hashable, Callable[[], None]] = {}
        self.lock = threading.Lock()
        self.tapped = False
        self.newest_ns = 0  # the newest stamp of /tf (a jump back clears the buffer)

    def watch(self, key: Hashable, on_change: Callable[[], None]) -> None:
        """Call ``on_change()`` (in the receive thread: queue only) whenever tf changes."""
        with self.lock:
            self.watchers[key] = on_change
            tap, self.tapped = not self.tapped, True
        if tap:
            for topic, static in ((TF_TOPIC, False), (TF_STATIC_TOPIC, True)):
                self.state.tap(topic, TF_TYPE, ("scene", "tf"),
                               lambda incoming, _static=static: self.receive(incoming, _static))

    def unwatch(self, key: Hashable) -> None:
        with self.lock:
            self.watchers.pop(key, None)
            untap = self.tapped and not self.watchers
            if untap:
                self.tapped = False
        if untap:
            for topic in (TF_TOPIC, TF_STATIC_TOPIC):
                self.state.untap(topic, ("scene", "tf"))

    def receive(self, incoming: Incoming, static: bool) -> None:
        """A TFMessage from /tf or /tf_static into the buffer."""
        try:
            msg = incoming.decoded()
        except Exception as exc:
            minros.logdebug(f"[web] tf: cannot decode a message on {incoming.tap.topic}: {exc}")
            return
        self.add(msg.transforms, incoming.header.get("callerid", "unknown_publisher"), static)

    def add(self, transforms: List[Any], authority: str, static: bool) -> None:
        if not static and transforms:
            stamp = transforms[0].header.stamp
            ns = stamp.secs * 1_000_000_000 + stamp.nsecs
            if ns < self.newest_ns - TIME_JUMP_NS:  # a simulation restarted, a bag looped
                minros.loginfo("[web] tf: time went back by "
                               f"{(self.newest_ns - ns) / 1e9:.1f} s: the 3D view forgets the "
                               "transforms it had (static ones stay)")
                self.buffer.clear()
                self.newest_ns = ns
            self.newest_ns = max(self.newest_ns, ns)
        self.buffer.set_transforms(transforms, authority, static)
        now = self.clock()
        with self.lock:
            for t in transforms:
                child = t.child_frame_id.lstrip("/")
                if child and (len(self.frames) < MAX_FRAMES or child in self.frames):
                    self.frames[child] = FrameInfo(t.header.frame_id.lstrip("/"), now, static)
            watchers = list(self.watchers.values())
        for on_change in watchers:
            on_change()

    def lookup(self, fixed: str, frame: str, stamp: Any = None) -> Tuple[List[float], str]:
        """(pose of ``frame`` in ``fixed`` at ``stamp``, a warning or ""); tf's exception when
        there is none. Data newer than the newest transform, or older than tf keeps, is
        placed with the latest transform (the warning says so for old data)."""
        frame = frame.lstrip("/")
        if not frame:
            raise TransformException("the message's header.frame_id is empty: set it to a tf "
                                     f"frame (e.g. {fixed})")
        try:
            return self._lookup(fixed, frame, stamp)
        except TransformException as exc:  # say which frames, as Rviz does
            raise type(exc)(f"No transform from [{frame}] to [{fixed}]: {exc}".strip()) from None

    def _lookup(self, fixed: str, frame: str, stamp: Any) -> Tuple[List[float], str]:
        zero = minros.Time(0, 0)
        if stamp is None or (stamp.secs == 0 and stamp.nsecs == 0):
            return scenedata.transform7(self.buffer.lookup_transform_core(fixed, frame, zero)), ""
        try:
            return scenedata.transform7(self.buffer.lookup_transform_core(fixed, frame, stamp)), ""
        except ExtrapolationException as exc:
            result = scenedata.transform7(self.buffer.lookup_transform_core(fixed, frame, zero))
            return result, (f"shown with the latest transform: {exc}" if "past" in str(exc) else "")

    def frames_json(self, fixed: str) -> Dict[str, Any]:
        """Every frame's latest pose in ``fixed`` (null when not connected to it), parent, age
        and whether it is stale; ``error`` when the fixed frame is unknown."""
        now = self.clock()
        with self.lock:
            known = dict(self.frames)
        present = set(known) | {info.parent for info in known.values() if info.parent}
        names = present | {fixed}
        out = []
        zero = minros.Time(0, 0)
        for name in sorted(names)[:MAX_FRAMES]:
            info = known.get(name)
            try:
                pose = scenedata.transform7(self.buffer.lookup_transform_core(fixed, name, zero))
            except TransformException:
                pose = None
            age = 0.0 if info is None or info.static else now - info.received
            out.append({"name": name, "parent": info.parent if info else "", "T": pose,
                        "age": round(age, 2), "stale": age > STALE_SECONDS,
                        "static": bool(info and info.static)})
        frame: Dict[str, Any] = {"op": "scene_frames", "fixed": fixed, "frames": out}
        if not known:
            frame["warning"] = ("no tf received yet: only data in the fixed frame "
                                f"[{fixed}] can be placed")
        elif fixed not in present:
            frame["error"] = f"Fixed Frame [{fixed}] does not exist"
        return frame


class Display:
    """One display of one page: a topic tapped, or the robot model of a parameter."""

    def __init__(self, session: SceneSession, display_id: str, kind: str, topic: str,
                 type_name: str) -> None:
        self.session = session
        self.id = display_id
        self.kind = kind
        self.topic = topic
        self.type = type_name
        self.status: Tuple[str, str] = ("", "")
        self.max_points = 0  # a cloud's points sent at most (0: all of them)
        self.slot = ("page", "scene", display_id)
        self.keys: List[Tuple[str, Hashable]] = []  # (topic, tap key) to untap
        self.imarkers: Optional[scenedata.InteractiveMarkerState] = None
        self.namespace = ""  # an interactive marker server's topic namespace
        self.im_lock = threading.Lock()

    # -- status ----------------------------------------------------------------------------

    def status_frame(self, level: str, text: str) -> List[str]:
        """The ``scene_status`` frame when the status changed, else nothing."""
        if (level, text) == self.status:
            return []
        self.status = (level, text)
        return [json_text({"op": "scene_status", "id": self.id, "level": level, "text": text})]

    # -- rendering (the page's writer thread) ----------------------------------------------

    def render(self, item: Any) -> List[Any]:
        try:
            frames, problems = self._render(item)
        except DisplayError as exc:
            return self.status_frame("error", str(exc))
        except TransformException as exc:
            return self.status_frame("error", _tf_text(exc))
        except Exception as exc:  # a message that does not decode, a peer's odd data
            return self.status_frame("error", f"{type(exc).__name__}: {exc}")
        if problems:
            return self.status_frame("warn", "; ".join(problems[:3]) + (
                f" (and {len(problems) - 3} more)" if len(problems) > 3 else "")) + frames
        return self.status_frame("ok", "") + frames

    def _render(self, item: Any) -> Tuple[List[Any], List[str]]:
        if self.kind == "imarkers":
            return self._render_imarkers()
        incoming: Incoming = item
        arrived = incoming.tap.type
        if arrived and KINDS.get(arrived) != self.kind:  # the topic came with another type
            raise DisplayError(f"{self.topic} is a {arrived}, not what a {self.kind} display "
                               "shows: remove this display and add the topic again")
        msg = incoming.decoded()
        fixed = self.session.fixed or ""
        hub = self.session.hub
        problems: List[str] = []
        base = {"id": self.id, "kind": self.kind, "fixed": fixed}
        if self.kind == "markers":
            markers = msg.markers if hasattr(msg, "markers") else [msg]
            return [self._markers_frame(markers, base, problems)], problems
        header = msg.header
        frame = header.frame_id
        T, warning = hub.lookup(fixed, frame, header.stamp)
        if warning:
            problems.append(warning)
        place = {"frame": frame.lstrip("/"), "T": T, "stamp": header.stamp.to_sec()}
        if self.kind in ("cloud", "scan"):
            # the arrays are the same for every page (only the placing differs): made once
            if self.kind == "cloud":
                max_points = self.max_points
                xyz, colors, info = incoming.cached(
                    ("scene", "cloud", max_points), lambda: scenedata.cloud_arrays(msg, max_points))
            else:
                xyz, colors, info = incoming.cached(("scene", "scan"), lambda: scenedata.scan_arrays(msg))
            arrays = [("position", xyz)] + ([("color", colors)] if colors is not None else [])
            return [pack({"op": "scene_data", **base, **place, "count": len(xyz), **info},
                         arrays)], problems
        if self.kind == "grid":
            meta, cells = scenedata.grid_cells(msg)
            place["locked"] = True  # a map follows its frame, as Rviz's Map display
            return [pack({"op": "scene_data", **base, **place, **meta}, [("cells", cells)])], problems
        if self.kind == "path":
            data = scenedata.path_json(msg)
        elif self.kind == "pose":
            pose = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
            data = {"pose": scenedata.pose7(pose)}
        elif self.kind == "odometry":
            data = {"pose": scenedata.pose7(msg.pose.pose), "child": msg.child_frame_id}
        elif self.kind == "pose_array":
            data = scenedata.pose_array_json(msg)
        elif self.kind == "polygon":
            data = scenedata.polygon_json(msg)
        else:
            raise DisplayError(f"no display for {self.type}")
        return [json_text({"op": "scene_data", **base, **place, **data})], problems

    def _markers_frame(self, markers: List[Any], base: Dict[str, Any],
                       problems: List[str]) -> str:
        hub, fixed = self.session.hub, self.session.fixed or ""
        placed: Dict[Tuple[str, int, int], Any] = {}
        items = []
        for marker in markers:
            try:
                entry = scenedata.marker_json(marker, self.session.mesh_url)
                if entry["action"] == scenedata.ADD:
                    stamp = marker.header.stamp
                    key = (marker.header.frame_id, stamp.secs, stamp.nsecs)
                    if key not in placed:
                        try:
                            placed[key] = hub.lookup(fixed, marker.header.frame_id, stamp)
                        except TransformException as exc:
                            placed[key] = exc
                    found = placed[key]
                    if isinstance(found, TransformException):
                        raise DisplayError(f"marker {marker.ns}/{marker.id}: {_tf_text(found)}")
                    entry.update(frame=marker.header.frame_id.lstrip("/"), T=found[0],
                                 locked=entry["frame_locked"] or (stamp.secs == 0 and stamp.nsecs == 0))
                    try:
                        json_text(entry)  # refuses NaN here, for this marker only
                    except DisplayError as exc:
                        raise DisplayError(f"marker {marker.ns}/{marker.id}: {exc}") from None
                items.append(entry)
            except DisplayError as exc:
                problems.append(str(exc))
        return json_text({"op": "scene_data", **base, "markers": items})

    # -- interactive markers ---------------------------------------------------------------

    def im_receive(self, incoming: Incoming, full: bool) -> None:
        try:
            msg = incoming.decoded()
        except Exception as exc:
            minros.logdebug(f"[web] {incoming.tap.topic}: cannot decode: {exc}")
            return
        with self.im_lock:
            state = self.imarkers
            changed = state.init(msg) if full else state.update(msg)
        if changed:
            self.session.page.outbox.put(self.slot, None)

    def _render_imarkers(self) -> Tuple[List[Any], List[str]]:
        hub, fixed = self.session.hub, self.session.fixed or ""
        with self.im_lock:
            markers = list(self.imarkers.markers.values()) if self.imarkers else []
        items, problems = [], []
        for marker in markers:
            try:
                entry = scenedata.imarker_json(marker, self.session.mesh_url)
                stamp = marker.header.stamp
                T, warning = hub.lookup(fixed, marker.header.frame_id, stamp)
                entry.update(frame=marker.header.frame_id.lstrip("/"), T=T,
                             locked=stamp.secs == 0 and stamp.nsecs == 0)
                json_text(entry)
                items.append(entry)
            except DisplayError as exc:
                problems.append(f"{marker.name}: {exc}")
            except TransformException as exc:
                problems.append(f"{marker.name}: {_tf_text(exc)}")
        base = {"op": "scene_data", "id": self.id, "kind": self.kind, "fixed": fixed}
        return [json_text({**base, "imarkers": items})], problems


def _tf_text(exc: Exception) -> str:
    text = str(exc)
    return text if text else type(exc).__name__


class SceneSession:
    """The 3D view's part of one page's session (see the module doc)."""

    def __init__(self, page: Any, hub: SceneHub) -> None:
        self.page = page
        self.hub = hub
        self.state = page.state
        self.fixed: Optional[str] = None
        self.displays: Dict[str, Display] = {}
        self.lock = threading.Lock()
        self.frames_slot = ("page", "scene_frames")
        self.feedback_count = 0
        self._urls: Dict[str, Tuple[Optional[str], Optional[str]]] = {}

    @property
    def ops(self) -> Dict[str, Callable[[Dict[str, Any]], None]]:
        return {"scene_watch": self.scene_watch, "display_add": self.display_add,
                "display_remove": self.display_remove, "im_feedback": self.im_feedback}

    def mesh_url(self, uri: str) -> Tuple[Optional[str], Optional[str]]:
        """The page's URL of a mesh URI (looked up once per session)."""
        found = self._urls.get(uri)
        if found is None:
            found = assets.page_url(uri)
            if len(self._urls) < 10_000:
                self._urls[uri] = found
        return found

    # -- the fixed frame -------------------------------------------------------------------

    def scene_watch(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "fixed", (str,))])
        fixed = msg["fixed"].strip().lstrip("/")
        if not fixed:
            raise OpError("the fixed frame is empty: name a tf frame (map, odom, base_link...)")
        changed = fixed != self.fixed
        self.fixed = fixed
        self.page.outbox.open_slot(self.frames_slot, lambda _token: json_text(
            self.hub.frames_json(self.fixed or fixed)), maxlen=1, min_interval=FRAMES_INTERVAL)
        self.hub.watch(self.page.key, self.frames_changed)
        self.frames_changed()
        if changed:  # interactive markers are placed again (the page re-places the rest)
            with self.lock:
                displays = [d for d in self.displays.values() if d.kind == "imarkers"]
            for display in displays:
                self.page.outbox.put(display.slot, None)
        self.page.reply(msg, fixed=fixed)

    def frames_changed(self) -> None:
        self.page.outbox.put(self.frames_slot, None)

    def tick(self) -> None:
        """Once a second: frames age even when tf is quiet."""
        if self.fixed is not None:
            self.frames_changed()

    # -- displays --------------------------------------------------------------------------

    def display_add(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "id", (str,)), (False, "topic", (str,)), (False, "kind", (str,)),
                     (False, "param", (str,)), (False, "max_points", (int,))])
        max_points = msg.get("max_points", 0)
        if isinstance(max_points, bool) or max_points < 0:
            raise OpError(f"display_add: max_points must be a number of points (0: all), not "
                          f"{max_points!r}")
        display_id = msg["id"]
        self.display_remove({"id": display_id})
        if len(self.displays) >= MAX_DISPLAYS:
            raise OpError(f"{MAX_DISPLAYS} displays are shown already: remove one first")
        if msg.get("kind") == "robot":
            self._add_robot(msg, display_id)
            return
        if "topic" not in msg:
            raise OpError("display_add needs a topic (or kind 'robot')")
        topic = minros.resolve_name(msg["topic"])
        self.page._allowed(topic)
        type_name = self.state.topic_type(topic)
        if type_name is None:
            # not published yet: wait for it, as Rviz does, with the kind the page expects
            kind = msg.get("kind")
            if kind not in set(KINDS.values()):
                self.page.fail(msg, f"topic {topic} does not exist (or has no type yet)")
                return
        else:
            kind = KINDS.get(type_name)
        if kind is None:
            self.page.fail(msg, f"{topic} is a {type_name}: the 3D view shows "
                                f"{', '.join(sorted(KINDS))}")
            return
        display = Display(self, display_id, kind, topic, type_name)
        display.max_points = max_points
        self.page.outbox.open_slot(display.slot, display.render, maxlen=QUEUE.get(kind, 1),
                                   max_bytes=64 << 20)
        with self.lock:
            self.displays[display_id] = display
        put = self.page.outbox.put
        if kind == "imarkers":
            namespace = topic[:-len("/update")] if topic.endswith("/update") else topic
            display.imarkers = scenedata.InteractiveMarkerState()
            display.namespace = namespace
            for name, type_, full in ((namespace + "/update_full",
                                       "visualization_msgs/InteractiveMarkerInit", True),
                                      (topic, type_name or IM_UPDATE, False)):
                key = (*self.page.key, "scene", display_id, name)
                display.keys.append((name, key))
                self.state.tap(name, type_, key,
                               lambda incoming, _full=full: display.im_receive(incoming, _full))
        else:
            key = (*self.page.key, "scene", display_id)
            display.keys.append((topic, key))
            slot = display.slot
            self.state.tap(topic, type_name, key,
                           lambda incoming: put(slot, incoming, incoming.size))
        self.page.reply(msg, kind=kind, type=type_name or "", topic=topic)

    def _add_robot(self, msg: Dict[str, Any], display_id: str) -> None:
        param = msg.get("param") or DEFAULT_ROBOT_PARAM
        display = Display(self, display_id, "robot", param, "urdf")
        with self.lock:
            self.displays[display_id] = display
        key = (*self.page.key, "scene", display_id)

        def send_robot() -> None:
            try:
                text = self.state.get_param(param)
            except KeyError:
                self.page.send({"op": "scene_status", "id": display_id, "level": "error",
                                "text": f"parameter {param} is not set: load the robot's URDF "
                                        "there (e.g. <param name=\"robot_description\" "
                                        "textfile=\"...\"/> or xacro)"})
                return
            except Exception as exc:
                self.page.send({"op": "scene_status", "id": display_id, "level": "error",
                                "text": f"cannot read parameter {param}: {exc}"})
                return
            if not isinstance(text, str):
                self.page.send({"op": "scene_status", "id": display_id, "level": "error",
                                "text": f"parameter {param} is a {type(text).__name__}, not a "
                                        "URDF text"})
                return
            try:
                robot = scenedata.robot_json(text, self.mesh_url)
            except DisplayError as exc:
                self.page.send({"op": "scene_status", "id": display_id, "level": "error",
                                "text": str(exc)})
                return
            problems = robot["problems"]
            self.page.send({"op": "scene_data", "id": display_id, "kind": "robot", "robot": robot})
            self.page.send({"op": "scene_status", "id": display_id,
                            "level": "warn" if problems else "ok", "text": "; ".join(problems[:3])})

        def on_params(changed: Dict[str, Any], removed: List[str]) -> None:
            prefix = param.rstrip("/") + "/"
            if any(name == param or name.startswith(prefix) for name in [*changed, *removed]):
                self.page._run_async(send_robot)
        self.state.add_param_listener(key, on_params)
        display.keys.append(("", key))
        self.page.reply(msg, kind="robot", type="urdf", param=param)
        self.page._run_async(send_robot)

    def display_remove(self, msg: Dict[str, Any]) -> None:
        with self.lock:
            display = self.displays.pop(msg.get("id"), None)
        if display is None:
            return
        for topic, key in display.keys:
            if topic:
                self.state.untap(topic, key)
            else:
                self.state.remove_param_listener(key)
        self.page.outbox.close_slot(display.slot)

    # -- interactive marker feedback -------------------------------------------------------

    def im_feedback(self, msg: Dict[str, Any]) -> None:
        from visualization_msgs.msg import InteractiveMarkerFeedback

        _check(msg, [(True, "id", (str,)), (True, "marker", (str,)), (False, "control", (str,)),
                     (True, "event", (int,)), (False, "pose", (list,)), (False, "menu", (int,))])
        display = self.displays.get(msg["id"])
        if display is None or display.imarkers is None:
            raise OpError(f"no interactive marker display {msg['id']}")
        with display.im_lock:
            marker = display.imarkers.markers.get(msg["marker"])
        if marker is None:
            raise OpError(f"interactive marker {msg['marker']} is not (or no longer) served")
        feedback = InteractiveMarkerFeedback()
        feedback.header.frame_id = marker.header.frame_id
        feedback.header.stamp = marker.header.stamp
        feedback.client_id = f"{minros.get_caller_id()}/page/{self.page.client_id}"
        feedback.marker_name = marker.name
        feedback.control_name = msg.get("control", "")
        feedback.event_type = msg["event"]
        feedback.menu_entry_id = int(msg.get("menu", 0))
        pose = msg.get("pose")
        if pose is not None:
            if len(pose) != 7 or not all(isinstance(v, (int, float)) for v in pose):
                raise OpError("im_feedback: pose must be 7 numbers [x, y, z, qx, qy, qz, qw]")
            frame_pose, _ = self.hub.lookup(self.fixed or "", marker.header.frame_id)
            local = scenedata.compose(scenedata.invert(frame_pose), [float(v) for v in pose])
        else:
            local = scenedata.pose7(marker.pose)
        p, q = feedback.pose.position, feedback.pose.orientation
        p.x, p.y, p.z, q.x, q.y, q.z, q.w = local
        topic = display.namespace + "/feedback"
        self.state.acquire_publisher(self.page, topic, InteractiveMarkerFeedback, queue_size=100)
        self.page.published.add(topic)
        self.state.publishers[topic].publish(feedback)
        self.feedback_count += 1

    # -- the end ---------------------------------------------------------------------------

    def close(self) -> None:
        self.hub.unwatch(self.page.key)
        with self.lock:
            ids = list(self.displays)
        for display_id in ids:
            self.display_remove({"id": display_id})

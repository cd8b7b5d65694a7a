"""The smach introspection protocol smach_viewer speaks, over three topics per server:

* ``<server>/smach/container_structure`` (smach_msgs/SmachContainerStructure): each
  container's children and internal edges, every 2 s;
* ``<server>/smach/container_status`` (smach_msgs/SmachContainerStatus): its initial and
  active states and its userdata, every 2 s and at each transition;
* ``<server>/smach/container_init`` (smach_msgs/SmachContainerInitialStatusCmd): a viewer
  sets a container's initial state and userdata.

Userdata travels as ROS's smach sends it: pickle (protocol 2) in base64 text in the
``local_data`` bytes. What arrives on ``container_init`` is decoded with a restricted
unpickler that builds only plain values (numbers, text, bytes, lists, tuples, dicts, sets):
unpickling a peer's data as ROS's smach does would run any code the peer chose.
"""

from __future__ import annotations

import base64
import binascii
import io
import pickle
import threading
import time
from typing import Any, Dict, List, Optional

import minros
from minros import smach
from smach_msgs.msg import (
    SmachContainerInitialStatusCmd,
    SmachContainerStatus,
    SmachContainerStructure,
)
from std_msgs.msg import Header

__all__ = ["IntrospectionClient", "IntrospectionServer", "encode_userdata", "decode_userdata"]

STATUS_TOPIC = "/smach/container_status"
INIT_TOPIC = "/smach/container_init"
STRUCTURE_TOPIC = "/smach/container_structure"
#: a container_init message's userdata is refused above this size (decoded)
MAX_INIT_DATA = 1 << 20


def encode_userdata(data: Dict[str, Any]) -> str:
    """``local_data`` as ROS's smach writes it; values that cannot be pickled are left out
    (with a debug line), so one odd value does not stop the status messages."""
    try:
        raw = pickle.dumps(data, 2)
    except Exception:  # noqa: BLE001 - any value may refuse pickling in its own way
        kept = {}
        for key, value in data.items():
            try:
                pickle.dumps(value, 2)
                kept[key] = value
            except Exception:  # noqa: BLE001
                minros.logdebug(f"smach introspection: userdata key '{key}' cannot be pickled")
        raw = pickle.dumps(kept, 2)
    return base64.b64encode(raw).decode("ascii")


class _PlainUnpickler(pickle.Unpickler):
    """Builds only the values pickle encodes without naming a class."""

    def find_class(self, module: str, name: str) -> Any:
        if module in ("builtins", "__builtin__") and name in ("set", "frozenset", "bytearray",
                                                             "complex", "slice"):
            return getattr(__import__("builtins"), name)
        if (module, name) == ("_codecs", "encode"):  # protocol 2's way of writing bytes
            import codecs
            return codecs.encode
        raise pickle.UnpicklingError(f"refusing to build {module}.{name}: only plain values "
                                     "are accepted in smach userdata from the network")


def decode_userdata(local_data: Any) -> Dict[str, Any]:
    """Userdata from a ``local_data`` field (base64 text of a pickle, or the raw pickle);
    raises ValueError naming what was wrong."""
    raw = bytes(local_data) if not isinstance(local_data, str) else local_data.encode("latin-1")
    if len(raw) > MAX_INIT_DATA * 2:
        raise ValueError(f"userdata of {len(raw)} bytes is over the {MAX_INIT_DATA} byte limit")
    try:
        raw = base64.b64decode(raw, validate=True)
    except (binascii.Error, ValueError):
        pass  # not base64: a pickle sent as raw bytes (ROS 2's smach does that)
    try:
        data = _PlainUnpickler(io.BytesIO(raw)).load()
    except Exception as exc:  # noqa: BLE001 - a peer's bytes: any failure is "bad input"
        raise ValueError(f"userdata is not a pickle of plain values: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"userdata must be a pickled dict, not {type(data).__name__}")
    return data


class ContainerProxy:
    """The introspection topics of one container of the tree."""

    def __init__(self, server_name: str, container: smach.Container, path: str,
                 update_rate: float = 2.0) -> None:
        self._path = path
        self._container = container
        self._update_rate = update_rate
        self._status_pub_lock = threading.Lock()
        self._stop = threading.Event()
        self._init_cmd = minros.Subscriber(server_name + INIT_TOPIC,
                                           SmachContainerInitialStatusCmd, self._init_cmd_cb)
        self._structure_pub = minros.Publisher(server_name + STRUCTURE_TOPIC,
                                               SmachContainerStructure, queue_size=1)
        self._status_pub = minros.Publisher(server_name + STATUS_TOPIC, SmachContainerStatus,
                                            queue_size=1)
        container.register_transition_cb(self._transition_cb)
        self._thread = threading.Thread(name=f"{server_name}:introspection{path}",
                                        target=self._heartbeat, daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        for endpoint in (self._init_cmd, self._structure_pub, self._status_pub):
            endpoint.unregister()

    def _heartbeat(self) -> None:
        while not self._stop.is_set() and not minros.is_shutdown():
            try:
                self._publish_structure("HEARTBEAT")
                self._publish_status("HEARTBEAT")
            except Exception as exc:  # noqa: BLE001 - e.g. shutdown under way
                if not minros.is_shutdown() and not self._stop.is_set():
                    minros.logerr(f"Publishing SMACH introspection messages failed: {exc}")
            self._stop.wait(self._update_rate)

    def structure_message(self) -> Any:
        edges = self._container.get_internal_edges()
        return SmachContainerStructure(
            header=Header(stamp=minros.Time.now()), path=self._path,
            children=list(self._container.get_children()),
            internal_outcomes=[str(o) for o, _, _ in edges],
            outcomes_from=[str(f) for _, f, _ in edges],
            outcomes_to=[str(t) for _, _, t in edges],
            container_outcomes=list(self._container.get_registered_outcomes()))

    def status_message(self, info: str = "") -> Any:
        return SmachContainerStatus(
            header=Header(stamp=minros.Time.now()), path=self._path,
            initial_states=self._container.get_initial_states(),
            active_states=self._container.get_active_states(),
            local_data=encode_userdata(dict(self._container.userdata._data)).encode("ascii"),
            info=info)

    def _publish_structure(self, info: str = "") -> None:
        self._structure_pub.publish(self.structure_message())

    def _publish_status(self, info: str = "") -> None:
        with self._status_pub_lock:
            self._status_pub.publish(self.status_message(info))

    def _transition_cb(self, *args: Any, **kwargs: Any) -> None:
        self._publish_status(f"{args}, {kwargs}")

    def _init_cmd_cb(self, msg: Any) -> None:
        if msg.path != self._path:
            return
        children = self._container.get_children()
        if not all(s in children for s in msg.initial_states):
            minros.logerr(f"Attempting to set initial state in container '{self._path}' to "
                          f"'{list(msg.initial_states)}', but this container only has states: "
                          f"{list(children)}")
            return
        try:
            data = decode_userdata(msg.local_data)
        except ValueError as exc:
            minros.logerr(f"smach introspection: ignoring the container_init message for "
                          f"'{self._path}': {exc}")
            return
        ud = smach.UserData()
        ud._data.update(data)
        self._container.set_initial_state(list(msg.initial_states), ud)
        self._publish_status("REMOTE_INIT")


class IntrospectionServer:
    """Publishes the introspection topics of a container and every container inside it
    (``path`` is the root's, usually '/SM_ROOT')."""

    def __init__(self, server_name: str, state: smach.Container, path: str) -> None:
        self._proxies: List[ContainerProxy] = []
        self._server_name = server_name
        self._state = state
        self._path = path

    def start(self) -> None:
        self.construct(self._server_name, self._state, self._path)

    def stop(self) -> None:
        for proxy in self._proxies:
            proxy.stop()

    def construct(self, server_name: str, state: smach.Container, path: str) -> None:
        proxy = ContainerProxy(server_name, state, path)
        prefix = "" if path == "/" else path
        for label, child in state.get_children().items():
            if isinstance(child, smach.Container):
                self.construct(server_name, child, f"{prefix}/{label}")
        proxy._publish_status("Initial state")
        proxy.start()
        self._proxies.append(proxy)

    def clear(self) -> None:
        self._proxies = []


class IntrospectionClient:
    """The viewer's side: find servers, set a container's initial state."""

    def get_servers(self) -> List[str]:
        """The names of the introspection servers on the master."""
        topics = minros.get_published_topics()
        return [t[: t.rfind(STATUS_TOPIC)] for t, kind in topics
                if kind == "smach_msgs/SmachContainerStatus"]

    def set_initial_state(self, server: str, path: str, initial_states: List[str],
                          initial_userdata: Optional[smach.UserData] = None,
                          timeout: Any = None) -> bool:
        """Ask ``server`` to start container ``path`` in ``initial_states``; with a
        ``timeout``, resend until the server's status shows it (True) or time runs out."""
        userdata = initial_userdata if initial_userdata is not None else smach.UserData()
        cmd = SmachContainerInitialStatusCmd(path=path, initial_states=list(initial_states),
                                             local_data=encode_userdata(userdata._data).encode())
        seen: Dict[str, Any] = {}

        def on_status(msg: Any) -> None:
            if msg.path == path:
                seen["msg"] = msg

        sub = minros.Subscriber(server + STATUS_TOPIC, SmachContainerStatus, on_status)
        pub = minros.Publisher(server + INIT_TOPIC, SmachContainerInitialStatusCmd, queue_size=1)
        try:
            pub.publish(cmd)
            if timeout is None:
                return False
            seconds = timeout.to_sec() if hasattr(timeout, "to_sec") else float(timeout)
            deadline = time.monotonic() + seconds
            while time.monotonic() < deadline and not minros.is_shutdown():
                pub.publish(cmd)
                msg = seen.get("msg")
                if msg is not None and all(s in msg.initial_states for s in initial_states):
                    try:
                        data = decode_userdata(msg.local_data)
                    except ValueError:
                        data = {}
                    if all(data.get(k) == v for k, v in userdata._data.items()):
                        return True
                time.sleep(0.3)
            return False
        finally:
            sub.unregister()
            pub.unregister()

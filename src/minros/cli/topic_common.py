"""What the ``rostopic`` commands and rostopic's Python API (:mod:`minros.cli.topic_api`)
share: the master client, the graph queries (a topic's type, also when the name goes on into a
field: ``/odom/pose/pose``), the tool's node, the clock and ``--filter`` expressions."""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Dict, Tuple

from minros import names
from minros.tools.common import ToolError
from minros.tools.master import Master

NAME = "rostopic"
#: How long ``rostopic pub -1`` stays up after publishing, so subscribers get the message.
ONCE_DELAY = 3.0
#: How long ``rostopic pub`` from a file or stdin waits for a first subscriber.
SUBSCRIBER_TIMEOUT = 5.0


def master_client() -> Master:
    return Master("/rostopic")


def checked_master() -> Master:
    master = master_client()
    master.getPid()
    return master


# ---------------------------------------------------------------------------------------------
# graph queries

def get_topic_list(master: Master) -> Tuple[list, list]:
    pubs, subs, _srvs = master.system_state()
    types = dict((t, ty) for t, ty in master.topic_types())
    return ([(t, types.get(t, "unknown type"), nodes) for t, nodes in pubs],
            [(t, types.get(t, "unknown type"), nodes) for t, nodes in subs])


def message_class(type_name: str) -> Any:
    from minros.msgs import get_message_class

    try:
        return get_message_class(type_name)
    except Exception:
        return None


def _nested_ok(cls: Any, path: str) -> bool:
    obj = cls()
    for part in path.split("/"):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            return False
    return True


def topic_type(master: Master, topic: str) -> Tuple[str | None, str | None, str]:
    """(type, real topic, field path) for ``topic`` which may name a field (``/pose/x``)."""
    types = master.topic_types()
    for name, type_name in types:
        if name == topic:
            return (None if type_name == names.ANYTYPE else type_name), name, ""
    candidates = sorted(((t, ty) for t, ty in types if topic.startswith(t + "/")), reverse=True)
    for name, type_name in candidates:
        field = topic[len(name) + 1:].rstrip("/").split("[")[0]
        if field == "":
            break
        cls = message_class(type_name)
        # a type not installed here is checked against its definition when messages arrive
        if cls is None or _nested_ok(cls, field):
            if type_name == names.ANYTYPE:
                return None, None, ""
            return type_name, name, topic[len(name):]
        continue
    return None, None, ""


def _field_error(master: Master, topic: str) -> str | None:
    """Why ``topic`` cannot be a field of a published topic of an installed type (or None)."""
    for name, type_name in sorted(master.topic_types(), reverse=True):
        if not topic.startswith(name + "/"):
            continue
        field = topic[len(name) + 1:].rstrip("/").split("[")[0]
        cls = message_class(type_name)
        if field and cls is not None and not _nested_ok(cls, field):
            return f"no field named [{field}] in topic [{name}] of type [{type_name}]"
    return None


def wait_topic_type(master: Master, topic: str) -> Tuple[str, str, str]:
    found = topic_type(master, topic)
    if found[0]:
        return found  # type: ignore[return-value]
    # a misspelt field of a topic that exists is an error, not something to wait for
    problem = _field_error(master, topic)
    if problem:
        raise ToolError(problem)
    sys.stderr.write(f"WARNING: topic [{topic}] does not appear to be published yet\n")
    sys.stderr.flush()
    from minros import node

    while not node.is_shutdown():
        found = topic_type(master, topic)
        if found[0]:
            return found  # type: ignore[return-value]
        if node.wait_for_shutdown(0.1):
            break
    raise KeyboardInterrupt


def init_tool_node(disable_rosout: bool = False) -> None:
    from minros.client.init import init_node

    init_node(NAME, argv=[sys.argv[0]] + [a for a in sys.argv[1:] if ":=" in a],
              anonymous=True, disable_rosout=disable_rosout)


def spin_until(done: Callable[[], bool], step: float = 0.1) -> None:
    from minros import node

    while not done():
        if node.wait_for_shutdown(step):
            return


def info_text(master: Master, topic: str) -> str:
    pubs, subs = get_topic_list(master)
    pubs = [x for x in pubs if x[0] == topic]
    subs = [x for x in subs if x[0] == topic]
    if not pubs and not subs:
        raise ToolError(f"Unknown topic {topic}")
    types = dict((t, ty) for t, ty in master.topic_types())
    uris: Dict[str, str | None] = {}

    def api(n: str) -> str:
        return master.lookup_node_cached(uris, n) or f"unknown address {n}"

    out = f"Type: {types.get(topic, 'unknown type')}\n\n"
    if pubs:
        out += "Publishers: \n" + "".join(f" * {n} ({api(n)})\n" for _, _, nodes in pubs for n in nodes)
    else:
        out += "Publishers: None\n"
    out += "\n"
    if subs:
        out += "Subscribers: \n" + "".join(f" * {n} ({api(n)})\n" for _, _, nodes in subs for n in nodes)
    else:
        out += "Subscribers: None\n"
    return out + "\n"


def ros_now() -> Any:
    from minros.msgs import Time

    try:
        from minros.client import rostime

        return rostime.get_rostime()
    except Exception:
        return Time.from_sec(time.time())


def compile_filter(expr: str | None) -> Callable | None:
    if not expr:
        return None
    try:
        code = compile(expr, "<filter>", "eval")
    except SyntaxError as exc:
        raise ToolError(f"invalid filter expression [{expr}]: {exc.msg}") from None

    def fn(m: Any, topic: str) -> bool:
        return bool(eval(code, {"__builtins__": __builtins__}, {"m": m, "topic": topic}))  # noqa: S307 - rostopic's documented --filter

    return fn

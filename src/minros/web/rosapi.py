"""rosapi, served by ``minros web`` itself: the introspection services roslibjs apps call.

Each handler takes a request message of a ``rosapi/*`` service type and returns the response,
computing it as rosbridge_suite's rosapi node (ROS 1 branch) does: topic lists from the
master's ``getTopicTypes`` and ``getSystemState`` (topics only subscribed to appear with their
type, unknown ones with ``""``), parameter values as JSON text, ``TypeDef`` lists for message
details. The ROS side is reached through a small backend object (see :class:`RosapiBackend`),
so the handlers run in tests without a master.
"""

from __future__ import annotations

import fnmatch
import inspect
import json
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Protocol, Sequence, Tuple

ATOMICS = ("bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
           "int64", "uint64", "float32", "float64", "string")
SPECIALS = ("time", "duration")
#: not-set default of rosapi's get_param: rospy.get_param(name, None)
_NO_DEFAULT = ""


@dataclass
class Graph:
    """One reading of the master: ``getTopicTypes`` and ``getSystemState``."""

    topic_types: Dict[str, str] = field(default_factory=dict)
    publishers: Dict[str, List[str]] = field(default_factory=dict)
    subscribers: Dict[str, List[str]] = field(default_factory=dict)
    services: Dict[str, List[str]] = field(default_factory=dict)

    def topics(self) -> List[str]:
        return sorted(set(self.publishers) | set(self.subscribers))

    def nodes(self) -> List[str]:
        names = set()
        for table in (self.publishers, self.subscribers, self.services):
            for ids in table.values():
                names.update(ids)
        return sorted(names)


class RosapiBackend(Protocol):
    def read_graph(self) -> Graph: ...
    def service_type(self, service: str) -> str: ...
    def service_uri(self, service: str) -> Optional[str]: ...
    def get_param(self, name: str, default: Any) -> Any: ...
    def set_param(self, name: str, value: Any) -> None: ...
    def has_param(self, name: str) -> bool: ...
    def delete_param(self, name: str) -> None: ...
    def search_param(self, name: str) -> Optional[str]: ...
    def get_param_names(self) -> List[str]: ...
    def now(self) -> Any: ...


def _matches(name: str, globs: Sequence[str]) -> bool:
    return not globs or any(fnmatch.fnmatch(name, g) for g in globs)


def _filter(names: Sequence[str], globs: Sequence[str]) -> List[str]:
    return [n for n in names if _matches(n, globs)]


# -- TypeDef -------------------------------------------------------------------------------

def _split(slot_type: str) -> Tuple[str, int]:
    if slot_type.endswith("]"):
        base, _, size = slot_type[:-1].partition("[")
        return base, int(size) if size else 0
    return slot_type, -1


def _constants(cls: type) -> Tuple[List[str], List[str]]:
    """Public non-field, non-method class attributes, by name (inspect.getmembers order)."""
    names, values = [], []
    instance = cls()
    for name, value in inspect.getmembers(instance):
        if name in cls.__slots__ or name.startswith("_") or inspect.isroutine(value):
            continue
        names.append(str(name))
        values.append(str(value))
    return names, values


def typedef_of(cls: type) -> Dict[str, Any]:
    """rosapi's TypeDef fields for one message class."""
    instance = cls()
    names, types, lengths, examples = [], [], [], []
    for name, slot_type in zip(cls.__slots__, cls._slot_types):
        base, length = _split(slot_type)
        names.append(name)
        types.append(base)
        lengths.append(length)
        if length >= 0:
            examples.append("[]")
        elif base not in ATOMICS:
            examples.append("{}")
        else:
            examples.append(str(getattr(instance, name)))
    constnames, constvalues = _constants(cls)
    return {"type": cls._type, "fieldnames": names, "fieldtypes": types,
            "fieldarraylen": lengths, "examples": examples, "constnames": constnames,
            "constvalues": constvalues}


def _special_typedef(name: str) -> Dict[str, Any]:
    return {"type": name, "fieldnames": ["secs", "nsecs"], "fieldtypes": ["int32", "int32"],
            "fieldarraylen": [-1, -1], "examples": ["0", "0"], "constnames": [],
            "constvalues": []}


def typedefs(cls: type, get_class: Callable[[str], type]) -> List[Dict[str, Any]]:
    """The TypeDef of ``cls`` followed by those of every type it contains (each once)."""
    seen: List[str] = []
    out: List[Dict[str, Any]] = []

    def visit_class(klass: type) -> None:
        td = typedef_of(klass)
        out.append(td)
        for field_type in td["fieldtypes"]:
            visit(field_type)

    def visit(type_name: str) -> None:
        if type_name in seen or type_name in ATOMICS:
            return
        seen.append(type_name)
        if type_name in SPECIALS:
            out.append(_special_typedef(type_name))
            return
        visit_class(get_class(type_name))

    visit_class(cls)
    return out


def typedef_messages(defs: List[Dict[str, Any]], typedef_class: type) -> List[Any]:
    return [typedef_class(**d) for d in defs]


# -- the services --------------------------------------------------------------------------

#: service name -> (rosapi service type, handler method)
SERVICES: Dict[str, Tuple[str, str]] = {
    "/rosapi/topics": ("rosapi/Topics", "topics"),
    "/rosapi/topics_for_type": ("rosapi/TopicsForType", "topics_for_type"),
    "/rosapi/topics_and_raw_types": ("rosapi/TopicsAndRawTypes", "topics_and_raw_types"),
    "/rosapi/services": ("rosapi/Services", "services"),
    "/rosapi/services_for_type": ("rosapi/ServicesForType", "services_for_type"),
    "/rosapi/nodes": ("rosapi/Nodes", "nodes"),
    "/rosapi/node_details": ("rosapi/NodeDetails", "node_details"),
    "/rosapi/action_servers": ("rosapi/GetActionServers", "action_servers"),
    "/rosapi/topic_type": ("rosapi/TopicType", "topic_type"),
    "/rosapi/service_type": ("rosapi/ServiceType", "service_type"),
    "/rosapi/publishers": ("rosapi/Publishers", "publishers"),
    "/rosapi/subscribers": ("rosapi/Subscribers", "subscribers"),
    "/rosapi/service_providers": ("rosapi/ServiceProviders", "service_providers"),
    "/rosapi/service_node": ("rosapi/ServiceNode", "service_node"),
    "/rosapi/service_host": ("rosapi/ServiceHost", "service_host"),
    "/rosapi/message_details": ("rosapi/MessageDetails", "message_details"),
    "/rosapi/service_request_details": ("rosapi/ServiceRequestDetails", "service_request_details"),
    "/rosapi/service_response_details": ("rosapi/ServiceResponseDetails", "service_response_details"),
    "/rosapi/set_param": ("rosapi/SetParam", "set_param"),
    "/rosapi/get_param": ("rosapi/GetParam", "get_param"),
    "/rosapi/has_param": ("rosapi/HasParam", "has_param"),
    "/rosapi/search_param": ("rosapi/SearchParam", "search_param"),
    "/rosapi/delete_param": ("rosapi/DeleteParam", "delete_param"),
    "/rosapi/get_param_names": ("rosapi/GetParamNames", "get_param_names"),
    "/rosapi/get_time": ("rosapi/GetTime", "get_time"),
}


class RosapiError(Exception):
    """A rosapi request that cannot be answered (the caller sees a failed service call)."""


class Rosapi:
    """The rosapi handlers over a backend; ``globs`` are rosapi's topics/services/params globs."""

    def __init__(self, backend: RosapiBackend, topics_glob: Sequence[str] = (),
                 services_glob: Sequence[str] = (), params_glob: Sequence[str] = ()) -> None:
        from minros.msgs import get_message_class, get_service_class

        self.backend = backend
        self.topics_glob = list(topics_glob)
        self.services_glob = list(services_glob)
        self.params_glob = list(params_glob)
        self._get_message_class = get_message_class
        self._get_service_class = get_service_class

    def service_class(self, name: str) -> type:
        return self._get_service_class(SERVICES[name][0])

    def handle(self, name: str, request: Any) -> Any:
        """Answer ``request`` for the rosapi service ``name``."""
        srv = self.service_class(name)
        values = getattr(self, SERVICES[name][1])(request)
        response = srv._response_class()
        for key, value in values.items():
            setattr(response, key, value)
        return response

    # topics
    def _topics_and_types(self) -> Tuple[List[str], List[str]]:
        graph = self.backend.read_graph()
        names = set(_filter(graph.topics(), self.topics_glob))
        known = [(t, ty) for t, ty in graph.topic_types.items() if t in names]
        pairs = known + [(t, "") for t in sorted(names - {t for t, _ in known})]
        return [t for t, _ in pairs], [ty for _, ty in pairs]

    def topics(self, req: Any) -> Dict[str, Any]:
        topics, types = self._topics_and_types()
        return {"topics": topics, "types": types}

    def topics_for_type(self, req: Any) -> Dict[str, Any]:
        graph = self.backend.read_graph()
        found = [t for t, ty in graph.topic_types.items() if ty == req.type]
        return {"topics": _filter(found, self.topics_glob)}

    def topics_and_raw_types(self, req: Any) -> Dict[str, Any]:
        topics, types = self._topics_and_types()
        texts = []
        for type_name in types:
            try:
                texts.append(self._get_message_class(type_name)._full_text)
            except Exception:
                texts.append("")
        return {"topics": topics, "types": types, "typedefs_full_text": texts}

    def topic_type(self, req: Any) -> Dict[str, Any]:
        if not _matches(req.topic, self.topics_glob):
            return {"type": ""}
        return {"type": self.backend.read_graph().topic_types.get(req.topic, "")}

    def publishers(self, req: Any) -> Dict[str, Any]:
        if not _matches(req.topic, self.topics_glob):
            return {"publishers": []}
        return {"publishers": self.backend.read_graph().publishers.get(req.topic, [])}

    def subscribers(self, req: Any) -> Dict[str, Any]:
        if not _matches(req.topic, self.topics_glob):
            return {"subscribers": []}
        return {"subscribers": self.backend.read_graph().subscribers.get(req.topic, [])}

    def action_servers(self, req: Any) -> Dict[str, Any]:
        topics, _types = self._topics_and_types()
        return {"action_servers": action_servers(topics)}

    # services and nodes
    def services(self, req: Any) -> Dict[str, Any]:
        return {"services": _filter(sorted(self.backend.read_graph().services), self.services_glob)}

    def _service_type(self, name: str) -> str:
        if not _matches(name, self.services_glob):
            return ""
        try:
            return self.backend.service_type(name) or ""
        except Exception:
            return ""

    def services_for_type(self, req: Any) -> Dict[str, Any]:
        names = _filter(sorted(self.backend.read_graph().services), self.services_glob)
        return {"services": [s for s in names if self._service_type(s) == req.type]}

    def service_type(self, req: Any) -> Dict[str, Any]:
        return {"type": self._service_type(req.service)}

    def service_providers(self, req: Any) -> Dict[str, Any]:
        providers: List[str] = []
        for name, nodes in sorted(self.backend.read_graph().services.items()):
            if self._service_type(name) == req.service:
                providers += nodes
        return {"providers": providers}

    def service_node(self, req: Any) -> Dict[str, Any]:
        nodes = self.backend.read_graph().services.get(req.service) or [""]
        return {"node": nodes[0]}

    def service_host(self, req: Any) -> Dict[str, Any]:
        uri = self.backend.service_uri(req.service)
        if not uri:
            return {"host": ""}
        rest = uri[len("rosrpc://"):] if uri.startswith("rosrpc://") else uri
        return {"host": rest.rpartition(":")[0] if ":" in rest else rest}

    def nodes(self, req: Any) -> Dict[str, Any]:
        return {"nodes": self.backend.read_graph().nodes()}

    def node_details(self, req: Any) -> Dict[str, Any]:
        graph = self.backend.read_graph()

        def of(table: Dict[str, List[str]]) -> List[str]:
            return sorted(name for name, ids in table.items() if req.node in ids)

        return {"subscribing": of(graph.subscribers), "publishing": of(graph.publishers),
                "services": of(graph.services)}

    # types
    def _typedefs(self, cls: type) -> List[Any]:
        typedef_class = self._get_message_class("rosapi/TypeDef")
        return typedef_messages(typedefs(cls, self._get_message_class), typedef_class)

    def message_details(self, req: Any) -> Dict[str, Any]:
        try:
            cls = self._get_message_class(req.type)
        except Exception as exc:
            raise RosapiError(f"unknown message type {req.type!r}: {exc}") from None
        return {"typedefs": self._typedefs(cls)}

    def _service(self, type_name: str) -> type:
        try:
            return self._get_service_class(type_name)
        except Exception as exc:
            raise RosapiError(f"unknown service type {type_name!r}: {exc}") from None

    def service_request_details(self, req: Any) -> Dict[str, Any]:
        return {"typedefs": self._typedefs(self._service(req.type)._request_class)}

    def service_response_details(self, req: Any) -> Dict[str, Any]:
        return {"typedefs": self._typedefs(self._service(req.type)._response_class)}

    # parameters (values are JSON text, as rosapi's)
    def _param_allowed(self, name: str) -> bool:
        return not self.params_glob or any(fnmatch.fnmatch(name, g) for g in self.params_glob)

    def set_param(self, req: Any) -> Dict[str, Any]:
        if not self._param_allowed(req.name):
            return {}
        try:
            value = json.loads(req.value)
        except ValueError:
            raise RosapiError("Due to the type flexibility of the ROS parameter server, the value "
                              "argument to set_param must be a JSON-formatted string.") from None
        self.backend.set_param(req.name, value)
        return {}

    def get_param(self, req: Any) -> Dict[str, Any]:
        if not self._param_allowed(req.name):
            return {"value": ""}
        default = None
        if req.default != _NO_DEFAULT:
            try:
                default = json.loads(req.default)
            except ValueError:
                default = req.default
        return {"value": json.dumps(self.backend.get_param(req.name, default))}

    def has_param(self, req: Any) -> Dict[str, Any]:
        return {"exists": self._param_allowed(req.name) and self.backend.has_param(req.name)}

    def delete_param(self, req: Any) -> Dict[str, Any]:
        if self._param_allowed(req.name) and self.backend.has_param(req.name):
            self.backend.delete_param(req.name)
        return {}

    def search_param(self, req: Any) -> Dict[str, Any]:
        if not self._param_allowed(req.name):
            return {"global_name": ""}
        return {"global_name": self.backend.search_param(req.name) or ""}

    def get_param_names(self, req: Any) -> Dict[str, Any]:
        return {"names": [n for n in self.backend.get_param_names() if self._param_allowed(n)]}

    def get_time(self, req: Any) -> Dict[str, Any]:
        return {"time": self.backend.now()}


def action_servers(topics: Sequence[str]) -> List[str]:
    """Namespaces that have all five actionlib topics (cancel, feedback, goal, result, status)."""
    wanted = {"cancel", "feedback", "goal", "result", "status"}
    found: Dict[str, set] = {}
    for topic in topics:
        namespace, _, leaf = topic.rpartition("/")
        if namespace and leaf in wanted:
            found.setdefault(namespace, set()).add(leaf)
    return sorted(ns for ns, leaves in found.items() if leaves == wanted)

"""The Foxglove WebSocket protocol (subprotocol ``foxglove.websocket.v1``): frame codecs.

Pure functions, no sockets. Binary frames start with a 1-byte opcode; integers are
little-endian. Text frames are JSON objects with an ``op``. For ROS 1 a channel's encoding is
``ros1``, its schema encoding ``ros1msg`` and its schema the ``message_definition`` text, and
message payloads are the TCPROS message bodies unchanged.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Set, Tuple

SUBPROTOCOL = "foxglove.websocket.v1"
ENCODING = "ros1"
SCHEMA_ENCODING = "ros1msg"

# server -> client binary opcodes
MESSAGE_DATA = 0x01
TIME = 0x02
SERVICE_CALL_RESPONSE = 0x03
FETCH_ASSET_RESPONSE = 0x04
# client -> server binary opcodes
CLIENT_MESSAGE_DATA = 0x01
SERVICE_CALL_REQUEST = 0x02

# status levels
INFO, WARNING, ERROR = 0, 1, 2

_MESSAGE_HEAD = struct.Struct("<BIQ")
_TIME = struct.Struct("<BQ")
_SERVICE_HEAD = struct.Struct("<BIII")
_ASSET_HEAD = struct.Struct("<BIBI")
FETCH_ASSET_SUCCESS, FETCH_ASSET_ERROR = 0, 1


class ProtocolError(ValueError):
    """A client frame that breaks the protocol; the text is what the client is told."""


# -- server -> client ----------------------------------------------------------------------

def message_data_head(subscription_id: int, receive_ns: int) -> bytes:
    """The 13 bytes before a message payload (opcode, subscription id, receive time)."""
    return _MESSAGE_HEAD.pack(MESSAGE_DATA, subscription_id, receive_ns)


def message_data(subscription_id: int, receive_ns: int, payload: bytes) -> bytes:
    return message_data_head(subscription_id, receive_ns) + bytes(payload)


def time_frame(ns: int) -> bytes:
    return _TIME.pack(TIME, ns)


def service_call_response(service_id: int, call_id: int, encoding: str, payload: bytes) -> bytes:
    enc = encoding.encode("utf-8")
    return _SERVICE_HEAD.pack(SERVICE_CALL_RESPONSE, service_id, call_id, len(enc)) + enc + bytes(payload)


def fetch_asset_response(request_id: int, data: Optional[bytes] = None,
                         error: str = "") -> bytes:
    """A fetchAsset answer: opcode, request id, status (0 success, 1 error), the error text's
    length and text, then the asset's bytes (success) or nothing."""
    if data is not None:
        return _ASSET_HEAD.pack(FETCH_ASSET_RESPONSE, request_id, FETCH_ASSET_SUCCESS, 0) + data
    text = error.encode("utf-8")
    return _ASSET_HEAD.pack(FETCH_ASSET_RESPONSE, request_id, FETCH_ASSET_ERROR, len(text)) + text


def dumps(obj: Mapping[str, Any]) -> str:
    return json.dumps(obj, separators=(",", ":"))


def server_info(name: str, capabilities: Sequence[str], session_id: str,
                metadata: Optional[Mapping[str, str]] = None) -> Dict[str, Any]:
    return {"op": "serverInfo", "name": name, "capabilities": list(capabilities),
            "supportedEncodings": [ENCODING], "metadata": dict(metadata or {}),
            "sessionId": session_id}


def status(level: int, message: str, status_id: Optional[str] = None) -> Dict[str, Any]:
    out: Dict[str, Any] = {"op": "status", "level": level, "message": message}
    if status_id is not None:
        out["id"] = status_id
    return out


def channel(channel_id: int, topic: str, type_name: str, definition: str) -> Dict[str, Any]:
    return {"id": channel_id, "topic": topic, "encoding": ENCODING, "schemaName": type_name,
            "schema": definition, "schemaEncoding": SCHEMA_ENCODING}


def advertise(channels: Iterable[Mapping[str, Any]]) -> Dict[str, Any]:
    return {"op": "advertise", "channels": list(channels)}


def unadvertise(channel_ids: Iterable[int]) -> Dict[str, Any]:
    return {"op": "unadvertise", "channelIds": list(channel_ids)}


def service(service_id: int, name: str, type_name: str, request_definition: str,
            response_definition: str) -> Dict[str, Any]:
    """A service as ``advertiseServices`` lists it: the ``request``/``response`` objects of the
    current spec and the older ``requestSchema``/``responseSchema`` strings (both are read)."""
    return {
        "id": service_id, "name": name, "type": type_name,
        "request": {"encoding": ENCODING, "schemaName": f"{type_name}Request",
                    "schemaEncoding": SCHEMA_ENCODING, "schema": request_definition},
        "response": {"encoding": ENCODING, "schemaName": f"{type_name}Response",
                     "schemaEncoding": SCHEMA_ENCODING, "schema": response_definition},
        "requestSchema": request_definition, "responseSchema": response_definition,
    }


def advertise_services(services: Iterable[Mapping[str, Any]]) -> Dict[str, Any]:
    return {"op": "advertiseServices", "services": list(services)}


def unadvertise_services(service_ids: Iterable[int]) -> Dict[str, Any]:
    return {"op": "unadvertiseServices", "serviceIds": list(service_ids)}


def service_call_failure(service_id: int, call_id: int, message: str) -> Dict[str, Any]:
    return {"op": "serviceCallFailure", "serviceId": service_id, "callId": call_id,
            "message": message}


def parameter(name: str, value: Any) -> Dict[str, Any]:
    """One entry of ``parameterValues``: ROS parameter values are XML-RPC values; binary ones
    travel as base64 with type ``byte_array``, floats are marked ``float64``."""
    import base64

    if isinstance(value, (bytes, bytearray)):
        return {"name": name, "value": base64.b64encode(bytes(value)).decode("ascii"),
                "type": "byte_array"}
    if isinstance(value, float):
        return {"name": name, "value": value, "type": "float64"}
    if isinstance(value, list) and value and all(isinstance(v, float) for v in value):
        return {"name": name, "value": value, "type": "float64_array"}
    return {"name": name, "value": value}


def parameter_values(params: Iterable[Tuple[str, Any]], request_id: Optional[str] = None) -> Dict[str, Any]:
    out: Dict[str, Any] = {"op": "parameterValues",
                           "parameters": [parameter(n, v) for n, v in params]}
    if request_id is not None:
        out["id"] = request_id
    return out


def parameter_from_client(entry: Mapping[str, Any]) -> Tuple[str, Any, bool]:
    """``(name, ROS value, delete)`` of a ``setParameters`` entry."""
    import base64

    name = entry.get("name")
    if not isinstance(name, str) or not name:
        raise ProtocolError("setParameters: every parameter needs a 'name' string")
    if "value" not in entry or entry["value"] is None:
        return name, None, True
    value = entry["value"]
    kind = entry.get("type")
    try:
        if kind == "byte_array":
            if not isinstance(value, str):
                raise ValueError
            return name, base64.b64decode(value, validate=True), False
        if kind == "float64":
            if isinstance(value, (str, bool)):
                raise ValueError
            return name, float(value), False
        if kind == "float64_array":
            if not isinstance(value, list) or any(isinstance(v, (str, bool)) for v in value):
                raise ValueError
            return name, [float(v) for v in value], False
    except (TypeError, ValueError, OverflowError):
        what = {"byte_array": "base64 text", "float64": "a number",
                "float64_array": "a list of numbers"}[kind]
        raise ProtocolError(f"setParameters: {name}: a {kind} value must be {what}") from None
    return name, value, False


GraphMap = Mapping[str, Set[str]]


def connection_graph_update(old: Tuple[GraphMap, GraphMap, GraphMap],
                            new: Tuple[GraphMap, GraphMap, GraphMap]) -> Optional[Dict[str, Any]]:
    """The ``connectionGraphUpdate`` that turns graph ``old`` into ``new`` (None: no change).

    A graph is (published topics -> publisher node names, subscribed topics -> subscriber
    names, services -> provider names).
    """
    (old_pub, old_sub, old_srv), (new_pub, new_sub, new_srv) = old, new
    published = [{"name": t, "publisherIds": sorted(ids)} for t, ids in sorted(new_pub.items())
                 if old_pub.get(t) != ids]
    subscribed = [{"name": t, "subscriberIds": sorted(ids)} for t, ids in sorted(new_sub.items())
                  if old_sub.get(t) != ids]
    services = [{"name": s, "providerIds": sorted(ids)} for s, ids in sorted(new_srv.items())
                if old_srv.get(s) != ids]
    removed_topics = sorted((set(old_pub) | set(old_sub)) - (set(new_pub) | set(new_sub)))
    removed_services = sorted(set(old_srv) - set(new_srv))
    if not (published or subscribed or services or removed_topics or removed_services):
        return None
    return {"op": "connectionGraphUpdate", "publishedTopics": published,
            "subscribedTopics": subscribed, "advertisedServices": services,
            "removedTopics": removed_topics, "removedServices": removed_services}


# -- client -> server ----------------------------------------------------------------------

@dataclass(frozen=True)
class ClientMessage:
    channel_id: int
    payload: memoryview


@dataclass(frozen=True)
class ServiceCallRequest:
    service_id: int
    call_id: int
    encoding: str
    payload: memoryview


def parse_binary(data: bytes) -> Any:
    """A client binary frame as ClientMessage or ServiceCallRequest; ProtocolError if malformed."""
    view = memoryview(data)
    if len(view) < 1:
        raise ProtocolError("empty binary message")
    opcode = view[0]
    if opcode == CLIENT_MESSAGE_DATA:
        if len(view) < 5:
            raise ProtocolError("client message data shorter than its 5-byte header")
        (channel_id,) = struct.unpack_from("<I", view, 1)
        return ClientMessage(channel_id, view[5:])
    if opcode == SERVICE_CALL_REQUEST:
        if len(view) < 13:
            raise ProtocolError("service call request shorter than its 13-byte header")
        service_id, call_id, enc_len = struct.unpack_from("<III", view, 1)
        if 13 + enc_len > len(view):
            raise ProtocolError("service call request: encoding length past the end of the message")
        encoding = bytes(view[13:13 + enc_len]).decode("utf-8", "replace")
        return ServiceCallRequest(service_id, call_id, encoding, view[13 + enc_len:])
    raise ProtocolError(f"Unrecognized client binary opcode {opcode}")


def parse_text(text: str) -> Dict[str, Any]:
    """A client JSON frame as a dict with a string ``op``; ProtocolError otherwise."""
    try:
        obj = json.loads(text)
    except ValueError as exc:
        raise ProtocolError(f"Invalid JSON message: {exc}") from None
    except RecursionError:  # json's C parser counts its depth against the recursion limit
        raise ProtocolError("Invalid JSON message: nested too deeply to read") from None
    if not isinstance(obj, dict) or not isinstance(obj.get("op"), str):
        raise ProtocolError("JSON message must be an object with a string 'op'")
    return obj


def int_list(obj: Mapping[str, Any], key: str) -> List[int]:
    value = obj.get(key)
    if not isinstance(value, list) or not all(type(v) is int and v >= 0 for v in value):
        raise ProtocolError(f"{obj.get('op')}: '{key}' must be a list of non-negative integers")
    return value


def str_list(obj: Mapping[str, Any], key: str, default: Optional[List[str]] = None) -> List[str]:
    value = obj.get(key, default)
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ProtocolError(f"{obj.get('op')}: '{key}' must be a list of strings")
    return value


def dict_list(obj: Mapping[str, Any], key: str) -> List[Dict[str, Any]]:
    value = obj.get(key)
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ProtocolError(f"{obj.get('op')}: '{key}' must be a list of objects")
    return value

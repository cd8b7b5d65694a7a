"""Fuzzing every parser a peer or a file feeds, with hypothesis: the XML-RPC request reader and
dispatcher (and the master's API behind it), the TCPROS connection-header decoder, message
deserializers, the .msg parser, launch XML and parameter YAML.

The property is always the same: hostile input ends in the parser's one documented error (or
a valid result), never another exception, a hang or an allocation the input only announced.
Example counts are bounded (``MINROS_FUZZ_EXAMPLES``, default 150 per test) so the suite stays
fast; raise it for a longer hunt. ``tests/unit/test_msgs_props.py`` and ``test_tcpros.py`` hold
the round-trip properties of the message classes and the framing.
"""

from __future__ import annotations

import os
import struct
import xmlrpc.client

import pytest
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from minros.exceptions import DeserializationError
from minros.launch.config import LaunchError
from minros.launch.loader import load_launch_string
from minros.launch.rosparam_yaml import load_yaml
from minros.master import CallbackPool, MasterHandler
from minros.msgs import get_message_class
from minros.msgs.spec import MsgSpecError, parse_msg, parse_srv
from minros.msgs.testing import strategy_for
from minros.wire import tcpros
from minros.wire import xmlrpc as mx

FUZZ = settings(max_examples=int(os.environ.get("MINROS_FUZZ_EXAMPLES", "150")), deadline=None,
                database=None, suppress_health_check=list(HealthCheck))

# --------------------------------------------------------------------------- XML-RPC

#: text XML can carry (no control characters, surrogates or non-characters)
XML_TEXT = st.text(st.characters(blacklist_categories=("Cc", "Cs", "Cn")), max_size=20)
#: values XML-RPC carries (ints within its 32 bits, no None: allow_none is off, as in ROS)
XMLRPC_VALUES = st.recursive(
    st.booleans() | st.integers(-(2 ** 31), 2 ** 31 - 1)
    | st.floats(allow_nan=False, allow_infinity=False) | XML_TEXT
    | st.binary(max_size=20).map(xmlrpc.client.Binary),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(XML_TEXT, inner, max_size=4),
    max_leaves=12)


class Echo:
    def echo(self, value):
        return value


def _response(payload: bytes):
    """Parse a server reply as a client would: the result, or the Fault."""
    try:
        (result,), _ = xmlrpc.client.loads(payload, use_builtin_types=False)
        return result
    except xmlrpc.client.Fault as fault:
        return fault


@FUZZ
@given(st.lists(st.binary(max_size=200), max_size=8))
def test_request_reader_takes_any_bytes(chunks):
    reader = mx.RequestReader(max_body=1000)
    try:
        for chunk in chunks:
            reader.received(chunk)
            while (body := reader.body()) is not None:
                assert len(body) == reader.head().length <= 1000
                reader.next_request()
    except mx._HttpError as err:
        assert err.status in (400, 404, 411, 413, 414, 431, 501, 505)


_HEAD_TOKENS = [b"POST", b"GET", b" ", b"/", b"/RPC2", b"HTTP/1.1", b"HTTP/1.0", b"HTTP/2", b"\r\n",
                b"\n", b"Content-Length:", b"content-length: ", b"5", b"-1", b"99999", b"x",
                b"Connection: close", b"Expect: 100-continue", b"Transfer-Encoding: chunked", b":"]


@FUZZ
@given(st.lists(st.sampled_from(_HEAD_TOKENS), max_size=40), st.integers(1, 7))
def test_request_reader_heads_any_chunking(tokens, step):
    data = b"".join(tokens) + b"\r\n\r\nhello"
    whole = mx.RequestReader(max_body=1000)
    whole.received(data)
    try:
        expected = whole.head()
    except mx._HttpError as err:
        expected = err.status
    pieces = mx.RequestReader(max_body=1000)
    got = None
    try:
        for i in range(0, len(data), step):  # the same bytes, trickled: the same answer
            pieces.received(data[i:i + step])
            if (got := pieces.head()) is not None:
                break
    except mx._HttpError as err:
        got = err.status
    if isinstance(expected, mx.RequestHead):
        assert isinstance(got, mx.RequestHead) and got.length == expected.length
    else:
        assert got == expected


@FUZZ
@given(XMLRPC_VALUES)
def test_dispatcher_round_trips_every_value(value):
    dispatcher = mx.Dispatcher(Echo())
    body = xmlrpc.client.dumps((value,), "echo", allow_none=False).encode()
    result = _response(dispatcher.handle_request_body(body))
    expected, _ = xmlrpc.client.loads(body, use_builtin_types=False)
    assert result == expected[0]


@FUZZ
@given(XMLRPC_VALUES, st.lists(st.tuples(st.integers(0, 10 ** 6), st.integers(0, 255)), max_size=6),
       st.integers(0, 10 ** 6))
def test_dispatcher_answers_every_mutated_call(value, flips, cut):
    body = bytearray(xmlrpc.client.dumps((value,), "echo", allow_none=False).encode())
    for pos, byte in flips:
        body[pos % len(body)] = byte
    del body[cut % (len(body) + 1):]
    reply = mx.Dispatcher(Echo()).handle_request_body(bytes(body))
    _response(reply)  # always a well-formed methodResponse: a result or a fault


_METHODS = ["getPid", "getUri", "setParam", "getParam", "deleteParam", "searchParam", "hasParam",
            "getParamNames", "subscribeParam", "unsubscribeParam", "registerPublisher",
            "unregisterPublisher", "registerSubscriber", "unregisterSubscriber", "registerService",
            "unregisterService", "lookupService", "lookupNode", "getPublishedTopics",
            "getTopicTypes", "getSystemState", "system.multicall", "nope", "_private"]
_NAMES = st.sampled_from(["/", "/a", "a", "~p", "/a/b/", "", "//", "/a b", "http://127.0.0.1:1/"])
_ARGS = st.one_of(_NAMES, XMLRPC_VALUES)


@pytest.fixture(scope="module")
def master_dispatcher():
    pool = CallbackPool(1, 0.01)
    yield mx.Dispatcher(MasterHandler(pool))
    pool.stop()


@FUZZ
@given(st.sampled_from(_METHODS), st.lists(_ARGS, max_size=5))
def test_master_api_answers_any_call(master_dispatcher, method, params):
    body = xmlrpc.client.dumps(tuple(params), method, allow_none=False).encode()
    result = _response(master_dispatcher.handle_request_body(body))
    if isinstance(result, xmlrpc.client.Fault) or method == "system.multicall":
        return
    assert isinstance(result, list) and len(result) == 3 and result[0] in (-1, 0, 1)
    assert isinstance(result[1], str)


# --------------------------------------------------------------------------- connection headers


@FUZZ
@given(st.binary(max_size=300))
def test_header_decoder_only_raises_header_error(block):
    try:
        fields = tcpros.decode_header(block)
    except tcpros.HeaderError:
        return
    assert all(isinstance(k, str) and isinstance(v, str) for k, v in fields.items())


@FUZZ
@given(st.dictionaries(st.text(min_size=1, max_size=12).filter(lambda k: "=" not in k),
                       st.text(max_size=40), max_size=8),
       st.lists(st.tuples(st.integers(0, 10 ** 5), st.integers(0, 255)), max_size=4))
def test_header_round_trip_and_mutations(fields, flips):
    data = tcpros.encode_header(fields)
    assert tcpros.read_header_block(data) == (fields, len(data))
    mutated = bytearray(data)
    for pos, byte in flips:
        mutated[pos % len(mutated)] = byte
    try:
        parsed = tcpros.read_header_block(bytes(mutated), max_size=1 << 16)
    except tcpros.HeaderError:
        return
    assert parsed is None or parsed[1] <= len(mutated)


# --------------------------------------------------------------------------- messages

_MESSAGE_TYPES = ["sensor_msgs/Image", "sensor_msgs/PointCloud2", "nav_msgs/Path",
                  "visualization_msgs/MarkerArray", "diagnostic_msgs/DiagnosticArray",
                  "trajectory_msgs/JointTrajectory", "rosgraph_msgs/Log", "tf2_msgs/TFMessage"]


@pytest.mark.parametrize("type_name", _MESSAGE_TYPES)
@FUZZ
@given(data=st.data())
def test_deserializers_survive_mutated_messages(type_name, data):
    """A real message with bytes flipped, lengths inflated to 2**32-1 or cut short: the class
    raises DeserializationError (or reads some other valid message), allocating nothing the
    bytes do not hold."""
    cls = get_message_class(type_name)
    wire = bytearray(data.draw(strategy_for(type_name)).serialize_to_bytes())
    assume(len(wire) >= 4)
    for _ in range(data.draw(st.integers(0, 3))):
        pos = data.draw(st.integers(0, len(wire) - 4))
        if data.draw(st.booleans()):
            wire[pos:pos + 4] = struct.pack("<I", data.draw(st.sampled_from([2 ** 32 - 1, 2 ** 31, 1 << 24])))
        else:
            wire[pos] = data.draw(st.integers(0, 255))
    wire = wire[:data.draw(st.integers(0, len(wire)))]
    try:
        msg = cls().deserialize(bytes(wire))
    except DeserializationError:
        return
    assert all(hasattr(msg, name) for name in cls.__slots__)


# --------------------------------------------------------------------------- .msg definitions


@FUZZ
@given(st.lists(st.text(max_size=30), max_size=12))
def test_msg_parser_takes_any_text(lines):
    text = "\n".join(lines)
    for parse, name in ((parse_msg, "pkg/Fuzz"), (parse_srv, "pkg/FuzzSrv")):
        try:
            parse(text, name, "Fuzz.msg")
        except MsgSpecError as exc:
            assert exc.filename == "Fuzz.msg" and exc.lineno >= 1
            assert "\n" not in str(exc).strip()


# --------------------------------------------------------------------------- launch XML

_TAGS = ["launch", "node", "param", "rosparam", "arg", "group", "include", "remap", "env",
         "machine", "test", "bogus"]
_ATTRS = ["name", "pkg", "type", "value", "default", "ns", "if", "unless", "file", "command",
          "output", "respawn", "required", "args", "from", "to", "textfile", "subst_value"]
_VALUES = st.sampled_from(["", "x", "/a", "true", "false", "1", "$(arg x)", "$(find rospy)",
                           "$(env HOME)", "$(optenv NOPE d)", "$(anon n)", "$(eval 1+1)",
                           "$(bogus)", "$(arg", "screen", "log", "a: 1", "[1, 2", "&amp;", "<"])


def _element(depth: int):
    attrs = st.dictionaries(st.sampled_from(_ATTRS), _VALUES, max_size=4)
    children = st.lists(st.deferred(lambda: _element(depth - 1)), max_size=3) if depth else st.just([])
    return st.builds(lambda tag, a, kids, text: (tag, a, kids, text), st.sampled_from(_TAGS),
                     attrs, children, st.sampled_from(["", "a: 1", "x", "- 1"]))


def _render(element) -> str:
    tag, attrs, children, text = element
    attr_text = "".join(f' {k}="{xmlrpc.client.escape(v)}"' for k, v in attrs.items())
    inner = xmlrpc.client.escape(text) + "".join(_render(c) for c in children)
    return f"<{tag}{attr_text}>{inner}</{tag}>"


@FUZZ
@given(st.lists(_element(2), max_size=4), st.booleans())
def test_launch_loader_takes_any_launch_tree(children, raw_break):
    text = "<launch>" + "".join(_render(c) for c in children) + "</launch>"
    if raw_break:
        text = text[:len(text) // 2]
    try:
        load_launch_string(text, filename="fuzz.launch", env={"HOME": "/tmp"}, run_commands=False)
    except LaunchError as exc:
        assert str(exc)


@FUZZ
@given(st.binary(max_size=200))
def test_launch_loader_takes_any_bytes(data):
    try:
        load_launch_string(data.decode("utf-8", "replace"), filename="fuzz.launch", env={},
                           run_commands=False)
    except LaunchError:
        pass


# --------------------------------------------------------------------------- parameter YAML


@FUZZ
@given(st.text(max_size=200))
def test_rosparam_yaml_takes_any_text(text):
    try:
        load_yaml(text)
    except ValueError as exc:
        assert "\n" not in str(exc)


_YAML_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-(2 ** 31), 2 ** 31 - 1)
    | st.floats(allow_nan=False) | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12)


@FUZZ
@given(_YAML_VALUES)
def test_rosparam_yaml_round_trips_values(value):
    assert load_yaml(yaml.safe_dump(value)) == value

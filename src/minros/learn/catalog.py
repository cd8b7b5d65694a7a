"""The exercises of ``minros learn``, as data, and their checkers (pure functions).

Each exercise starts what it needs (a master or two, small nodes from
:mod:`minros.learn.actors`, ``minros zenoh`` bridges, traced into the exercise's folder), asks one
question the wire answers, and checks the learner's answer against the learner's own trace
(``me*.jsonl`` in the folder) and the traces of what it started. A wrong answer gets a hint
that names what the answer was instead (a port where a URI was asked, the other side's
md5sum, ...) and where to look.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import math
import random
import re
import struct
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from minros.learn.evidence import Conn, calls, connections, latency, node_names, replied
from minros.learn.model import Attempt, Exercise, Process, Result, same_uri

__all__ = ["EXERCISES", "STRING_MD5"]

STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"
_HEX32 = re.compile(r"^[0-9a-f]{32}$")


def _master(which: str = "a") -> Process:
    port = "{port}" if which == "a" else "{port_b}"
    name = "master" if which == "a" else "master_b"
    return Process(name, ("minros", "core", "-p", port), master=which, ready=("master",))


def _actor(name: str, role: str, *args: str, ready: Tuple[str, ...] = (), master: str = "a",
           **more: Any) -> Process:
    return Process(name, ("minros.learn.actors", role, *args), master=master, ready=ready, **more)


def _zenoh_bridge(name: str, which: str, *endpoints: str, ready: Tuple[str, ...]) -> Process:
    """``minros zenoh`` on master ``which``, on loopback only: a Zenoh peer listens on every
    interface unless told where, and finds others by UDP multicast unless told not to.

    Untraced: a bridge asks its master for the graph ten times a second, which would add
    some 50 kB/s to its trace; what it does on the wire with the talker, the master and the
    learner, the traces of those show from their side (its calls as served)."""
    return Process(name, ("minros", "zenoh", *endpoints, "--no-multicast-scouting"),
                   master=which, ready=ready, traced=False, node="/minros_zenoh")


def _zenoh_missing() -> str:
    """What the zenoh variant lacks here: the eclipse-zenoh package (minros.zenoh.available,
    which this layer may not import, asks the same), found without importing it."""
    try:
        found = importlib.util.find_spec("zenoh") is not None
    except (ImportError, ValueError):  # a broken or None entry in sys.modules
        found = False
    return "" if found else ("the Zenoh bridge needs the eclipse-zenoh package, which minros "
                             "installs as an extra: pip install minros[zenoh]")


def _no_trace(a: Attempt, what: str) -> Result:
    return Result(False, f"Your trace ({a.facts.get('me', 'me.jsonl')}) has no {what} yet.",
                  hint="Run the traced command the task shows (minros learn "
                       f"{a.facts.get('number', 'N')} prints it again), then check again.")


def _words_or_ask(a: Attempt, form: str) -> Optional[Result]:
    if a.words:
        return None
    return Result(False, "Give your answer after the exercise's number.",
                  hint=f"minros learn check {a.facts.get('number', 'N')} {form}")


def _port_of(text: str) -> str:
    return text.rstrip("/").rpartition(":")[2]


# --------------------------------------------------------------------------- 1


def _check_register_subscriber(a: Attempt) -> Result:
    regs = [ev for ev in calls(a.mine, "registerSubscriber", "/chatter") if replied(ev)]
    if not regs:
        return _no_trace(a, "registerSubscriber call for /chatter with its answer")
    reg = regs[-1]
    code, status, uris = replied(reg)  # type: ignore[misc]
    uris = [str(u) for u in uris] if isinstance(uris, list) else []
    if not uris:
        return Result(False, "The master answered your registerSubscriber with no publisher.",
                      hint="Was the exercise still running (minros learn 1)? Subscribe again.")
    asked = _words_or_ask(a, "URI...")
    if asked:
        return asked
    own = str(reg["args"][3]) if len(reg.get("args", [])) > 3 else ""
    data_ports = {str(r[2][2]) for ev in calls(a.mine, "requestTopic", "/chatter")
                  if (r := replied(ev)) and isinstance(r[2], list) and len(r[2]) == 3}
    words = a.words
    wrong = [w for w in words if not any(same_uri(w, u) for u in uris)]
    missing = [u for u in uris if not any(same_uri(w, u) for w in words)]
    if not wrong and not missing:
        port = ", ".join(sorted(data_ports)) or "?"
        return Result(True, f"Right: the master answered {json.dumps([code, status, uris])} [2]. "
                      f"{uris[0]} is /talker's XML-RPC server, its slave API: the master knows "
                      "nodes by these URIs and never sees a data port. Your node then called "
                      f"requestTopic on it [3] and was given the TCPROS port {port} [4], where "
                      "the messages came from.")
    for w in wrong:
        if _port_of(w) in data_ports or w.upper() == "TCPROS":
            return Result(False, f"{w} is where the data came from: the talker's TCPROS port, "
                          "from its answer to requestTopic [4].",
                          hint="The master never knows data ports. Look at the line under [1]: "
                               "its answer's third value is a list of URIs.")
        if same_uri(w, str(a.facts.get("master", ""))):
            return Result(False, f"{w} is the master itself (your ROS_MASTER_URI).",
                          hint="The answer to registerSubscriber [2] names the publishers.")
        if own and same_uri(w, own):
            return Result(False, f"{w} is your own node's URI: you sent it as "
                          "registerSubscriber's fourth argument [1], so that the master can "
                          "call you back.", hint="Look at the answer, the line after [1].")
    return Result(False, f"The master's answer named {len(uris)} URI"
                  f"{'s' if len(uris) != 1 else ''}; yours {'do' if len(words) > 1 else 'does'}"
                  " not match.",
                  hint=f"minros trace show {a.facts.get('me')} --topic /chatter: the line "
                       'after [1] reads <- 1, "Subscribed to [/chatter]", [...]: give the list.')


# --------------------------------------------------------------------------- 2


def _check_headers(a: Attempt) -> Result:
    conns = [c for c in connections(a.mine, topic="/chatter", side="connect")
             if c.out and c.inn and not c.refused]
    if not conns:
        return _no_trace(a, "connection to /chatter with both headers")
    asked = _words_or_ask(a, "SUBSCRIBER_FIELD PUBLISHER_FIELD")
    if asked:
        return asked
    c = conns[-1]
    sub_only, pub_only = set(c.out) - set(c.inn), set(c.inn) - set(c.out)
    words = [w.split("=", 1)[0] for w in a.words]
    given_sub, given_pub = set(words[:len(sub_only)]), set(words[len(sub_only):])
    if given_sub == sub_only and given_pub == pub_only:
        shared = ", ".join(sorted(set(c.out) & set(c.inn)))
        return Result(True, "Right: only the subscriber sends "
                      + ", ".join(f"{k}={c.out[k]}" for k in sorted(sub_only))
                      + " (it may ask the publisher for TCP_NODELAY), only the publisher "
                      + ", ".join(f"{k}={c.inn[k]}" for k in sorted(pub_only))
                      + " (whether it latches). Both send " + shared + ". Yours said type="
                      f"{c.out.get('type')} and md5sum={c.out.get('md5sum')}: rostopic takes "
                      "any type, and the publisher's answer gives the real one with its full "
                      "definition, which is how rostopic prints a type it has no class for.")
    if given_sub == pub_only and given_pub == sub_only:
        return Result(False, "The other way round.",
                      hint="The first header of [5] is yours: the subscriber speaks first, "
                           "the publisher answers.")
    return Result(False, "Those are not the fields only one side sent.",
                  hint=f"minros trace show {a.facts.get('me')} --topic /chatter: compare the "
                       "two headers of [5] field by field; most fields are in both.")


# --------------------------------------------------------------------------- 3


def _check_publisher_update(a: Attempt) -> Result:
    regs = [ev for ev in calls(a.mine, "registerPublisher", "/news") if replied(ev)]
    if not regs:
        return _no_trace(a, "registerPublisher call for /news")
    own = str(regs[-1]["args"][3])
    asked = _words_or_ask(a, "METHOD URI")
    if asked:
        return asked
    words = a.words
    method = words[0].split("(")[0]
    wrong_method = {
        "registerPublisher": "That is your node's call to the master [0]; the master then "
                             "calls the listener.",
        "requestTopic": "That is the listener calling your node [3], after the master told "
                        "it about you.",
        "registerSubscriber": "That was the listener's own registration, before you started.",
    }
    if method != "publisherUpdate":
        return Result(False, wrong_method.get(method, f"{method} is not the call the master "
                                                      "made to /listener."),
                      hint=f"minros trace show {a.facts.get('dir')}/*.jsonl --topic /news: look "
                           "for the line [2] from /master to /listener.")
    uris = words[1:]
    if not any(same_uri(w, own) for w in uris):
        listener = a.facts.get("listener_uri", "")
        if any(same_uri(w, str(a.facts.get("master", ""))) for w in uris):
            why = "That is the master's URI."
        elif any(w for w in uris if listener and same_uri(w, listener)):
            why = "That is the listener's own URI, where the master called it."
        else:
            why = "Give the URI the call passed in its third argument."
        return Result(False, why, hint="The third argument of publisherUpdate lists the "
                                        "publishers' URIs; yours is the fourth argument of "
                                        "your registerPublisher [0].")
    updates = [ev for ev in calls(a.traces.get("master", []), "publisherUpdate", "/news")
               if any(same_uri(str(u), own) for u in (ev.get("args") or [None] * 3)[2] or [])]
    seen = " (the master's trace shows it)" if updates else ""
    return Result(True, f'Right: the master called publisherUpdate("/master", "/news", '
                  f'["{own}"]) on /listener{seen}. The listener registered first, so the answer '
                  "to its registerSubscriber named nobody; this call is how it learns about a "
                  "publisher that comes later [2]. It then called requestTopic on you [3].")


# --------------------------------------------------------------------------- 4


def _md5(text: str) -> str:
    return hashlib.md5(text.encode()).hexdigest()


def _header_md5() -> str:
    from minros.msgs import get_message_class

    return get_message_class("std_msgs/Header")._md5sum


def _reading_lines(facts: Mapping[str, Any]) -> Tuple[List[str], List[str]]:
    field = facts.get("field", "value")
    constants = ["uint8 CELSIUS=0", "uint8 FAHRENHEIT=1"]
    fields = ["{md5} header", f"float64 {field}", "uint8 unit"]
    return constants, fields


READING_MSG = """# A reading of one sensor (comments are not part of the md5sum)
Header header
float64 {field}   # in the unit below
uint8 unit
uint8 CELSIUS=0
uint8 FAHRENHEIT=1
"""


def md5_variants(facts: Mapping[str, Any]) -> Dict[str, str]:
    """The right md5sum of learn_msgs/Reading (``right``) and those of common mistakes."""
    constants, fields = _reading_lines(facts)
    header = _header_md5()

    def text(cs: Sequence[str], fs: Sequence[str], embedded: str = header) -> str:
        return "\n".join([*cs, *(f.replace("{md5}", embedded) for f in fs)])

    right = text(constants, fields)
    file_text = READING_MSG.format(field=facts.get("field", "value"))
    return {
        "right": _md5(right),
        "newline": _md5(right + "\n"),
        "file order": _md5(text([], fields) + "\n" + "\n".join(constants)),
        "Header": _md5(text(constants, fields, "Header")),
        "std_msgs/Header": _md5(text(constants, fields, "std_msgs/Header")),
        "file": _md5(file_text),
        "file stripped": _md5(file_text.strip()),
        "no constants": _md5(text([], fields)),
    }


_MD5_HINTS = {
    "newline": "Almost: no newline at the end.",
    "file order": "Constants come first, then the fields (each group in file order).",
    "Header": "An embedded message type is written as its own md5sum, not its name: "
              "minros msg md5 std_msgs/Header.",
    "std_msgs/Header": "An embedded message type is written as its own md5sum, not its name: "
                       "minros msg md5 std_msgs/Header.",
    "file": "That is the md5sum of the file itself: drop the comments and blank lines first.",
    "file stripped": "That is the md5sum of the file's text: drop the comments, and write each "
                     "line as 'type name' with one space.",
    "no constants": "The constants count too, first, as 'type NAME=value'.",
}


def _check_md5(a: Attempt) -> Result:
    asked = _words_or_ask(a, "MD5SUM")
    if asked:
        return asked
    word = a.words[0].lower()
    if not _HEX32.match(word):
        return Result(False, f"{a.words[0]} is not an md5sum.",
                      hint="An md5sum is 32 hexadecimal digits, as md5sum or hashlib print it.")
    variants = md5_variants(a.facts)
    if word == variants["right"]:
        constants, fields = _reading_lines(a.facts)
        text = "\n".join([*constants, *(f.replace("{md5}", _header_md5()) for f in fields)])
        return Result(True, "Right: that is learn_msgs/Reading's md5sum, the md5 of:",
                      details=["    " + line for line in text.split("\n")]
                      + ["A node built from another version of this file sends another md5sum "
                         "in its connection header, and its peers refuse it (exercise 6)."])
    for name, value in variants.items():
        if word == value and name in _MD5_HINTS:
            return Result(False, "Not yet.", hint=_MD5_HINTS[name])
    return Result(False, "Not yet: that is not the md5sum of the text the rules give.",
                  hint="Write the lines out first: 2 constants, then 3 fields, the Header as "
                       "its md5sum; print(repr(text)) shows stray spaces and newlines.")


# --------------------------------------------------------------------------- 5


def _temperature_layout(body: bytes) -> Tuple[Dict[str, Any], List[str]]:
    """A sensor_msgs/Temperature body, field by field, with its bytes."""
    seq, secs, nsecs, n = struct.unpack_from("<IIII", body, 0)
    frame_id = body[16:16 + n].decode("utf-8", "replace")
    at = 16 + n
    temperature, variance = struct.unpack_from("<dd", body, at)
    rows = [(body[0:4], f"header.seq = {seq}"),
            (body[4:8], f"header.stamp.secs = {secs}"),
            (body[8:12], f"header.stamp.nsecs = {nsecs}"),
            (body[12:16], f"the length of frame_id: {n}"),
            (body[16:at], f'header.frame_id = "{frame_id}"'),
            (body[at:at + 8], f"temperature = {temperature!r}"),
            (body[at + 8:at + 16], f"variance = {variance!r}")]
    lines = [f"    {chunk.hex():<18} {text}" for chunk, text in rows]
    return {"frame_id": frame_id, "temperature": temperature, "variance": variance,
            "at": at}, lines


def _first_frame(conns: Sequence[Conn]) -> Optional[bytes]:
    for c in conns:
        for frame in c.frames_in:
            head = bytes.fromhex(str(frame.get("head", "")))
            if len(head) >= int(frame.get("len", 0)) > 0:
                return head
    return None


def _check_decode_frame(a: Attempt) -> Result:
    conns = connections(a.mine, topic="/temperature", side="connect")
    body = _first_frame(conns)
    if body is None:
        return _no_trace(a, "whole frame received on /temperature")
    try:
        values, layout = _temperature_layout(body)
    except (struct.error, ValueError):
        return Result(False, "The first frame on /temperature is not a sensor_msgs/Temperature.",
                      hint="Subscribe to /temperature of this exercise's master.")
    asked = _words_or_ask(a, "FRAME_ID TEMPERATURE")
    if asked:
        return asked
    hexed = body[16:16 + len(values["frame_id"].encode())].hex()
    numbers, names = [], []
    for w in a.words:
        try:
            if w.lower() == hexed:  # digits only, but the frame_id's bytes
                raise ValueError(w)
            numbers.append(float(w))
        except ValueError:
            names.append(w)
    frame_ok = values["frame_id"] in names
    temp_ok = any(math.isclose(x, values["temperature"], rel_tol=1e-9) for x in numbers)
    if frame_ok and temp_ok:
        return Result(True, "Right. Your frame, byte by byte (little-endian throughout):",
                      details=layout)
    if not temp_ok:
        at = values["at"]
        chunk = body[at:at + 8]
        mistakes = {
            "big-endian": struct.unpack(">d", chunk)[0],
            "variance": values["variance"],
            "float32": struct.unpack("<f", chunk[:4])[0],
        }
        for name, value in mistakes.items():
            if any(math.isclose(x, value, rel_tol=1e-6) for x in numbers if not math.isnan(x)):
                hint = {
                    "big-endian": "TCPROS is little-endian: the first byte is the least "
                                  "significant (struct.unpack('<d', ...)).",
                    "variance": "That is the field after it: temperature comes first.",
                    "float32": "A float64 is 8 bytes.",
                }[name]
                return Result(False, "The temperature is not right yet.", hint=hint)
        return Result(False, "The temperature is not right yet." if frame_ok else
                      "Neither value is right yet.",
                      hint="After the header (seq, secs, nsecs: 4 bytes each; frame_id: a "
                           "4-byte length, then the text) come 8 bytes of float64: "
                           "struct.unpack('<d', bytes.fromhex('...')).")
    if hexed in (n.lower() for n in names):
        return Result(False, "frame_id is text: decode its bytes.",
                      hint="bytes.fromhex('...').decode()")
    return Result(False, "frame_id is not right yet.",
                  hint="A string is a 4-byte little-endian length, then that many bytes of "
                       "UTF-8; it comes after seq, secs and nsecs.")


# --------------------------------------------------------------------------- 6


def _check_md5_mismatch(a: Attempt) -> Result:
    refused = [c for c in connections(a.mine, topic="/greetings") if c.refused]
    if not refused:
        return _no_trace(a, "refused connection on /greetings (publish for a few seconds: "
                         "/old_listener connects when the master tells it about you)")
    c = refused[-1]
    wanted = c.client_header.get("md5sum", "")
    refuser = "publisher" if c.server_header.get("error") else "subscriber"
    asked = _words_or_ask(a, "MD5SUM publisher|subscriber")
    if asked:
        return asked
    words = [w.lower() for w in a.words]
    md5s = [w for w in words if _HEX32.match(w)]
    sides = [w for w in words if w in ("publisher", "subscriber", "talker", "listener",
                                       "pub", "sub")]
    side = {"talker": "publisher", "pub": "publisher", "listener": "subscriber",
            "sub": "subscriber"}.get(sides[0], sides[0]) if sides else ""
    if wanted not in md5s:
        if STRING_MD5 in md5s:
            return Result(False, f"{STRING_MD5} is your publisher's md5sum, the real "
                          "std_msgs/String's.", hint="The listener asked for another one: its "
                                                     "header, the first of [5].")
        return Result(False, "That is not the md5sum the listener asked for.",
                      hint="The subscriber's header (the first of [5]) names it: md5sum=...")
    if side != refuser:
        return Result(False, f"The md5sum is right; the {side or '?'} is not who refused.",
                      hint="Look for the header that carries error=: which node sent it?")
    error = c.server_header.get("error") or c.client_header.get("error", "")
    return Result(True, f"Right: /old_listener asked for std_msgs/String with md5sum {wanted}; "
                  f"your node has {STRING_MD5}, so your publisher refused in its header: "
                  f"error={error} The master never compares types: only the two ends do, in "
                  "their headers. minros msg md5 std_msgs/String on each machine shows which "
                  "build is stale.")


# --------------------------------------------------------------------------- 7


def _check_latching(a: Attempt) -> Result:
    seen: Dict[str, Conn] = {}
    for topic in ("/door", "/window"):
        conns = [c for c in connections(a.mine, topic=topic, side="connect") if c.inn]
        if conns:
            seen[topic] = conns[-1]
    missing = [t for t in ("/door", "/window") if t not in seen]
    if missing:
        return _no_trace(a, f"connection to {' and '.join(missing)} (subscribe to both topics)")
    latched = [t for t, c in seen.items() if c.inn.get("latching") == "1"]
    asked = _words_or_ask(a, "TOPIC FIELD=VALUE")
    if asked:
        return asked
    words = a.words
    topics = ["/" + w.lstrip("/") for w in words if w.lstrip("/") in ("door", "window")]
    fields = [w for w in words if "=" in w]
    if not latched:
        return Result(False, "Neither publisher said it latches in your traces.",
                      hint="Subscribe again while the exercise runs.")
    if topics[:1] != latched[:1]:
        return Result(False, f"{topics[0] if topics else 'No topic named'}: not the latched one.",
                      hint="Look at the latching= field in the publisher's header (the second "
                           "header of [5]) of each topic.")
    if "latching=1" not in fields:
        return Result(False, "The topic is right; now the header field, as key=value.",
                      hint=f"The publisher's header on {latched[0]} (the second of [5]).")
    other = "/window" if latched[0] == "/door" else "/door"
    got = len(seen[latched[0]].frames_in)
    return Result(True, f"Right: {latched[0]}'s publisher answered latching=1 and sent its last "
                  f"message right after the headers ({got} frame{'s' if got != 1 else ''}), "
                  f"although it was published before you connected; {other}'s said latching=0 "
                  f"and sent {len(seen[other].frames_in)}: its only message went out when "
                  "nobody was subscribed, and was gone.")


# --------------------------------------------------------------------------- 8


CLIENT_PY = '''"""A client of /add_two_ints: waits for the service, then three calls on one connection."""
import rospy
from rospy_tutorials.srv import AddTwoInts

rospy.wait_for_service("add_two_ints", timeout=10)
add = rospy.ServiceProxy("add_two_ints", AddTwoInts, persistent=True)
for a in range(3):
    print(a, "+ 10 =", add(a, 10).sum)
add.close()
'''


def _check_service_probe(a: Attempt) -> Result:
    conns = connections(a.mine, service="/add_two_ints", side="connect")
    if not conns:
        return _no_trace(a, "connection to /add_two_ints")
    asked = _words_or_ask(a, "N FIELD=VALUE")
    if asked:
        return asked
    probes = [c for c in conns if c.kind == "probe"]
    carried = sum(len(c.frames_out) for c in conns)
    numbers = [int(w) for w in a.words if w.isdigit()]
    fields = [w for w in a.words if "=" in w]
    if numbers[:1] != [len(conns)]:
        if numbers and numbers[0] == carried + len(probes):
            hint = "persistent=True keeps one connection for every call: count the lines " \
                   "'TCP connection' in the trace."
        elif numbers and numbers[0] == len(conns) - len(probes):
            hint = "Count the probe too: wait_for_service opens a connection that carries " \
                   "no request."
        else:
            hint = f"minros trace show {a.facts.get('me')} --service /add_two_ints: each " \
                   "connection is numbered #1, #2, ..."
        return Result(False, "That is not the number of connections.", hint=hint)
    if not probes:
        return Result(True, f"{len(conns)} connections, none of them a probe: your client did "
                      "not call wait_for_service.")
    if "probe=1" not in fields:
        if "persistent=1" in fields:
            return Result(False, "persistent=1 is on the connection that carried the calls.",
                          hint="The other connection's header has one field more than a call's.")
        return Result(False, "The number is right; now the header field, as key=value.",
                      hint="The client's header on the connection that carried no request.")
    calls_text = ", ".join(str(len(c.frames_out)) for c in conns if c.kind == "service")
    oks = sorted({int(f.get("ok", -1)) for c in conns for f in c.frames_in})
    return Result(True, f"Right: {len(conns)} connections. The probe (probe=1, md5sum=*) only "
                  "checks that the server answers with its header, then closes; the persistent "
                  f"one (persistent=1) carried {calls_text} requests, each answered with the "
                  f"ok byte {', '.join(map(str, oks))} before the response. Without "
                  "persistent=True every call opens a connection of its own.")


# --------------------------------------------------------------------------- 9


def _check_nagle(a: Attempt) -> Result:
    conns = [c for c in connections(a.mine, topic="/sensor", side="connect")
             if len(c.frames_in) >= 10]
    by_flag: Dict[str, Conn] = {}
    for c in conns:
        by_flag[c.out.get("tcp_nodelay", "0")] = c
    missing = [name for flag, name in (("0", "a plain subscription"),
                                       ("1", "one with --tcpnodelay")) if flag not in by_flag]
    if missing:
        return _no_trace(a, f"{' and '.join(missing)} to /sensor that received messages")
    asked = _words_or_ask(a, "FIELD=VALUE")
    if asked:
        return asked
    words = [w.lower() for w in a.words]
    details = []
    for flag, label in (("0", "tcp_nodelay=0"), ("1", "tcp_nodelay=1")):
        lat = latency(by_flag[flag], a.traces.get("sensor", []))
        details.append(f"    {label}: " + (lat.text() if lat else "(the sensor's trace "
                                                                   "does not match)"))
    if "tcp_nodelay=1" in words:
        return Result(True, "Right: the subscriber asks with tcp_nodelay=1 in its header, and "
                      "the publisher sets TCP_NODELAY on that connection's socket. Measured in "
                      "your traces (send to receive):", details=details + [
                          "A max near 40 ms without the flag is Nagle's algorithm waiting for "
                          "the delayed acknowledgement; it depends on timing, so it does not "
                          "happen on every run."])
    if "tcp_nodelay=0" in words:
        return Result(False, "0 is the default: Nagle's algorithm stays on.",
                      hint="Your second subscription asked for the opposite.")
    return Result(False, "Name the header field with its value, as it is on the wire.",
                  hint="key=value, from the subscriber's header of your --tcpnodelay run [5].")


# --------------------------------------------------------------------------- 10


def _check_master_restart(a: Attempt) -> Result:
    new = a.traces.get("master2", [])
    if not new:
        return Result(False, f"No trace of a new master at {a.facts.get('dir')}/master2.jsonl.",
                      hint=f"After killing the first master: minros trace -o "
                           f"{a.facts.get('dir')}/master2.jsonl -- minros core -p "
                           f"{a.facts.get('port')}")
    old_pids = {ev.get("pid") for ev in a.traces.get("master", []) if ev.get("ev") == "process"}
    if {ev.get("pid") for ev in new if ev.get("ev") == "process"} & old_pids:
        return Result(False, "master2.jsonl was written by the first master.",
                      hint="Kill the first master, then start a new one.")
    found = {}
    for method, who in (("registerPublisher", "/talker"), ("registerSubscriber", "/listener")):
        served = [ev for ev in calls(new, method, "/chatter", served=True)
                  if (ev.get("args") or [""])[0] == who]
        if served:
            found[method] = (who, served[0])
    if not found:
        return Result(False, "The new master has no registration of /chatter yet.",
                      hint="minros nodes call getPid on their master every second and register "
                           "again when it answers with another pid: wait a few seconds.")
    asked = _words_or_ask(a, "METHOD...")
    if asked:
        return asked
    words = {w.split("(")[0] for w in a.words}
    if words == set(found):
        start = min(float(ev["t"]) for ev in new)
        lines = [f"    {who} called {method} {float(ev['t']) - start:.1f} s after the new "
                 "master started" for method, (who, ev) in found.items()]
        return Result(True, "Right: their minros-master-probe thread saw getPid fail, then "
                      "succeed with another pid, and every registration was redone:",
                      details=lines + [
                          "The frames never stopped: the talker-listener connection never went "
                          "through the master. (rospy and roscpp do not register again: after "
                          "a master restart their topics are unknown to the new master.)"])
    if "requestTopic" in words:
        return Result(False, "requestTopic goes from node to node, and the talker-listener "
                      "connection never broke.", hint="Look at the calls the new master served.")
    if "publisherUpdate" in words:
        return Result(False, "publisherUpdate is the master calling a node, not a node "
                      "registering.", hint="Which calls did the nodes make to the new master?")
    return Result(False, "Not the calls the new master received about /chatter.",
                  hint=f"minros trace show {a.facts.get('dir')}/master2.jsonl --topic /chatter")


# --------------------------------------------------------------------------- 11


def _received_on_b(a: Attempt) -> Union[Result, Conn]:
    """The connection through which the learner's subscriber on master B got /chatter (with
    an answer to check), or the verdict on why there is none yet."""
    regs = [ev for ev in calls(a.mine, "registerSubscriber", "/chatter") if replied(ev)]
    if not regs:
        return _no_trace(a, "registerSubscriber call for /chatter")
    master_b = str(a.facts.get("master_b", ""))
    if not same_uri(str(regs[-1].get("uri", "")), master_b):
        return Result(False, f"You subscribed through {regs[-1].get('uri')}, not master B.",
                      hint=f"ROS_MASTER_URI={master_b} for your subscriber.")
    conns = [c for c in connections(a.mine, topic="/chatter", side="connect") if c.inn]
    if not conns:
        return _no_trace(a, "connection to /chatter's publisher")
    return _words_or_ask(a, str(a.facts.get("answer_form", "CALLERID N"))) or conns[-1]


def _wrong_sender(names: List[str], callerid: str) -> Optional[Result]:
    if names[:1] == [callerid]:
        return None
    if names[:1] == ["/talker"]:
        return Result(False, "/talker publishes on master A, which your node never talked "
                      "to.", hint="The callerid of the publisher's header you received [5].")
    return Result(False, "That is not who sent you the message.",
                  hint="The callerid field of the second header of [5].")


def _calls_from(events: Sequence[Dict[str, Any]], names: Sequence[str]) -> List[Dict[str, Any]]:
    """The calls a master's trace shows it served for the nodes ``names``."""
    return [ev for ev in events if ev.get("ev") == "xmlrpc.serve" and names
            and (ev.get("args") or [""])[0] in names]


def _check_two_masters(a: Attempt) -> Result:
    if a.facts.get("variant") == "zenoh":
        return _check_two_masters_zenoh(a)
    conn = _received_on_b(a)
    if isinstance(conn, Result):
        return conn
    callerid = conn.inn.get("callerid", "")
    hops = int(a.facts.get("hops", 2))
    names = [w for w in a.words if w.startswith("/")]
    numbers = [int(w) for w in a.words if w.isdigit()]
    wrong = _wrong_sender(names, callerid)
    if wrong:
        return wrong
    if numbers[:1] != [hops]:
        return Result(False, "The sender is right; count the TCPROS connections again.",
                      hint="From /talker to the relay on master A, from the relay to you on "
                           "master B; the relay's two halves talk through a pipe, not TCPROS.")
    me = node_names(a.mine)
    heard = _calls_from(a.traces.get("master", []), me)
    return Result(True, f"Right: {callerid} registered /chatter on master B and sent you the "
                  f"messages it receives from /talker on master A: {hops} TCPROS connections, "
                  "one on each master. Master A's trace has "
                  + (f"{len(heard)} calls" if heard else "no call")
                  + f" from your node ({me[0] if me else '?'}): each master keeps its own graph, "
                  "and only the relay is on both. minros learn 11 --via zenoh does the same "
                  "with a minros zenoh bridge on each master and a Zenoh network in between.")


def zenoh_key(topic: str, type_name: str, md5sum: str, namespace: str = "*") -> str:
    """The key expression minros zenoh (and zenoh-bridge-ros1) carries a topic's messages
    under: the type's name in hex, its md5sum, the bridge namespace, the name without its
    slashes (minros.zenoh.keys.data_key, which this layer may not import)."""
    return f"{type_name.encode().hex()}/{md5sum}/{namespace}/{topic.strip('/')}"


def _wrong_key(word: str, key: str, type_name: str, md5sum: str) -> str:
    """A hint for a key that is not ``key`` ("" when ``word`` does not look like a key)."""
    parts = word.split("/")
    want = key.split("/")
    if word.startswith("ros1_discovery_info/"):
        return ("That is the key of a bridge's beacon, which declares that /chatter exists; "
                "the messages themselves go under the key that follows the class (pub/).")
    if word == type_name or word == md5sum:
        return ("That is one part of the key: the key is <the type's name in hex>/<md5sum>/"
                "<bridge namespace>/<topic without its slash> (minros zenoh keys /chatter).")
    if word != word.strip("/"):
        return ("A Zenoh key expression has no '/' at either end: the topic goes in without "
                "its leading slash.")
    if len(parts) != 4:
        return ("A data key has four parts: <the type's name in hex>/<md5sum>/<bridge "
                "namespace>/<topic without its slash>; minros zenoh keys /chatter prints it.")
    if parts[0] != want[0]:
        return (f"The first part is the hex of the type's whole name, {type_name} as it "
                "arrived in your header: python3 -c 'print(b\"...\".hex())'.")
    if parts[1] != want[1]:
        return "The second part is the md5sum of the publisher's header you received [5]."
    if parts[2] != want[2]:
        return "These bridges run without --namespace: the bridge namespace is '*'."
    return "The last part is the topic's name without its leading slash."


def _check_two_masters_zenoh(a: Attempt) -> Result:
    conn = _received_on_b(a)
    if isinstance(conn, Result):
        return conn
    callerid = conn.inn.get("callerid", "")
    type_name = conn.inn.get("type", "")
    md5sum = conn.inn.get("md5sum", "")
    key = zenoh_key("/chatter", type_name, md5sum)
    names = [w for w in a.words if w.startswith("/")]
    wrong = _wrong_sender(names, callerid)
    if wrong:
        if names[:1] == ["/talker"]:
            wrong.hint += " /talker's messages reached master B through the bridges."
        return wrong
    keys = [w for w in a.words if not w.startswith("/")]
    if not keys:
        return Result(False, f"{callerid} is right; now the key the message crossed Zenoh under.",
                      hint="With env.sh sourced: minros zenoh keys /chatter (it asks master B "
                           "and the publisher for the type and md5sum).")
    if keys[0] != key:
        return Result(False, f"{callerid} is right; {keys[0]} is not the key /chatter "
                      "crossed under.", hint=_wrong_key(keys[0], key, type_name, md5sum))
    master_b = _calls_from(a.traces.get("master_b", []), [callerid])
    registered = [ev for ev in master_b if ev.get("method") == "registerPublisher"
                  and (ev.get("args") or ["", ""])[1:2] == ["/chatter"]]
    on_b = (f" Master B's trace shows {callerid}'s registerPublisher for /chatter"
            if registered else f" {callerid} registered /chatter as a publisher on master B")
    me = node_names(a.mine)
    heard = _calls_from(a.traces.get("master", []), me)
    return Result(True, f"Right: the header you received says callerid={callerid}, the bridge "
                  f"on master B, not /talker.{on_b}, as a node of that master; the bridge on "
                  f"master A subscribed to /talker and put each message on Zenoh under {key} "
                  f"(the hex of {type_name}, its md5sum, the bridge namespace '*', the topic), "
                  "as the body alone, without TCPROS's length prefix. Two TCPROS connections, "
                  "one on each master, and a Zenoh link between the bridges: master A's trace "
                  "has " + (f"{len(heard)} calls" if heard else "no call")
                  + f" from your node ({me[0] if me else '?'}). zenoh-bridge-ros1 uses the "
                  "same keys, so a bridge of either kind could be at either end.")


# --------------------------------------------------------------------------- the list


def _choose_md5(rng: random.Random) -> Dict[str, Any]:
    return {"field": rng.choice(["value", "level", "reading", "amount"])}


def _choose_temperature(rng: random.Random) -> Dict[str, Any]:
    return {"frame_id": rng.choice(["kitchen", "garage", "attic", "cellar", "porch", "office"]),
            "temperature": rng.randrange(40, 120) / 4,
            "variance": rng.choice([0.25, 0.5, 0.75, 1.5])}


def _choose_latched(rng: random.Random) -> Dict[str, Any]:
    latched = rng.choice(["/door", "/window"])
    return {"latched": latched, "door_latch": "1" if latched == "/door" else "0",
            "window_latch": "1" if latched == "/window" else "0"}


_ENV = """In another terminal, first (it sets ROS_MASTER_URI={master} and ROS_HOSTNAME):
    source {dir}/env.sh"""

EXERCISES: Tuple[Exercise, ...] = (
    Exercise(
        1, "register-subscriber", "The master's answer to registerSubscriber", 3,
        "the master's answer to registerSubscriber",
        task=_ENV + """
/talker publishes /chatter (std_msgs/String). Subscribe to it from a traced process, then
read your side of the wire:
    minros trace -o {me} -- minros topic echo -n 1 /chatter
    minros trace show {me} --topic /chatter
Your node registered as a subscriber [1] and the master answered [2].
Question: which URIs did the master answer with?
    minros learn check 1 URI...""",
        answer_form="URI...", check=_check_register_subscriber,
        variants={"": (_master(), _actor("talker", "talker", "--topic", "/chatter",
                                         ready=("registerPublisher", "/chatter")))}),
    Exercise(
        2, "headers", "Both connection headers", 3, "both connection headers",
        task=_ENV + """
/talker publishes /chatter. Subscribe, traced, and look at step [5]: the two connection
headers, yours first, then the publisher's answer:
    minros trace -o {me} -- minros topic echo -n 1 /chatter
    minros trace show {me} --topic /chatter
Question: which field does only the subscriber send, and which only the publisher?
    minros learn check 2 SUBSCRIBER_FIELD PUBLISHER_FIELD""",
        answer_form="SUBSCRIBER_FIELD PUBLISHER_FIELD", check=_check_headers,
        variants={"": (_master(), _actor("talker", "talker", "--topic", "/chatter",
                                         ready=("registerPublisher", "/chatter")))}),
    Exercise(
        3, "publisher-update", "The listener first: publisherUpdate", 3,
        "registration order: the master calls the subscriber back",
        task=_ENV + """
/listener subscribes /news and nobody publishes it yet. Publish once, traced:
    minros trace -o {me} -- minros topic pub -1 /news std_msgs/String "data: hi"
    minros trace show {dir}/*.jsonl --topic /news
(the exercise traces the master and /listener into {dir} too.)
Question: which call did the master make to /listener, and which URI did it pass?
    minros learn check 3 METHOD URI""",
        answer_form="METHOD URI", check=_check_publisher_update,
        variants={"": (_master(), _actor("listener", "listener", "--topic", "/news",
                                         ready=("registerSubscriber", "/news")))}),
    Exercise(
        4, "decode-frame", "A frame, byte by byte", 5, "decoding a frame byte by byte",
        task=_ENV + """
/thermometer publishes sensor_msgs/Temperature on /temperature once a second. Receive a
few without printing them, traced (Ctrl-C after two seconds), then look at the bytes:
    minros trace -o {me} -- minros topic hz /temperature
    minros trace show {me} --topic /temperature --frames 1
The body line is the message, in hex. Its layout (minros msg show sensor_msgs/Temperature):
    header: uint32 seq, time stamp (uint32 secs, uint32 nsecs),
            string frame_id (uint32 length, then the bytes)
    float64 temperature, float64 variance            -- all little-endian
(python3: struct.unpack('<d', bytes.fromhex('...')) reads a float64.)
Question: what are frame_id and temperature?
    minros learn check 4 FRAME_ID TEMPERATURE""",
        answer_form="FRAME_ID TEMPERATURE", check=_check_decode_frame,
        choose=_choose_temperature,
        variants={"": (_master(), _actor(
            "thermometer", "temperature", "--frame-id", "{frame_id}", "--value",
            "{temperature}", "--variance", "{variance}",
            ready=("registerPublisher", "/temperature")))}),
    Exercise(
        5, "md5sum", "An md5sum by hand", 5, "computing a type's md5sum by hand",
        task="""
Every connection header carries md5sum: a hash of the type's definition, so that two
nodes built from different versions of a type refuse each other. Compute the md5sum of
learn_msgs/Reading by hand. Its file ({dir}/Reading.msg):

{reading}
The text that is hashed:
  - comments and blank lines dropped, each line as "type name" (one space);
  - constants first, as "type NAME=value", then the fields, each group in file order;
  - a field whose type is a message is written "MD5 name", MD5 being that type's md5sum
    (minros msg md5 std_msgs/Header);
  - lines joined with a newline, none at the end.
python3 -c 'import hashlib; print(hashlib.md5(b"...").hexdigest())' or printf ... | md5sum
    minros learn check 5 MD5SUM""",
        answer_form="MD5SUM", check=_check_md5, choose=_choose_md5,
        files={"Reading.msg": READING_MSG}),
    Exercise(
        6, "md5-mismatch", "An md5sum mismatch and its error", 4,
        "an md5 mismatch and its error",
        task=_ENV + """
/old_listener subscribes /greetings with a std_msgs/String built from an older definition
(a stale build). Publish to it for three seconds, traced (Ctrl-C then), and read the headers:
    minros trace -o {me} -- minros topic pub -r 1 /greetings std_msgs/String "data: hello"
    minros trace show {me} --topic /greetings
Question: which md5sum did /old_listener ask for, and which side refused the connection?
    minros learn check 6 MD5SUM publisher|subscriber""",
        answer_form="MD5SUM publisher|subscriber", check=_check_md5_mismatch,
        variants={"": (_master(), _actor("old_listener", "stale_listener", "--topic",
                                         "/greetings", ready=("registerSubscriber",
                                                              "/greetings")))}),
    Exercise(
        7, "latching", "Latched or not", 4, "latched versus not",
        task=_ENV + """
/door_sensor and /window_sensor each published one message on /door and /window when they
started; one of them latches. Subscribe to each, traced (one waits: Ctrl-C it after 3 s):
    minros trace -o {dir}/me-door.jsonl -- minros topic echo -n 1 /door
    minros trace -o {dir}/me-window.jsonl -- minros topic echo -n 1 /window
    minros trace show {dir}/me-door.jsonl {dir}/me-window.jsonl
Question: which topic is latched, and which header field said so (as key=value)?
    minros learn check 7 TOPIC FIELD=VALUE""",
        answer_form="TOPIC FIELD=VALUE", check=_check_latching, choose=_choose_latched,
        variants={"": (_master(),
                       _actor("door_sensor", "once", "--topic", "/door", "--latch",
                              "{door_latch}", ready=("registerPublisher", "/door")),
                       _actor("window_sensor", "once", "--topic", "/window", "--latch",
                              "{window_latch}", ready=("registerPublisher", "/window")))}),
    Exercise(
        8, "service-probe", "A service: the probe and a persistent connection", 4,
        "a service's probe and a persistent call",
        task=_ENV + """
/add_two_ints_server serves /add_two_ints (rospy_tutorials/AddTwoInts). {dir}/client.py
waits for the service, then makes three calls through one persistent proxy. Run it traced:
    minros trace -o {me} -- {python} {dir}/client.py
    minros trace show {me} --service /add_two_ints --frames all
Question: how many TCP connections did your client open to the server, and which header
field (key=value) marks the one that carried no request?
    minros learn check 8 N FIELD=VALUE""",
        answer_form="N FIELD=VALUE", check=_check_service_probe,
        files={"client.py": CLIENT_PY},
        variants={"": (_master(), _actor("add_two_ints_server", "add_server",
                                         ready=("registerService", "/add_two_ints")))}),
    Exercise(
        9, "nagle", "Nagle's algorithm and tcp_nodelay", 5,
        "Nagle (tcp_nodelay) and the 40 ms stall",
        task=_ENV + """
/sensor publishes 1000-byte messages at 400 Hz on /sensor, traced into {dir}/sensor.jsonl.
Subscribe twice, 3 seconds each (Ctrl-C), once plainly and once asking for TCP_NODELAY:
    minros trace -o {dir}/me-nagle.jsonl -- minros topic hz /sensor
    minros trace -o {dir}/me-nodelay.jsonl -- minros topic hz --tcpnodelay /sensor
Compare how long frames took from the sensor's send to your receive (the last lines):
    minros trace show {dir}/sensor.jsonl {dir}/me-nagle.jsonl --topic /sensor --frames 0
    minros trace show {dir}/sensor.jsonl {dir}/me-nodelay.jsonl --topic /sensor --frames 0
Question: which header field asked the publisher for TCP_NODELAY (as key=value)?
    minros learn check 9 FIELD=VALUE""",
        answer_form="FIELD=VALUE", check=_check_nagle,
        variants={"": (_master(), _actor("sensor", "flood", "--topic", "/sensor",
                                         ready=("registerPublisher", "/sensor")))}),
    Exercise(
        10, "master-restart", "The master restarts", 5,
        "killing and restarting the master and watching re-registration",
        task=_ENV + """
/talker publishes /chatter to /listener. Kill the master, then start a new one on the
same port, traced:
    kill {master_pid}
    minros trace -o {dir}/master2.jsonl -- minros core -p {port}
Wait five seconds, then look at what the nodes did:
    minros trace show {dir}/*.jsonl --topic /chatter
Question: which calls did /talker and /listener make to the new master about /chatter?
    minros learn check 10 METHOD...
(Stop your master with Ctrl-C when done.)""",
        answer_form="METHOD...", check=_check_master_restart,
        variants={"": (_master(),
                       _actor("talker", "talker", "--topic", "/chatter", "--rate", "5",
                              ready=("registerPublisher", "/chatter")),
                       _actor("listener", "listener", "--topic", "/chatter",
                              ready=("registerSubscriber", "/chatter")))}),
    Exercise(
        11, "two-masters", "A topic crossing two masters", 4,
        "a topic crossing two masters (two minros zenoh bridges, or a relay)",
        task="""Two masters: A at {master} and B at {master_b}.
/talker publishes /chatter on master A. {bridge_text}
In another terminal, subscribe on master B, traced (env.sh sets ROS_MASTER_URI={master_b}):
    source {dir}/env.sh
    minros trace -o {me} -- minros topic echo -n 1 /chatter
    minros trace show {dir}/*.jsonl --topic /chatter
{question}
    minros learn check 11 {answer_form}""",
        answer_form="CALLERID N", check=_check_two_masters,
        variants={
            "zenoh": (
                _master("a"), _master("b"),
                _actor("talker", "talker", "--topic", "/chatter",
                       ready=("registerPublisher", "/chatter")),
                _zenoh_bridge("bridge_a", "a", "--listen", "tcp/127.0.0.1:{zenoh_port}",
                              ready=("registerSubscriber", "/chatter")),
                _zenoh_bridge("bridge_b", "b", "--connect", "tcp/127.0.0.1:{zenoh_port}",
                              "--listen", "tcp/127.0.0.1:0",
                              ready=("registerPublisher", "/chatter"))),
            "relay": (
                _master("a"), _master("b"),
                _actor("talker", "talker", "--topic", "/chatter",
                       ready=("registerPublisher", "/chatter")),
                _actor("relay_a", "relay_out", "--topic", "/chatter", "--name", "relay",
                       ready=("registerSubscriber", "/chatter"), stdout_pipe=True),
                _actor("relay_b", "relay_in", "--topic", "/chatter", "--name", "relay",
                       master="b", stdin_from="relay_a",
                       ready=("registerPublisher", "/chatter")))},
        requires={"zenoh": _zenoh_missing},
        variant_facts={
            "zenoh": {
                "bridge": "/minros_zenoh", "hops": 2, "answer_form": "CALLERID KEY",
                "bridge_text": "A minros zenoh bridge on each master joins them\n"
                               "over Zenoh on this machine only: bridge_a (master A) listens on "
                               "tcp/127.0.0.1:{zenoh_port},\nbridge_b (master B) connects to "
                               "it; neither scouts by multicast, so nothing reaches the LAN.",
                "question": "Question: whose callerid is in the publisher's header you received, "
                            "and under which Zenoh\nkey expression did the message cross "
                            "between the bridges (minros zenoh keys --help)?",
            },
            "relay": {
                "bridge": "/relay", "hops": 2,
                "bridge_text": "A relay republishes it on master B: one\nnode on each "
                               "master, both named /relay, joined by a pipe (relay_a.jsonl and "
                               "relay_b.jsonl).",
                "question": "Question: whose callerid is in the publisher's header you received, "
                            "and how many TCPROS\nconnections did the message cross from "
                            "/talker to you?",
            }}),
)

"""``minros zenoh`` on loopback: two masters, two bridges (one listening, one connecting, no
multicast), and a Zenoh session of the test's own playing a plain Zenoh application or
zenoh-bridge-ros1 as its source puts it on the wire (tests/zenoh_support.py). Across network
namespaces and with Debian's nodes: tests/interop/test_zenoh_two_hosts.py."""

from __future__ import annotations

import io
import subprocess
import threading
import time
import xmlrpc.client

import pytest

from support import PYTHON, ros_env, wait_until
from zenoh_support import (
    LISTENER,
    SETBOOL_MD5,
    SETBOOL_SERVER,
    STRING_MD5,
    TALKER,
    EmulatedBridge,
    Pair,
    count_lines,
    require_zenoh,
    wait_gone,
    zenoh_session,
)

pytestmark = pytest.mark.timeout(120)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    require_zenoh()
    sites = Pair(tmp_path_factory.mktemp("zenoh"))
    try:
        yield sites
    finally:
        sites.close()


@pytest.fixture(scope="module")
def session(pair):
    s = zenoh_session(pair.endpoint)
    try:
        yield s
    finally:
        s.close()


def _string(text: str) -> bytes:
    from minros.msgs import get_message_class

    buff = io.BytesIO()
    get_message_class("std_msgs/String")(text).serialize(buff)
    return buff.getvalue()


def test_a_talker_is_heard_behind_the_other_bridge_with_its_wire_format(pair, session):
    from minros.zenoh import keys

    key = keys.data_key("/chatter_1", "std_msgs/String", STRING_MD5)
    assert key == "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter_1"
    samples, beacons = [], []
    sub = session.declare_subscriber(key, lambda s: samples.append(s.payload.to_bytes()))
    beacon_key = keys.discovery_key("pub", "/chatter_1", "std_msgs/String", STRING_MD5)
    bsub = session.declare_subscriber(
        "ros1_discovery_info/**",
        lambda s: beacons.append((time.monotonic(), str(s.key_expr), s.payload.to_bytes())))
    try:
        pair.a.python(TALKER, "chatter_1", "20")
        listener = pair.b.python(LISTENER, "chatter_1")
        listener.read_until("I heard hello", 20)
        # what went over Zenoh: String bodies without TCPROS's length prefix
        wait_until(lambda: len(samples) >= 5, 20, what="5 samples seen by a plain Zenoh app")
        assert all(s[4:].startswith(b"hello ") and len(s) == 4 + len(s[4:])
                               for s in samples[:5])
        assert _string("hello 3") in samples or any(s == _string(s[4:].decode()) for s in samples)
        # and its beacons: empty samples on the bridge's discovery key, once a second
        time.sleep(2.5)
        mine = [(t, p) for t, k, p in beacons if k == beacon_key]
        assert len(mine) >= 2 and all(p == b"" for _t, p in mine)
        gaps = [b[0] - a[0] for a, b in zip(mine, mine[1:])]
        assert all(0.7 < g < 1.4 for g in gaps), gaps
    finally:
        sub.undeclare()
        bsub.undeclare()
    info = pair.b.tool("topic", "info", "/chatter_1").stdout
    assert "Type: std_msgs/String" in info and "/minros_zenoh" in info


def test_keys_prints_the_key_from_the_master_or_a_type(pair):
    done = pair.a.tool("zenoh", "keys", "/chatter_1", "--all")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter_1",
        "ros1_discovery_info/*/pub/7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter_1",
        "ros1_discovery_info/*/sub/7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter_1"]
    done = pair.a.tool("zenoh", "keys", "set_bool", "--type", "std_srvs/SetBool", "--namespace", "r1")
    assert done.stdout.strip() == f"7374645f737276732f536574426f6f6c/{SETBOOL_MD5}/r1/set_bool"
    done = pair.a.tool("zenoh", "keys", "/nothing_here")
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.strip() == (f"ERROR: /nothing_here is neither a topic nor a service of the "
                                   f"master at http://localhost:{pair.a.port} (give its type with --type)")


def test_a_service_is_called_from_behind_the_other_bridge_with_its_errors(pair):
    pair.a.python(SETBOOL_SERVER, "set_flag_2").read_until("serving", 20)
    pair.b.bridge.read_until("bridging /set_flag_2 (std_srvs/SetBool) service Zenoh -> ROS", 20)
    ok = pair.b.tool("service", "call", "/set_flag_2", "data: true")
    assert ok.returncode == 0, ok.stderr
    assert "success: True" in ok.stdout and 'message: "set by /setbool_server' in ok.stdout
    refused = pair.b.tool("service", "call", "/set_flag_2", "data: false")
    direct = pair.a.tool("service", "call", "/set_flag_2", "data: false")
    assert refused.returncode == direct.returncode != 0
    assert refused.stderr.strip() == direct.stderr.strip() == (
        "ERROR: service [/set_flag_2] responded with an error: "
        "b'service cannot process request: false is refused'")


THING_MSG = "string name\nint32[] values\ngeometry_msgs/Point where\n"

LATCHED_THING = r'''
import rospy
from zthing_msgs.msg import Thing
from geometry_msgs.msg import Point
rospy.init_node("thing_talker")
pub = rospy.Publisher("thing_3", Thing, queue_size=1, latch=True)
pub.publish(Thing(name="only once", values=[1, 2, 3], where=Point(1.0, 2.0, 3.0)))
print("published", flush=True)
rospy.spin()
'''


def test_definition_and_latching_travel_to_a_site_without_the_msg_file(pair, tmp_path):
    pkg = tmp_path / "ws" / "zthing_msgs"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "msg" / "Thing.msg").write_text(THING_MSG)
    (pkg / "package.xml").write_text(
        '<package format="2"><name>zthing_msgs</name><version>0.0.1</version><description>t'
        '</description><maintainer email="a@b.c">a</maintainer><license>BSD</license></package>')
    env = dict(pair.a.env, ROS_PACKAGE_PATH=str(tmp_path / "ws"))
    pair.a.start([PYTHON, "-c", LATCHED_THING], env).read_until("published", 20)
    pair.b.bridge.read_until("bridging /thing_3 (zthing_msgs/Thing) Zenoh -> ROS", 20)
    # site b has no zthing_msgs: echo decodes by the definition the bridge advertises, and
    # subscribes after the one message was published: it comes latched
    echo = pair.b.tool("topic", "echo", "-n", "1", "/thing_3", timeout=20)
    assert echo.returncode == 0, echo.stderr
    assert 'name: "only once"' in echo.stdout and "values: [1, 2, 3]" in echo.stdout
    assert "x: 1.0" in echo.stdout
    bag = tmp_path / "thing.bag"
    recorder = pair.b.start([PYTHON, "-m", "minros", "bag", "record", "-O", str(bag), "/thing_3"])
    recorder.read_until("Recording to", 20)
    time.sleep(1.5)
    recorder.stop()
    from minros.bag import Bag

    with Bag(str(bag)) as b:
        conns = b.get_type_and_topic_info().topics
        assert conns["/thing_3"].msg_type == "zthing_msgs/Thing"
        [(_topic, msg, _t)] = list(b.read_messages(topics=["/thing_3"], raw=True))
        definition = msg[4]._full_text  # (type, bytes, md5, position, class)
        assert "geometry_msgs/Point where" in definition and "MSG: geometry_msgs/Point" in definition


@pytest.mark.smoke
def test_plain_zenoh_publisher_feeds_a_subscriber_only_topic(pair, session):
    from minros.zenoh import keys

    listener = pair.b.python(LISTENER, "from_zenoh_4")
    listener.read_until("listening", 20)
    pair.b.bridge.read_until("bridging /from_zenoh_4 (std_msgs/String) Zenoh -> ROS", 20)
    key = keys.data_key("/from_zenoh_4", "std_msgs/String", STRING_MD5)
    _put_until_heard(session, key, "from a plain Zenoh app", listener)


def _put_until_heard(session, key: str, text: str, listener) -> None:
    """Put ``text`` on ``key`` until the listener hears it (its connection to the bridge's
    publisher is made after the bridge advertised it)."""
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        session.put(key, _string(text))
        try:
            listener.read_until(f"I heard {text}", 0.3)
            return
        except AssertionError:
            continue
    raise AssertionError(f"the listener never heard {text!r} from Zenoh")


def test_garbage_and_unknown_keys_get_one_line_each_and_nothing_else(pair, session):
    from minros.zenoh import keys

    listener = pair.b.python(LISTENER, "garbage_5")
    listener.read_until("listening", 20)
    pair.b.bridge.read_until("bridging /garbage_5 (std_msgs/String) Zenoh -> ROS", 20)
    key = keys.data_key("/garbage_5", "std_msgs/String", STRING_MD5)
    bogus = ["ros1_discovery_info/*/pub/zz/" + STRING_MD5 + "/*/x",
             "ros1_discovery_info/*/xyz/7374645f6d7367732f537472696e67/" + STRING_MD5 + "/*/y",
             "ros1_discovery_info/*/pub/7374645f6d7367732f537472696e67/nope/*/z"]
    for _ in range(30):
        session.put(key, b"\xff\xff\xff\x7fnot a String")
        session.put(key, b"xy")
        for k in bogus:
            session.put(k, b"garbage payload")
    _put_until_heard(session, key, "fine after all", listener)
    for _ in range(30):  # and garbage again, once connected
        session.put(key, b"\xff\xff\xff\x7fnot a String")
    session.put(key, _string("the last one"))
    listener.read_until("I heard the last one", 20)
    bridge_text = pair.b.bridge.stop()
    heard = listener.stop()
    assert count_lines(bridge_text, f"dropping samples on {key}") == 1
    for k in bogus:
        assert count_lines(bridge_text, f"ignoring beacons on {k}") == 1
    assert "Traceback" not in bridge_text
    lines = [line for line in heard.splitlines() if line.strip()]
    assert set(lines) <= {"listening", "I heard fine after all", "I heard the last one"}, lines
    pair.b.start_bridge()  # the other tests go on with a fresh bridge b


def test_emulated_zenoh_bridge_ros1_peer_topics_services_and_loss(pair, session):
    """The test session speaks as zenoh-bridge-ros1 does: b's bridge must take its beacons,
    bodies and replies (an error as a plain text reply), and lose them 3 s after its beacons
    stop."""
    from minros.zenoh import keys

    peer = EmulatedBridge(session)
    try:
        topic_beacon = keys.discovery_key("pub", "/rt_6", "std_msgs/String", STRING_MD5)
        service_beacon = keys.discovery_key("srv", "/rt_srv_6", "std_srvs/SetBool", SETBOOL_MD5)
        data = peer.publisher(keys.data_key("/rt_6", "std_msgs/String", STRING_MD5))

        def answer(request: bytes) -> bytes:
            if request == b"\x01":
                return b"\x01\x02\x00\x00\x00ok"  # SetBoolResponse(True, "ok")
            return b"service cannot process request: false is refused"

        peer.queryable(keys.data_key("/rt_srv_6", "std_srvs/SetBool", SETBOOL_MD5), answer)
        peer.declare(topic_beacon)
        peer.declare(service_beacon)
        pair.b.bridge.read_until("bridging /rt_6 (std_msgs/String) Zenoh -> ROS", 20)
        pair.b.bridge.read_until("bridging /rt_srv_6 (std_srvs/SetBool) service Zenoh -> ROS", 20)
        listener = pair.b.python(LISTENER, "rt_6")
        listener.read_until("listening", 20)
        stop = threading.Event()

        def feed():
            while not stop.wait(0.05):
                data.put(_string("from the rust bridge"))
        feeder = threading.Thread(target=feed, daemon=True)
        feeder.start()
        try:
            listener.read_until("I heard from the rust bridge", 20)
        finally:
            stop.set()
            feeder.join(2)
        info = pair.b.tool("topic", "info", "/rt_6").stdout
        assert "Type: std_msgs/String" in info
        ok = pair.b.tool("service", "call", "/rt_srv_6", "data: true")
        assert "success: True" in ok.stdout and 'message: "ok"' in ok.stdout
        refused = pair.b.tool("service", "call", "/rt_srv_6", "data: false")
        assert refused.stderr.strip() == ("ERROR: service [/rt_srv_6] responded with an error: "
                                          "b'service cannot process request: false is refused'")
        # its beacons stop: b drops the topic and the service within LOST_AFTER + a tick (the
        # listener leaves first: a local subscriber keeps a topic bridged from Zenoh)
        listener.stop()
        peer.undeclare(topic_beacon)
        peer.undeclare(service_beacon)
        stopped = time.monotonic()

        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{pair.b.port}/")

        def listed() -> bool:  # asked directly: a tool process would take longer than that
            pubs, _subs, srvs = master.getSystemState("/test")[2]
            return any(t == "/rt_6" for t, _n in pubs) or any(s == "/rt_srv_6" for s, _n in srvs)
        wait_gone(listed, 6.0)
        assert time.monotonic() - stopped <= 3.5
        pair.b.bridge.read_until("lost remote pub /rt_6 (std_msgs/String)", 5)
    finally:
        peer.close()


def test_a_bridge_in_client_mode_goes_through_the_peer_it_connects_to(pair, tmp_path):
    from zenoh_support import Site

    client = Site("c", tmp_path, ["--mode", "client", "--connect", pair.endpoint])
    try:
        assert "(mode client, namespace *, connecting to" in client.banner
        pair.a.python(TALKER, "via_client_7", "20")
        client.python(LISTENER, "via_client_7").read_until("I heard hello", 30)
    finally:
        client.close()


def test_without_the_extra_the_bridge_says_how_to_get_it_and_keys_still_work(tmp_path):
    blocked = ("import sys; sys.modules['zenoh'] = None; from minros.cli.main import main; "
               "sys.exit(main(sys.argv[1:]))")
    env = ros_env(1, tmp_path)
    done = subprocess.run([PYTHON, "-c", blocked, "zenoh"], env=env, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.strip() == ("minros zenoh: error: the Zenoh bridge needs the eclipse-zenoh "
                                   "package, which minros installs as an extra: pip install "
                                   "minros[zenoh]")
    keys = subprocess.run([PYTHON, "-c", blocked, "zenoh", "keys", "/chatter", "--type",
                           "std_msgs/String"], env=env, capture_output=True, text=True, timeout=60)
    assert keys.returncode == 0, keys.stderr
    assert keys.stdout.strip() == f"7374645f6d7367732f537472696e67/{STRING_MD5}/*/chatter"
    plain = subprocess.run([PYTHON, "-c", "import sys; sys.modules['zenoh'] = None; "
                            "import minros.zenoh.keys, minros.zenoh.plan, minros.cli.zenoh; "
                            "print('ok')"], env=env, capture_output=True, text=True, timeout=60)
    assert plain.stdout.strip() == "ok", plain.stderr


def _threads(pid: int) -> int:
    from pathlib import Path

    status = Path(f"/proc/{pid}/status").read_text()
    return int(next(line for line in status.splitlines() if line.startswith("Threads:")).split()[1])


def test_a_beacon_flood_is_bounded_and_honest_topics_keep_flowing(tmp_path):
    """An attacker's script on the Zenoh link: beacons for 2,000 publishers, 500 subscribers
    and 200 services in 10 s, repeated as a bridge repeats them. Bridge b used to make a ROS
    publisher and a thread for each (1,167 publications and 1,204 threads); now at most
    --max-remote bridges for beacons alone, made at a bounded rate, no thread of their own,
    each bound said once, while a real topic a -> b keeps flowing and a new one is bridged."""
    from minros.zenoh import keys
    from zenoh_support import Pair

    require_zenoh()
    cap = 150
    pair = Pair(tmp_path, extra_args=["--max-remote", str(cap)])
    session = None
    try:
        talker = pair.a.python(TALKER, "honest_9", "20")
        listener = pair.b.python(LISTENER, "honest_9")
        listener.read_until("I heard", 30)
        bridge = pair.b.bridge
        # the bridge's steady count: some of its threads come and go each second (its own
        # beacons, the master's calls), so one sample may land 6 below the others
        threads_before = 0
        for _ in range(8):
            threads_before = max(threads_before, _threads(bridge.pid))
            time.sleep(0.25)
        heard: list = []
        stop = threading.Event()

        def count() -> None:
            while not stop.is_set():
                try:
                    listener.read_until("I heard", 0.5)
                except AssertionError:
                    continue
                heard.append(time.monotonic())
        counter = threading.Thread(target=count, daemon=True)
        counter.start()
        session = zenoh_session(pair.endpoint)
        flood = ([keys.discovery_key("pub", f"/flood_9/p{i}", "std_msgs/String", STRING_MD5)
                  for i in range(2000)]
                 + [keys.discovery_key("sub", f"/flood_9/s{i}", "std_msgs/String", STRING_MD5)
                    for i in range(500)]
                 + [keys.discovery_key("srv", f"/flood_9/v{i}", "std_srvs/SetBool", SETBOOL_MD5)
                    for i in range(200)])
        started = time.monotonic()
        peak = threads_before
        second = None
        while time.monotonic() - started < 16.0:
            elapsed = time.monotonic() - started
            for key in flood[:min(len(flood), int((elapsed + 1) * len(flood) / 10))]:
                session.put(key, b"")  # each beacon once a second, as a bridge sends them
            peak = max(peak, _threads(bridge.pid))
            if second is None and elapsed > 6.0:  # a new honest topic in the thick of it
                pair.a.python(TALKER, "honest_9b", "20")
                second = pair.b.python(LISTENER, "honest_9b")
                second_started = time.monotonic()
            time.sleep(max(0.0, 1.0 - (time.monotonic() - started) % 1.0))
        flood_end = time.monotonic()
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{pair.b.port}/")
        pubs, subs, srvs = master.getSystemState("/probe")[2]
        made = (sum(1 for t, _n in pubs if t.startswith("/flood_9"))
                + sum(1 for t, _n in subs if t.startswith("/flood_9"))
                + sum(1 for s, _n in srvs if s.startswith("/flood_9")))
        assert peak <= threads_before + 8, (threads_before, peak)
        assert 0 < made <= cap, made
        # the honest topic: 20 Hz throughout, no silence of a second
        stop.set()
        counter.join(2)
        during = [t for t in heard if started <= t <= flood_end]
        assert len(during) >= 0.8 * 20 * (flood_end - started), len(during)
        gaps = [b - a for a, b in zip(during, during[1:])]
        assert max(gaps) < 1.0, max(gaps)
        second.read_until("I heard", 10)
        assert time.monotonic() - second_started < 12.0
        session.close()
        session = None
        out = bridge.stop()
        talker.stop()
    finally:
        if session is not None:
            session.close()
        pair.close()
    assert "Traceback" not in out
    assert count_lines(out, "remote bridges are at their bound of 150") == 1
    assert count_lines(out, "bridges for remote beacons are made at most") == 1
    assert len(out.splitlines()) < 400, len(out.splitlines())

"""minros services <-> roscpp (a tiny C++ node built with g++ and pkg-config).

A roscpp client drives a minros node's ``~get_loggers``/``~set_logger_level`` (plain and
persistent connections, a missing service, a wrong md5); minros's ServiceProxy drives services
of a roscpp server using roscpp's own srv types. roscpp's handshake differs from rospy's
(``persistent`` always sent by the client, ``request_type``/``response_type`` in the server
header, an empty error string when a handler returns false), which is the point.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from support import PYTHON, Proc, build_roscpp, reference_env, ros_env

pytestmark = pytest.mark.interop

NODE_CPP = r'''
#include <ros/ros.h>
#include <roscpp/GetLoggers.h>
#include <roscpp/SetLoggerLevel.h>
#include <cstdio>
#include <string>
#include <vector>

static void show(const char* what, int i, bool ok, const roscpp::GetLoggers& g) {
  for (const auto& l : g.response.loggers)
    if (l.name == "rosout") printf("%s %d ok=%d rosout=%s\n", what, i, (int)ok, l.level.c_str());
  fflush(stdout);
}

static std::vector<roscpp::Logger> store;

static bool onSet(roscpp::SetLoggerLevel::Request& req, roscpp::SetLoggerLevel::Response&) {
  if (req.level == "fail") return false;  // roscpp answers ok=0 with an empty error string
  for (auto& l : store)
    if (l.name == req.logger) { l.level = req.level; return true; }
  roscpp::Logger l;
  l.name = req.logger;
  l.level = req.level;
  store.push_back(l);
  return true;
}

static bool onList(roscpp::GetLoggers::Request&, roscpp::GetLoggers::Response& res) {
  res.loggers = store;
  return true;
}

int main(int argc, char** argv) {
  std::string mode = argv[1];
  ros::init(argc, argv, mode == "server" ? "cpp_node" : "cpp_client");
  ros::NodeHandle nh;
  if (mode == "server") {
    // own services with roscpp's srv types (roscpp 1.15.15's built-in logger services crash
    // when called in some orders, with Debian's rospy as client too)
    ros::NodeHandle private_nh("~");
    ros::ServiceServer set = private_nh.advertiseService("set", onSet);
    ros::ServiceServer list = private_nh.advertiseService("list", onList);
    printf("READY\n");
    fflush(stdout);
    ros::spin();
    return 0;
  }
  std::string target = argv[2];
  if (!ros::service::waitForService(target + "/get_loggers", ros::Duration(20))) {
    printf("NO SERVICE\n");
    return 1;
  }
  roscpp::SetLoggerLevel s;
  s.request.logger = "rosout";
  s.request.level = "error";
  ros::ServiceClient set = nh.serviceClient<roscpp::SetLoggerLevel>(target + "/set_logger_level");
  printf("set ok=%d\n", (int)set.call(s));
  ros::ServiceClient get = nh.serviceClient<roscpp::GetLoggers>(target + "/get_loggers", true);
  for (int i = 0; i < 3; ++i) {
    roscpp::GetLoggers g;
    bool ok = get.call(g);
    show("persistent", i, ok, g);
  }
  printf("persistent valid=%d\n", (int)get.isValid());
  s.request.level = "info";
  set.call(s);
  ros::ServiceClient get2 = nh.serviceClient<roscpp::GetLoggers>(target + "/get_loggers");
  roscpp::GetLoggers g;
  show("plain", 0, get2.call(g), g);
  ros::ServiceClient missing = nh.serviceClient<roscpp::GetLoggers>("/no_such_service");
  printf("missing ok=%d\n", (int)missing.call(g));
  ros::ServiceClient wrong = nh.serviceClient<roscpp::SetLoggerLevel>(target + "/get_loggers");
  printf("wrong ok=%d\n", (int)wrong.call(s));
  printf("DONE\n");
  fflush(stdout);
  return 0;
}
'''

MINROS_NODE = r'''
import rospy
rospy.init_node("minros_node")
print("READY", flush=True)
rospy.spin()
'''


@pytest.fixture(scope="module")
def roscpp_node(tmp_path_factory) -> Path:
    """The C++ service node, compiled once per module."""
    return build_roscpp(NODE_CPP, "srv_node", tmp_path_factory.mktemp("roscpp_srv"),
                        required_headers=("/usr/include/roscpp/GetLoggers.h",))


def test_roscpp_client_against_minros_logger_services(roscpp_node, debian_rosmaster, ros_home,
                                                       tmp_path):
    env = ros_env(debian_rosmaster, ros_home)
    script = tmp_path / "minros_node.py"
    script.write_text(MINROS_NODE)
    node = Proc([PYTHON, str(script)], env)
    try:
        node.read_until("READY", 30)
        client = subprocess.run([str(roscpp_node), "client", "/minros_node"],
                                env=reference_env(env), capture_output=True, text=True, timeout=60)
    finally:
        node_out = node.stop()
    lines = client.stdout.splitlines()
    assert client.returncode == 0, client.stdout + client.stderr
    assert lines == [
        "set ok=1",
        "persistent 0 ok=1 rosout=error",
        "persistent 1 ok=1 rosout=error",
        "persistent 2 ok=1 rosout=error",
        "persistent valid=1",
        "plain 0 ok=1 rosout=info",
        "missing ok=0",
        "wrong ok=0",
        "DONE",
    ]
    assert "md5sums do not match" in node_out  # the server's warning for the wrong type


REF_CLIENT = r'''
import rospy
from roscpp.srv import SetLoggerLevel
try:
    rospy.ServiceProxy("/cpp_node/set", SetLoggerLevel)(logger="x", level="fail")
except rospy.ServiceException as e:
    print("ERR %s" % e, flush=True)
'''


def test_minros_client_against_roscpp_services(roscpp_node, debian_rosmaster, ros_home,
                                               monkeypatch, tmp_path):
    import minros
    from roscpp.srv import GetLoggers, SetLoggerLevel

    env = ros_env(debian_rosmaster, ros_home)
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    node = Proc([str(roscpp_node), "server"], reference_env(env))
    try:
        node.read_until("READY", 30)
        minros.wait_for_service("/cpp_node/list", timeout=20)
        setter = minros.ServiceProxy("/cpp_node/set", SetLoggerLevel)
        lister = minros.ServiceProxy("/cpp_node/list", GetLoggers, persistent=True)
        try:
            for i, level in enumerate(("debug", "warn", "error")):
                setter(logger=f"logger{i}", level=level)
                setter(f"logger{i}", level.upper())  # positional fields
                got = [(lg.name, lg.level) for lg in lister().loggers]
                assert got[-1] == (f"logger{i}", level.upper()) and len(got) == i + 1
        finally:
            lister.close()
        header = minros.ServiceProxy("/cpp_node/list", GetLoggers)()._connection_header
        assert header["type"] == "roscpp/GetLoggers"
        assert header["request_type"] == "roscpp/GetLoggersRequest"
        assert header["response_type"] == "roscpp/GetLoggersResponse"
        # a handler returning false: ok=0 and an empty error string, worded as rospy words it
        script = tmp_path / "ref_client.py"
        script.write_text(REF_CLIENT)
        ref = subprocess.run(["/usr/bin/python3", str(script)], env=reference_env(env),
                             capture_output=True, text=True, timeout=60)
        with pytest.raises(minros.ServiceException) as info:
            setter(logger="x", level="fail")
        assert ref.stdout.strip() == f"ERR {info.value}"
        assert str(info.value) == "service [/cpp_node/set] responded with an error: b''"
        with pytest.raises(minros.ServiceException) as info:
            minros.ServiceProxy("/cpp_node/list", SetLoggerLevel)(logger="x", level="info")
        assert str(info.value).startswith("unable to connect to service: remote error reported: ")
        assert "md5" in str(info.value)
    finally:
        node.stop()

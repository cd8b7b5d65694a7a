"""rosgraph.impl.graph.Graph on a live graph: a talker and a listener under minros's core."""

from __future__ import annotations

from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env, wait_until

TALKER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("talker")
pub = rospy.Publisher("/chatter", String, queue_size=1)
rospy.Service("/talker/ping", __import__("std_srvs.srv", fromlist=["Empty"]).Empty, lambda r: [])
while not rospy.is_shutdown():
    pub.publish(String("hi"))
    rospy.sleep(0.05)
'''

LISTENER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("listener")
rospy.Subscriber("/chatter", String, lambda m: None)
rospy.spin()
'''


@pytest.mark.smoke
def test_graph_follows_nodes_topics_and_connections(minros_core: int, ros_home: Path, tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch):
    from rosgraph.impl.graph import Edge, Graph, topic_node

    env = ros_env(minros_core, ros_home)
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    (tmp_path / "talker.py").write_text(TALKER)
    (tmp_path / "listener.py").write_text(LISTENER)
    talker = Proc([PYTHON, str(tmp_path / "talker.py")], env)
    listener = Proc([PYTHON, str(tmp_path / "listener.py")], env)
    try:
        graph = Graph()
        graph.set_master_stale(0.0)
        graph.set_node_stale(0.0)

        def connected() -> bool:
            graph.update()
            # the talker registers its service on its own schedule: wait for it too
            return (Edge("/talker", "/listener", "/chatter") in graph.nn_edges
                    and "/talker/ping" in graph.srvs)

        wait_until(connected, 20, what="talker -> listener edge and /talker/ping")
        assert {"/talker", "/listener"} <= graph.nn_nodes
        assert topic_node("/chatter") in graph.nt_nodes and "/talker/ping" in graph.srvs
        assert Edge("/talker", " /chatter") in graph.nt_edges
        assert Edge(" /chatter", "/listener") in graph.nt_all_edges
        listener.stop()
        wait_until(lambda: (graph.update(), "/listener" not in graph.nn_nodes)[1], 20,
                   what="the listener purged")
        assert not any(e.end == "/listener" or e.start == "/listener" for e in graph.nn_edges)
        assert graph.bad_nodes == {}
    finally:
        listener.stop()
        talker.stop()


def test_rosgraph_command_prints_peers_and_services(minros_core: int, ros_home: Path,
                                                    tmp_path: Path) -> None:
    """``rosgraph`` (here ``--once``): each node's inbound and outbound peers, then the services,
    in ROS's layout."""
    import subprocess

    env = ros_env(minros_core, ros_home)
    (tmp_path / "talker.py").write_text(TALKER)
    (tmp_path / "listener.py").write_text(LISTENER)
    talker = Proc([PYTHON, str(tmp_path / "talker.py")], env)
    listener = Proc([PYTHON, str(tmp_path / "listener.py")], env)
    try:
        def printed() -> str:
            out = subprocess.run([PYTHON, "-m", "minros", "links", "--once"], env=env,
                                 capture_output=True, text=True, timeout=30)
            assert out.returncode == 0, out.stderr
            return out.stdout

        text = ""

        def connected() -> bool:
            nonlocal text
            text = printed()
            # the talker registers its service on its own schedule: wait for both
            return ("  /listener :\n    Inbound:\n      /talker\n" in text
                    and "  /talker/ping\n" in text)

        wait_until(connected, 20, what="the listener's inbound peer and /talker/ping")
        assert text.startswith("\n\nNodes:\n")
        assert "  /talker :\n    Inbound:\n    Outbound:\n      /listener\n" in text
        assert "Services:\n" in text and "  /talker/ping\n" in text
    finally:
        listener.stop()
        talker.stop()


def test_rosgraph_command_without_master_and_with_bad_arguments(ros_home: Path) -> None:
    import subprocess

    from support import free_port

    env = ros_env(free_port(), ros_home)
    out = subprocess.run([PYTHON, "-m", "minros", "links"], env=env, capture_output=True,
                         text=True, timeout=30)
    assert (out.returncode, out.stderr) == (0, "ERROR: Unable to communicate with master!\n")
    out = subprocess.run([PYTHON, "-m", "minros", "links", "extra"], env=env,
                         capture_output=True, text=True, timeout=30)
    assert out.returncode == 255 and out.stdout.startswith("rosgraph is a command-line tool")

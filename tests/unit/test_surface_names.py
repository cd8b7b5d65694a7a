"""Small names of ROS's modules that carry state or behaviour: actionlib's goal counters,
resource_retriever's RosPack, rosbag's LZ4 flag, bondpy's duration helpers, the message
classes ROS's modules hand on (the same classes as the message packages')."""

from __future__ import annotations

import importlib.util


def test_actionlib_goal_counters_follow_the_ids_made(monkeypatch) -> None:
    from minros.client import rostime

    monkeypatch.setattr(rostime._clock, "initialized", True)  # Time.now() without a node
    import actionlib
    import actionlib.action_client as client
    import actionlib.goal_id_generator as generator
    from minros.actionlib.client import GoalManager
    from minros.actionlib.server import GoalIDGenerator

    before = client.g_goal_id
    GoalManager.__new__(GoalManager)._generate_id()
    assert client.g_goal_id == actionlib.g_goal_id == before + 1
    issued = generator.s_goalcount
    goal_id = GoalIDGenerator("/srv").generate_ID()
    assert generator.s_goalcount == issued + 1
    assert goal_id.id.startswith(f"/srv-{issued + 1}-")


def test_resource_retriever_rospack_and_rosbag_lz4_flag() -> None:
    import resource_retriever
    import rosbag.bag

    assert resource_retriever.r.get_path("std_msgs").endswith("std_msgs")
    assert resource_retriever.r is resource_retriever.r  # made once
    assert rosbag.bag.found_lz4 == (importlib.util.find_spec("lz4") is not None)


def test_bondpy_durations_and_reexported_messages() -> None:
    import minros
    import tf2_ros
    from bondpy import bondpy
    from geometry_msgs.msg import TransformStamped
    from std_msgs.msg import Header

    assert bondpy.as_ros_duration(1.5) == minros.Duration(1, 500000000)
    assert bondpy.as_ros_duration(minros.Duration(2)) == minros.Duration(2)
    assert bondpy.as_float_duration(minros.Duration(2, 500000000)) == 2.5
    assert bondpy.as_float_duration(3) == 3
    assert tf2_ros.TransformStamped is TransformStamped and tf2_ros.Header is Header
    assert bondpy.Status._type == "bond/Status"


def test_names_ros_modules_take_from_their_neighbours_are_the_same_objects() -> None:
    """ROS's modules import classes and helpers from their neighbours (roslaunch.nodeprocess
    from roslaunch.core, genmsg.msg_loader from genmsg.msgs, rosmaster.master_api from
    rosmaster.validators): code finds them there, and they are the neighbours' own."""
    import genmsg.msg_loader
    import genmsg.msgs
    import rosgraph.names
    import roslaunch
    import roslaunch.core
    import roslaunch.loader
    import roslaunch.nodeprocess
    import roslaunch.pmon
    import roslaunch.xmlloader
    import rosmaster.master_api
    import rosmaster.validators
    import rosunit.baretest
    import rosunit.core

    assert roslaunch.nodeprocess.Node is roslaunch.core.Node
    assert roslaunch.nodeprocess.Process is roslaunch.pmon.Process
    assert roslaunch.nodeprocess.PHASE_SETUP == roslaunch.loader.PHASE_SETUP == "setup"
    assert roslaunch.Node is roslaunch.core.Node and roslaunch.NAME == "roslaunch"
    assert roslaunch.xmlloader.ns_join is rosgraph.names.ns_join
    assert genmsg.msg_loader.MsgSpec is genmsg.msgs.MsgSpec
    assert genmsg.msg_loader.HEADER_FULL_NAME == "std_msgs/Header"
    assert rosmaster.master_api.is_topic is rosmaster.validators.is_topic
    assert (rosmaster.master_api.STATUS, rosmaster.master_api.MSG, rosmaster.master_api.VAL) == (0, 1, 2)
    assert rosunit.baretest.xml_results_file is rosunit.core.xml_results_file

"""actionlib_tools: ROS's action helpers (DynamicAction, the YAML message helpers) and a
headless ``axclient``: ROS's axclient and axserver are wxPython windows; minros's axclient
sends one goal given as YAML and prints the feedback and the result (``rosrun
actionlib_tools axclient.py /name [pkg/TypeAction] --goal 'a: 1'``), and there is no
axserver."""

from minros.actionlib_tools.dynamic_action import DynamicAction

__all__ = ["DynamicAction"]

"""joint_state_publisher: the robot's movable joints on ``joint_states``, at their default
positions or at what ``source_list`` topics say, with mimic joints following their joint and
ROS's parameters (``rate``, ``publish_default_positions|velocities|efforts``, ``zeros``,
``use_mimic_tags``, ``use_smallest_joint_limits``, ``dependent_joints``, ``delta``). The
program is ``rosrun joint_state_publisher joint_state_publisher`` (no GUI: the sliders of
joint_state_publisher_gui are not there)."""

from minros.joint_state_publisher.joints import JointTable

__all__ = ["JointTable", "JointStatePublisher", "get_param"]


def __getattr__(name: str):
    # the publisher needs a node runtime: imported when first used
    if name in ("JointStatePublisher", "get_param"):
        from minros.joint_state_publisher import publisher

        return getattr(publisher, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

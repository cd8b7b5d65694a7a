"""urdf_parser_py, ROS 1's URDF library (stand-in: ``stubs/urdf_parser_py``), in pure Python
over xml.etree: ``urdf.URDF`` reads and writes robot descriptions; ``xml_reflection`` is the
declarative XML mapping its classes are written in.

    from urdf_parser_py.urdf import URDF
    robot = URDF.from_parameter_server()          # or from_xml_string(text), from_xml_file(path)
    robot.get_chain(robot.get_root(), "tool0")    # ['base_link', 'joint1', 'link1', ...]

(``minros.urdf_model`` is the smaller reader robot_state_publisher and joint_state_publisher
use: joints only.)
"""

from .urdf import URDF, Robot

__all__ = ["URDF", "Robot"]

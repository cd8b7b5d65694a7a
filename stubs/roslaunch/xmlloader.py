"""roslaunch.xmlloader: launch XML into a ROSLaunchConfig (minros.launch.rosmodel over
minros's loader)."""

from rospkg.common import ResourceNotFound  # noqa: E402, F401

from minros.launch.rosmodel import XmlLoader, XmlParseException  # noqa: F401
from rosgraph.names import get_ros_namespace, is_legal_name, is_private, make_global_ns, ns_join  # noqa: E402, F401
from roslaunch.core import Machine, Node, Param, RLException, Test  # noqa: E402, F401
from roslaunch.substitution_args import ArgException, SubstitutionException  # noqa: E402, F401

CLEAR_PARAMS = "clear_params"
NS = "ns"

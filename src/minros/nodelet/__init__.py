"""nodelet for Python: nodelets loaded into a manager process, on ROS's services and bonds.

A manager (``rosrun nodelet nodelet manager __name:=mgr``) offers ``mgr/load_nodelet``,
``mgr/unload_nodelet`` and ``mgr/list`` (nodelet/NodeletLoad, NodeletUnload, NodeletList)
and keeps a bond on ``mgr/bond`` with each loader, unloading the nodelet when its loader
dies, as ROS's C++ manager does; ``nodelet load|unload|standalone`` are the clients. The
nodelets minros loads are Python classes deriving from :class:`Nodelet`, declared in a
package's plugin file like C++ ones (``<class name="pkg/Type" type="pkg.module.Class"
base_class_type="nodelet::Nodelet"/>``, a Python dotted path instead of a C++ type).
"""

from minros.nodelet.loader import Loader, LoaderROS
from minros.nodelet.nodelet import Nodelet
from minros.nodelet.plugins import NodeletTypeError, declared_nodelets, find_class

__all__ = ["Nodelet", "Loader", "LoaderROS", "NodeletTypeError", "declared_nodelets",
           "find_class"]

"""rospy's internal modules (rospy.core, rospy.names, rospy.impl.*) over minros's node and
client library.

Real rospy code and its tests reach below rospy's public API: they read the topic manager,
set a caller id, call the TCPROS handler a connection header, make a TCPROSTransport. These
modules keep rospy's names, classes and behaviour, and do the work with minros's objects:
the topic and service managers are views of the process's :class:`minros.node.Node`
registries, the transports speak TCPROS through :mod:`minros.wire.tcpros` and
:mod:`minros.wire.sockets`, the validators are :mod:`minros.wire.rosapi`'s.

They are adapters: the node runtime and client library keep their own shape, and these
modules only translate (so they stay small and follow the runtime when it changes).
"""

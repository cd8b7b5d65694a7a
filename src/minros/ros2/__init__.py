"""minros and ROS 2: the types both worlds share, the DDS wire, a ROS 2 node, the bridge.

The package, bottom up (each part imports only from the parts below it and from minros's
layers under it):

``types/``
    ROS 2 interface types as pure code: the definitions of the common ROS 2 packages bundled
    per distro (Jazzy, Kilted, Humble; verbatim from upstream, ``types/share/<distro>/
    SOURCES.md``), the ``.msg``/``.srv``/``.action`` parser, type descriptions and RIHS01 hashes
    (REP-2011), plain CDR codecs generated per type, the ROS 1 <-> ROS 2 type mapping by
    ros1_bridge's rules (with ROS 2 types made from ROS 1 definitions that have none), and the
    generated ROS 1 <-> CDR byte converters the bridge and bag conversion run per message.
    Sits on :mod:`minros.msgs` (the ROS 1 message system) and nothing else of minros.
``rtps/``
    DDSI-RTPS: the wire (messages, parameter lists), discovery data (SPDP, SEDP, QoS matching),
    reliable and best-effort writers and readers as state machines (fragments, flow control),
    all without I/O, and ``participant``, the thin UDP layer on loopback under them.
``rmw/``
    What ROS 2's middleware puts on DDS: nodes, rmw's topic and type names, QoS profiles,
    the graph (``ros_discovery_info``), services and clients in each vendor's form.
the bridge
    ``minros ros2``, joining a ROS 1 graph to a ROS 2 domain, on ``rmw`` and ``types``.

Importing this package imports nothing.
"""

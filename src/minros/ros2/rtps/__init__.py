"""DDSI-RTPS 2.x in pure Python: the wire protocol DDS (and so ROS 2) speaks.

The layers, each importing only those below it (an import-linter contract in pyproject.toml):

``participant``  the I/O: UDP sockets on loopback, three threads (discovery receive, user
                 data receive, timer), SPDP announcements and leases, SEDP, matching
``reader`` | ``writer``  the reliable and best-effort reader and writer as state machines
                 without I/O, driven by submessages and ``tick(now)``, returning datagrams
``discovery``    SPDP participant data, SEDP endpoint data, the QoS matching rules, ports
``endpoint``     what the state machines hand the I/O layer (Datagram, Sample)
``messages`` | ``params``  the wire: the message header, submessages, parameter lists
``guid``         GUIDs, entity ids, vendor ids

Everything below ``participant`` is pure: no sockets, no threads, no clock (the caller says
what time it is). ``docs/ros2.md`` teaches the protocol from captures of real peers.
"""

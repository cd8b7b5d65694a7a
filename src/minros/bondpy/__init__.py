"""bondpy: bonds between two processes (ROS's bond_core), in pure Python.

Two ``Bond`` objects with one topic and id find each other through ``bond/Status``
heartbeats; each learns when the other dies (a dead heartbeat, or none for
``heartbeat_timeout``). nodelet uses bonds to unload a nodelet whose loader died. The
state machine (ROS generates it with SMC from BondSM.sm) is the table in ``states``.
"""

from minros.bondpy.bond import Bond, Timeout

__all__ = ["Bond", "Timeout"]

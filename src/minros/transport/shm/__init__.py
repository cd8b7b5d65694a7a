"""MINROSSHM: topics between minros nodes of one host through shared memory (the protocol,
without I/O, is ``minros.wire.shm``; its docstring is the specification). By job:

* ``segment``: what it asks of the kernel (whether this process may use it, the publisher's
  sealed memfd, the subscriber's read-only mapping);
* ``sender``: the publisher's end, the queued sender of ``minros.transport.sender`` with
  shared memory's wire (a large frame copied once into a slot and announced; small ones
  inline);
* ``receiver``: the subscriber's end (messages read in place, slots given back);
* ``handler``: the protocol the node speaks (offer, answer, connect, accept).

Anything that goes wrong with shared memory (the kernel refusing a memfd or its seal, a
segment that cannot be allocated or mapped, a peer sending garbage, the publisher's socket
refusing the connection) ends the connection with
:class:`~minros.transport.base.FallBack`: the subscriber asks again, offering only TCPROS.
"""

from minros.transport.shm.handler import ShmHandler
from minros.transport.shm.receiver import ShmReceiver, own
from minros.transport.shm.segment import ENV, TRACE_ENV, Loan, ShmSegment, boot_id, supported
from minros.transport.shm.sender import ShmSender

__all__ = ["ENV", "TRACE_ENV", "Loan", "ShmHandler", "ShmReceiver", "ShmSegment", "ShmSender",
           "boot_id", "own", "supported"]

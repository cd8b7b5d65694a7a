"""What the writer and reader state machines exchange with the code that owns the sockets.

A state machine never sends: it returns :class:`Datagram` objects (where to, and the buffers
to send in one ``sendmsg``, a payload among them as a view, not a copy), and it is told the
time (``now``, seconds on a monotonic clock) by whoever calls it. A reader hands what it
delivers back as :class:`Sample` objects.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple, Union

__all__ = ["Address", "Datagram", "MAX_DATAGRAM", "Sample"]

#: (host, port) of a UDP locator
Address = Tuple[str, int]
Buffer = Union[bytes, bytearray, memoryview]

#: the largest datagram minros sends (a UDP/IPv4 payload is at most 65507 bytes)
MAX_DATAGRAM = 65_000


class Datagram:
    """One RTPS message to send to each of ``addresses``."""

    __slots__ = ("addresses", "buffers", "size")

    def __init__(self, addresses: Sequence[Address], buffers: List[Buffer]) -> None:
        self.addresses = addresses
        self.buffers = buffers
        self.size = sum(len(b) for b in buffers)

    def tobytes(self) -> bytes:
        """The datagram as one bytes object (tests; the runtime sends the buffers as they are)."""
        return b"".join(bytes(b) for b in self.buffers)

    def __repr__(self) -> str:
        return f"Datagram({list(self.addresses)}, {self.size} bytes)"


class Sample:
    """A sample a reader delivers: the writer's GUID and sequence number, the serialized
    payload (its encapsulation header first), the source time (ns) and the inline QoS."""

    __slots__ = ("writer", "sn", "payload", "timestamp", "inline_qos", "little")

    def __init__(self, writer: bytes, sn: int, payload: Buffer, timestamp: Optional[int],
                 inline_qos: Optional[bytes], little: bool = True) -> None:
        self.writer = writer
        self.sn = sn
        self.payload = payload
        self.timestamp = timestamp
        #: the raw inline QoS parameter list (without sentinel), or None
        self.inline_qos = inline_qos
        #: the byte order of ``inline_qos``
        self.little = little

    def __repr__(self) -> str:
        return f"Sample(sn={self.sn}, {len(self.payload)} bytes)"

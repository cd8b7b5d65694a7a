"""Service introspection the tools share: a server's connection header, read through a probe.

``rosservice type``/``info``/``args`` and ``minros web`` learn a service's type and md5sum the
way rosservice does: connect to its ``rosrpc://`` URI, send a header with ``probe=1`` (and md5sum
``*``), and read the header the server answers with; no request is sent. The connection is a
service client's end of the transport seam (``minros.transport.tcpros_service``).
"""

from __future__ import annotations

from typing import Dict

from minros.transport.tcpros_service import connect_service
from minros.wire.rosapi import parse_rosrpc_uri

__all__ = ["PROBE_TIMEOUT", "probe_service"]

#: bound on the whole probe (connect and header), in seconds
PROBE_TIMEOUT = 5.0
#: a service's answer is a handful of fields: a bigger header is refused
MAX_HEADER = 1 << 16


def probe_service(uri: str, service: str, caller_id: str,
                  timeout: float = PROBE_TIMEOUT) -> Dict[str, str]:
    """The connection header the server of ``service`` at ``uri`` answers a probe with.

    rosapi.ParameterInvalid for a malformed URI; OSError (refused, timed out) or
    tcpros.HeaderError when the server cannot be asked or answers garbage.
    """
    host, port = parse_rosrpc_uri(uri)
    end = connect_service(host, port, service, timeout)
    try:
        return end.probe({"probe": "1", "md5sum": "*", "callerid": caller_id,
                          "service": service}, MAX_HEADER)
    finally:
        end.close()

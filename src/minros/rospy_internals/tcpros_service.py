"""rospy.impl.tcpros_service: the TCPROS protocol of services (header fields of each side),
the conversion of a handler's return value, and the check of an inbound service connection
against the service manager. Service, ServiceProxy and wait_for_service are minros's."""

from __future__ import annotations

import socket
import threading
from typing import Any, Dict, Optional

from minros import node as _node
from minros.client.services import Service, ServiceProxy, wait_for_service  # noqa: F401
from minros.client.services import _convert_return_to_response as convert_return_to_response
from minros.names import SERVICE_ANYTYPE

from .registration import get_service_manager
from .tcpros_base import DEFAULT_BUFF_SIZE, TCPROSTransport, TCPROSTransportProtocol
from .transport import BIDIRECTIONAL

__all__ = ["Service", "ServiceProxy", "TCPROSServiceClient", "TCPService",
           "convert_return_to_response", "service_connection_handler", "wait_for_service"]


def service_connection_handler(sock: socket.socket, client_addr: Any,
                               header: Dict[str, str]) -> Optional[str]:
    """Check a client's header against the service manager and serve it in a thread; the error
    text to send back when it cannot be served."""
    for required in ("service", "md5sum", "callerid"):
        if required not in header:
            return f"Missing required '{required}' field"
    name, md5sum = header["service"], header["md5sum"]
    service = get_service_manager().get_service(name)
    if not service:
        return f"[{_node.get_caller_id()}] is not a provider of  [{name}]"
    actual = service.service_class._md5sum
    if md5sum != SERVICE_ANYTYPE and md5sum != actual:
        return f"request from [{header['callerid']}]: md5sums do not match: [{md5sum}] vs. [{actual}]"
    handle = getattr(service, "handle", None)
    protocol = getattr(service, "protocol", None)
    if handle is None or protocol is None:
        return f"[{_node.get_caller_id()}] cannot serve [{name}] on this connection"
    transport = TCPROSTransport(protocol, name, header=header)
    transport.set_socket(sock, header["callerid"])
    transport.write_header()
    threading.Thread(target=handle, args=(transport, header), daemon=True).start()
    return None


class TCPService(TCPROSTransportProtocol):
    """The server's side of a service connection."""

    def __init__(self, resolved_name: str, service_class: Any,
                 buff_size: int = DEFAULT_BUFF_SIZE) -> None:
        super().__init__(resolved_name, service_class._request_class, buff_size=buff_size)
        self.service_class = service_class
        self.direction = BIDIRECTIONAL

    def get_header_fields(self) -> Dict[str, str]:
        cls = self.service_class
        return {"service": self.resolved_name, "type": cls._type, "md5sum": cls._md5sum,
                "callerid": _node.get_caller_id()}


class TCPROSServiceClient(TCPROSTransportProtocol):
    """The client's side of a service connection (``headers``: extra fields, e.g.
    ``persistent``)."""

    def __init__(self, resolved_name: str, service_class: Any,
                 headers: Optional[Dict[str, str]] = None,
                 buff_size: int = DEFAULT_BUFF_SIZE) -> None:
        super().__init__(resolved_name, service_class._response_class, buff_size=buff_size)
        self.service_class = service_class
        self.headers = headers or {}
        self.direction = BIDIRECTIONAL

    def get_header_fields(self) -> Dict[str, str]:
        fields = {"service": self.resolved_name, "md5sum": self.service_class._md5sum,
                  "callerid": _node.get_caller_id()}
        fields.update(self.headers)
        return fields

"""rosgraph.xmlrpc: an XML-RPC server of the ROS kind (a master, a node's slave API, a
roslaunch child), bound and named by ROS's environment rules, on minros's server.

``XmlRpcNode(port, handler).start()`` serves ``handler``'s public methods from a thread: it
binds where ROS_IP/ROS_HOSTNAME say (loopback when they name this host's loopback), sets
``uri`` from the same rules, then calls ``handler._ready(uri)``; ``shutdown(reason)`` calls
``handler._shutdown(reason)``. :class:`ThreadingXMLRPCServer` keeps socketserver's shape
(``register_instance``, ``serve_forever``) over :class:`minros.wire.xmlrpc.XmlRpcServer`,
so the connections are admitted and bounded as every minros server's are.
"""

from __future__ import annotations

import errno
import logging
import socket
import threading
from typing import Any, Callable, Optional, Tuple

from minros import rosenv

from .xmlrpc import Dispatcher, XmlRpcServer

_logger = logging.getLogger("xmlrpc")


class XmlRpcHandler:
    """Base of XmlRpcNode handlers: public methods are the XML-RPC methods."""

    def _ready(self, uri: str) -> None:
        """Called once the server has its URI."""

    def _shutdown(self, reason: str) -> None:
        """Called when the server shuts down."""


class ThreadingXMLRPCServer:
    """A bound XML-RPC server with socketserver's method names (each connection served by a
    thread of its own, as socketserver's ThreadingMixIn does)."""

    def __init__(self, addr: Tuple[str, int], log_requests: int = 1) -> None:
        host, port = addr
        self._server = XmlRpcServer(None, host, int(port or 0), what="this XML-RPC server")
        self._server.start()
        self.server_address = (host, self._server.port)

    @property
    def socket(self) -> Optional[socket.socket]:
        return self._server._sock

    def register_instance(self, instance: Any, allow_dotted_names: bool = False) -> None:
        self._server.dispatcher = Dispatcher(instance)

    def register_multicall_functions(self) -> None:
        """system.multicall is always served."""

    def register_introspection_functions(self) -> None:
        """system.listMethods is always served."""

    def serve_forever(self, poll_interval: float = 0.5) -> None:
        self._server.serve_forever()

    def shutdown(self) -> None:
        self._server.shutdown()

    server_close = shutdown


class XmlRpcNode:
    """An XML-RPC server for ``rpc_handler`` on ``port`` (0: any), named by ``uri`` once up."""

    def __init__(self, port: Any = 0, rpc_handler: Any = None,
                 on_run_error: Optional[Callable[[Exception], Any]] = None) -> None:
        self.handler = rpc_handler
        self.uri: Optional[str] = None
        self.server: Any = None
        self.port = int(port) if isinstance(port, str) and port else port
        self.is_shutdown = False
        self.on_run_error = on_run_error

    def shutdown(self, reason: str) -> None:
        """Stop serving; the handler's ``_shutdown(reason)`` is called."""
        self.is_shutdown = True
        if self.server:
            server, handler = self.server, self.handler
            self.handler = self.server = self.port = self.uri = None
            if handler:
                handler._shutdown(reason)
            server.shutdown()

    def start(self) -> None:
        """Serve from a thread of its own."""
        threading.Thread(target=self.run, name="xmlrpc-node", daemon=True).start()

    def set_uri(self, uri: str) -> None:
        self.uri = uri

    def run(self) -> None:
        try:
            self._run()
        except Exception as exc:
            if self.is_shutdown:
                pass
            elif self.on_run_error is not None:
                self.on_run_error(exc)
            else:
                raise

    def _run_init(self) -> None:
        port = self.port or 0
        bind_address = rosenv.get_bind_address()
        _logger.info("XML-RPC server binding to %s:%d", bind_address, port)
        try:
            self.server = ThreadingXMLRPCServer((bind_address, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                msg = f"ERROR: Unable to start XML-RPC server, port {port} is already in use"
            else:
                msg = f"ERROR: Unable to start XML-RPC server: {exc.strerror}"
            _logger.error(msg)
            print(msg)
            raise
        self.port = self.server.server_address[1]
        self.set_uri(rosenv.create_local_xmlrpc_uri(self.port))
        _logger.info("Started XML-RPC server [%s]", self.uri)
        self.server.register_multicall_functions()
        self.server.register_instance(self.handler)
        if self.handler is not None:
            self.handler._ready(self.uri)

    def _run(self) -> None:
        self._run_init()
        while not self.is_shutdown:
            try:
                self.server.serve_forever()
                break  # returns only once the server is shut down
            except OSError as exc:
                if self.is_shutdown:
                    pass
                elif exc.errno != errno.EINTR:
                    self.is_shutdown = True
                    _logger.error("serve forever IOError: %s, %s", exc.errno, exc.strerror)

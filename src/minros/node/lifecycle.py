"""A node's lifecycle: initialised once, shut down once, with the hooks in between.

``signal_shutdown`` runs the client hooks (rospy.on_shutdown) while ``is_shutdown()`` is still
false, then the internal ones (the client library's own, given the reason), then ``close``
(the node's: unregister, close connections, stop servers). A second call waits for the first
to finish, unless it is that very call coming back (a hook that shuts down again).
"""

from __future__ import annotations

import logging
import sys
import threading
import traceback
from typing import Any, Callable, List, Tuple

from minros.exceptions import ROSException, ROSInitException

__all__ = ["Lifecycle"]

_logger = logging.getLogger("minros.node")


class Lifecycle:
    """Init and shutdown of one node; ``close()`` ends it (called once, by the shutdown)."""

    def __init__(self, close: Callable[[], None]) -> None:
        self._close = close
        self._lock = threading.Lock()  # a leaf
        #: True once init_node registered the node (publishing is allowed from then on)
        self.initialized = False
        #: the arguments init_node was called with (a second call must repeat them)
        self.init_args: Tuple[Any, ...] | None = None
        self._requested = False
        self._shutdown = threading.Event()  # set once is_shutdown() is true
        self._done = threading.Event()  # set when the shutdown sequence has finished
        self._thread: threading.Thread | None = None
        self._client_hooks: List[Callable[[], Any]] = []
        self._internal_hooks: List[Callable[[str], Any]] = []

    def claim_init(self, args_key: Tuple[Any, ...]) -> bool:
        """Whether this init_node call is the first; False when it repeats the first one's
        arguments, ROSException when it has others."""
        with self._lock:
            if self.init_args is not None:
                if self.init_args != args_key:
                    raise ROSException("rospy.init_node() has already been called with "
                                       "different arguments: " + str(self.init_args))
                return False
            self.init_args = args_key
            return True

    def is_shutdown(self) -> bool:
        return self._shutdown.is_set()

    def is_shutdown_requested(self) -> bool:
        return self._requested or self._shutdown.is_set()

    def wait_for_shutdown(self, timeout: float | None) -> bool:
        """Block up to ``timeout`` seconds; True if the node is (or becomes) shut down."""
        return self._shutdown.wait(timeout)

    def on_shutdown(self, hook: Callable[[], Any]) -> None:
        """Call ``hook()`` when the node shuts down, before it unregisters from the master."""
        if not callable(hook):
            raise TypeError(f"shutdown hook [{hook}] must be a function or callable object: {type(hook)}")
        with self._lock:
            run_now = self._shutdown.is_set()
            if not run_now:
                self._client_hooks.append(hook)
        if run_now:
            hook()

    def add_shutdown_hook(self, hook: Callable[[str], Any]) -> None:
        """Internal: ``hook(reason)`` runs during shutdown after the client hooks."""
        with self._lock:
            self._internal_hooks.append(hook)

    def signal_shutdown(self, reason: str) -> None:
        """Client hooks, internal hooks, then close(); see the module docstring."""
        with self._lock:
            first = not self._requested
            if first:
                self._requested = True
                self._thread = threading.current_thread()
                client_hooks, self._client_hooks = self._client_hooks, []
            else:
                in_progress_here = self._thread is threading.current_thread()
        if not first:
            if not in_progress_here:
                self._done.wait(5.0)
            return
        try:
            _logger.info("signal_shutdown [%s]", reason)
            for hook in client_hooks:
                try:
                    hook()
                except Exception:
                    traceback.print_exc()
            self._shutdown.set()
            with self._lock:
                internal, self._internal_hooks = self._internal_hooks, []
            for internal_hook in internal:
                try:
                    internal_hook(reason)
                except Exception as exc:
                    sys.stderr.write(f"signal_shutdown hook error[{exc}]\n")
            self._close()
        finally:
            self._done.set()

    def spin(self) -> None:
        """Block until the node is shut down."""
        if not self.initialized:
            raise ROSInitException("client code must call rospy.init_node() first")
        try:
            while not self._shutdown.wait(0.5):
                pass
        except KeyboardInterrupt:
            self.signal_shutdown("keyboard interrupt")

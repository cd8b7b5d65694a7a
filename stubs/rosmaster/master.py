"""rosmaster.master: a running master (minros.master.server.Master)."""

from __future__ import annotations

from typing import Optional

from minros.master import server as _master

from .master_api import NUM_WORKERS

DEFAULT_MASTER_PORT = _master.DEFAULT_MASTER_PORT


class Master:
    """``Master(port, num_workers).start()``; ``ok()`` until ``stop()`` or a ``shutdown`` call."""

    def __init__(self, port: int = DEFAULT_MASTER_PORT, num_workers: int = NUM_WORKERS) -> None:
        self.port = port
        self.num_workers = num_workers
        self.handler = None
        self.master_node: Optional[_master.Master] = None
        self.uri: Optional[str] = None

    def start(self) -> None:
        node = _master.Master(self.port, workers=max(1, self.num_workers)).start()
        self.master_node, self.handler, self.uri = node, node.handler, node.uri

    def ok(self) -> bool:
        return self.master_node is not None and self.master_node.ok()

    def stop(self) -> None:
        if self.master_node is not None:
            self.master_node.stop()
            self.master_node = None

"""rosmaster.main: the rosmaster command (minros.master.server.main)."""

from __future__ import annotations

import os
import sys
from typing import IO, Mapping, Sequence

from minros.master import server as _master


def rosmaster_main(argv: Sequence[str] = sys.argv, stdout: IO[str] = sys.stdout,
                   env: Mapping[str, str] = os.environ) -> None:
    """Run a master until it is shut down: ``rosmaster --core [-p PORT] [-w N] [-t SECS]``."""
    sys.exit(_master.main(list(argv[1:]), prog="rosmaster"))


NUM_WORKERS = 3

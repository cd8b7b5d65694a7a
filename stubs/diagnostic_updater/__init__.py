"""diagnostic_updater stand-in: diagnostics publishing served by minros.diagnostic_updater."""

from minros.diagnostic_updater import *  # noqa: F401,F403
from minros.diagnostic_updater import __all__ as __all__  # noqa: PLC0414

"""genpy.genpy_main: the command line of genmsg_py.py and gensrv_py.py (minros.msgs.pygen)."""

from genmsg.base import MsgGenerationException  # noqa: E402, F401
from minros.msgs.pygen import genmain, usage, write_modules  # noqa: F401

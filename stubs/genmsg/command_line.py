"""genmsg.command_line: the generators' ``-I pkg:dir`` options as a search path."""

from minros.msgs.loader import includepath_to_dict  # noqa: F401

"""genmsg.base: constants, exceptions and the verbose log."""

from __future__ import annotations

from minros.msgs.loader import (  # noqa: F401
    COMMENTCHAR,
    CONSTCHAR,
    EXT_MSG,
    EXT_SRV,
    IODELIM,
    MSG_DIR,
    SEP,
    SRV_DIR,
    InvalidMsgSpec,
    MsgGenerationException,
)

_verbose = False


def log_verbose(value: bool) -> None:
    global _verbose
    _verbose = value


def log(*args: object) -> None:
    if _verbose:
        print(*args)


def plog(msg: str, obj: object) -> None:
    if _verbose:
        print(f"{msg}: {obj}")


verbose = False

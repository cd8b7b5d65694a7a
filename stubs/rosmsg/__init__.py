"""Stand-in for rosmsg's Python API (minros.msgs.registry: what ``rosmsg show`` prints)."""

from __future__ import annotations

import sys
from typing import List

from minros.msgs.registry import UnknownTypeError, list_types, message_text, service_text

MODE_MSG = ".msg"
MODE_SRV = ".srv"


class ROSMsgException(Exception):
    """A type could not be found or read."""


def get_msg_text(type_: str, raw: bool = False, rospack: object = None) -> str:
    """What ``rosmsg show [-r] TYPE`` prints."""
    try:
        return message_text(type_, raw) + "\n"
    except (UnknownTypeError, ValueError) as exc:
        raise ROSMsgException(str(exc)) from None


def get_srv_text(type_: str, raw: bool = False, rospack: object = None) -> str:
    try:
        return service_text(type_, raw) + "\n"
    except (UnknownTypeError, ValueError) as exc:
        raise ROSMsgException(str(exc)) from None


def list_msgs(package: str, rospack: object = None) -> List[str]:
    return list_types(package, "msg")


def list_srvs(package: str, rospack: object = None) -> List[str]:
    return list_types(package, "srv")


def rosmsgmain(mode: str = MODE_MSG) -> None:
    from minros.cli.msg import main

    sys.exit(main(sys.argv[1:], prog="rosmsg" if mode == MODE_MSG else "rossrv",
                  kind="msg" if mode == MODE_MSG else "srv"))

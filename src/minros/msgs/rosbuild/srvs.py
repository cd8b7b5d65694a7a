"""roslib.srvs: service specs the rosbuild way (a request and a response roslib.msgs spec)."""

from __future__ import annotations

import os
import sys
from typing import Any, List, Tuple

from minros import names as _names
from minros import packages as _packages

from .. import spec as _spec
from . import msgs as _msgs

EXT = ".srv"
SEP = "/"
IODELIM = "---"
COMMENTCHAR = _msgs.COMMENTCHAR
VERBOSE = False


def is_verbose() -> bool:
    return VERBOSE


def set_verbose(v: bool) -> None:
    global VERBOSE
    VERBOSE = v


class SrvSpecException(Exception):
    """A service definition or name is not valid."""


class SrvSpec:
    """A service: request and response specs, its text and names."""

    def __init__(self, request: Any, response: Any, text: str, full_name: str = "",
                 short_name: str = "", package: str = "") -> None:
        self.request = request
        self.response = response
        self.text = text
        self.full_name = full_name
        self.short_name = short_name
        self.package = package

    def _key(self) -> tuple:
        return (self.request, self.response, self.text, self.full_name, self.short_name,
                self.package)

    def __eq__(self, other: object) -> bool:
        return bool(other) and isinstance(other, SrvSpec) and self._key() == other._key()

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"SrvSpec[{self.request!r}, {self.response!r}]"


def _srv_filter(f: str) -> bool:
    return os.path.isfile(f) and f.endswith(EXT)


def list_srv_types(package: str, include_depends: bool) -> List[str]:
    found = _packages.list_package_resources(package, include_depends, "srv", _srv_filter)
    return [x[:-len(EXT)] for x in found]


def srv_file(package: str, type_: str) -> str:
    """The path of ``package``'s ``type_.srv``, whether or not it exists."""
    return _packages.resource_file(package, "srv", type_ + EXT)


def get_pkg_srv_specs(package: str) -> Tuple[List[Tuple[str, SrvSpec]], List[str]]:
    specs, failures = [], []
    for t in list_srv_types(package, False):
        try:
            specs.append(load_from_file(srv_file(package, t), package))
        except Exception:
            failures.append(t)
            sys.stderr.write(f"ERROR: unable to load {t}\n")
    return specs, failures


def load_from_string(text: str, package_context: str = "", full_name: str = "",
                     short_name: str = "") -> SrvSpec:
    """Split at the first ``---`` line (comments dropped first) and parse both halves."""
    request_text, response_text, _ = _spec.split_srv_text(
        "\n".join(_spec._strip_comment(line) for line in text.split("\n")))
    request = _msgs.load_from_string(request_text, package_context, f"{full_name}Request",
                                     f"{short_name}Request")
    response = _msgs.load_from_string(response_text, package_context, f"{full_name}Response",
                                      f"{short_name}Response")
    return SrvSpec(request, response, text, full_name, short_name, package_context)


def load_from_file(file_name: str, package_context: str = "") -> Tuple[str, SrvSpec]:
    """``(type name, spec)`` of a ``.srv`` file."""
    if VERBOSE:
        where = f" into namespace [{package_context}]" if package_context else ""
        sys.stdout.write(f"Load spec from {file_name}{where}\n")
    type_, short, package_context = _msgs._type_name(file_name, EXT, package_context)
    if not _names.is_legal_resource_name(type_):
        raise SrvSpecException(f"{file_name}: {type_} is not a legal service type name")
    with open(file_name) as f:
        text = f.read()
    return type_, load_from_string(text, package_context, type_, short)

"""The ROS API convention that the master and every node's slave API share.

Every method of both XML-RPC APIs takes the caller's ``caller_id`` first and answers a triplet
``[code, statusMessage, value]``: code 1 (SUCCESS) did what was asked, 0 (FAILURE) is the callee's
own failure, -1 (ERROR) is the caller's mistake. ``value`` is there even on error, because
XML-RPC cannot carry None.

This module holds the convention once: the codes, :func:`unwrap` for callers (the one place a
code is checked: :class:`CallerError` for -1, :class:`CalleeFailure` for 0), and for servers
the :func:`api` decorator with its argument validators, which give the exact triplets rosmaster
and rospy answer to bad calls (both use the same decorator, ``apivalidate``). Pure: no sockets.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, List, Sequence, Tuple

from minros.names import ANYTYPE, SEP, resolve_name

__all__ = [
    "ERROR", "FAILURE", "ROSRPC", "SUCCESS",
    "CalleeFailure", "CallerError", "ParameterInvalid", "RemoteError", "Validator",
    "api", "empty_or_valid_name", "global_name", "is_api", "is_service", "is_topic", "non_empty",
    "non_empty_str", "not_none", "parse_rosrpc_uri", "triplet", "unwrap", "valid_name",
    "valid_name_validator_resolved", "valid_name_validator_unresolved", "valid_type_name",
]

#: the call did what was asked
SUCCESS = 1
#: the call was valid but failed (an internal error on the callee's side)
FAILURE = 0
#: the caller made an error (invalid argument, unknown name, ...)
ERROR = -1
#: the scheme of service URIs (``rosrpc://host:port``)
ROSRPC = "rosrpc://"


def triplet(code: int, msg: str, value: Any) -> List[Any]:
    """A ROS API result; ``value`` is mandatory even on error."""
    return [code, msg, value]


class RemoteError(Exception):
    """A ROS API call answered with a code other than SUCCESS (rosgraph's ROSMasterException)."""

    def __init__(self, code: int, msg: str, value: Any = None) -> None:
        super().__init__(msg)
        self.code = code
        self.msg = msg
        self.value = value


class CallerError(RemoteError):
    """Code -1 (ERROR): the callee says the call was wrong (unknown name, unset parameter...)."""


class CalleeFailure(RemoteError):
    """Code 0 (FAILURE), or an answer that is no triplet: the callee tried and failed."""


def unwrap(result: Any) -> Any:
    """Value of a SUCCESS triplet; :class:`CallerError` for code -1, :class:`CalleeFailure` for
    code 0, another code or a malformed result."""
    if not isinstance(result, (list, tuple)) or len(result) != 3:
        raise CalleeFailure(FAILURE, f"malformed ROS API result: {result!r}")
    code, msg, value = result
    if code == SUCCESS:
        return value
    if code == ERROR:
        raise CallerError(code, str(msg), value)
    raise CalleeFailure(code, str(msg), value)


# ---------------------------------------------------------------------------- validators


class ParameterInvalid(Exception):
    """An API argument failed validation (-> code -1 with this message)."""


def parse_rosrpc_uri(uri: str) -> Tuple[str, int]:
    """``rosrpc://host:port[/...]`` -> ``(host, port)``; ParameterInvalid otherwise (rospy's texts)."""
    if not uri.startswith(ROSRPC):
        raise ParameterInvalid(f"Invalid protocol for ROS service URL: {uri}")
    rest = uri[len(ROSRPC):].split("/", 1)[0]
    try:
        host, port_text = rest.split(":")
        port = int(port_text)
    except ValueError:
        raise ParameterInvalid(f"ROS service URL is invalid: {uri}") from None
    return host, port


#: ``validator(value, caller_id) -> canonical value``; raises ParameterInvalid
Validator = Callable[[Any, str], Any]


def non_empty(name: str) -> Validator:
    """Any value that is not empty (or zero)."""
    def check(value: Any, caller_id: str) -> Any:
        if not value:
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be specified and non-empty")
        return value
    return check


def non_empty_str(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not value:
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be specified and non-empty")
        if not isinstance(value, str):
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be a string")
        return value
    return check


def not_none(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if value is None:
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be specified")
        return value
    return check


def is_api(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not value or not isinstance(value, str):
            raise ParameterInvalid(f"ERROR: parameter [{name}] is not an XMLRPC URI")
        if not value.startswith("http://") and not value.startswith(ROSRPC):
            raise ParameterInvalid(f"ERROR: parameter [{name}] is not an RPC URI")
        return value
    return check


def valid_name_validator_unresolved(name: str, value: Any, caller_id: str) -> str:
    """``value`` as a graph name, unresolved (ParameterInvalid when it cannot be one)."""
    if not value or not isinstance(value, str):
        raise ParameterInvalid(f"ERROR: parameter [{name}] must be a non-empty string")
    # ':' and ' ' catch the common mistake of passing a URI where a name belongs
    if ":" in value or " " in value:
        raise ParameterInvalid(f"ERROR: parameter [{name}] contains illegal chars")
    return value


def valid_name_validator_resolved(name: str, value: Any, caller_id: str) -> str:
    """``value`` as a graph name resolved relative to ``caller_id``."""
    return resolve_name(valid_name_validator_unresolved(name, value, caller_id), caller_id)


_resolved_name = valid_name_validator_resolved


def valid_name(name: str, resolve: bool = True) -> Validator:
    """A graph name, resolved relative to the caller (unless ``resolve`` is False)."""
    def check(value: Any, caller_id: str) -> Any:
        if resolve:
            return valid_name_validator_resolved(name, value, caller_id)
        return valid_name_validator_unresolved(name, value, caller_id)
    return check


def global_name(name: str) -> Validator:
    """A global graph name, as given."""
    def check(value: Any, caller_id: str) -> Any:
        if not value or not isinstance(value, str):
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be a non-empty string")
        if not value.startswith(SEP):
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be a globally referenced name")
        return value
    return check


def is_topic(name: str) -> Validator:
    """A resolved topic (or service) name that is not the root namespace."""
    def check(value: Any, caller_id: str) -> Any:
        resolved = _resolved_name(name, value, caller_id)
        if value == SEP:
            raise ParameterInvalid(f"ERROR: parameter [{name}] cannot be the global namespace")
        return resolved
    return check


#: a service name is checked as a topic name is
is_service = is_topic


def empty_or_valid_name(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if not isinstance(value, str):
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be a string")
        if not value:
            return ""
        return resolve_name(value, caller_id)
    return check


def valid_type_name(name: str) -> Validator:
    def check(value: Any, caller_id: str) -> Any:
        if value == ANYTYPE:
            return value
        if not value or not isinstance(value, str):
            raise ParameterInvalid(f"ERROR: parameter [{name}] must be a non-empty string")
        if len(value.split("/")) != 2:
            raise ParameterInvalid(f"ERROR: parameter [{name}] is not a valid package resource name")
        return value
    return check


# ---------------------------------------------------------------------------- the decorator


def api(error_value: Any, validators: Sequence[Validator | None] = ()
        ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorate a master or slave API method: arity and caller_id checks, validators, and the
    exact error triplets of rosmaster/rospy.

    The decorated method takes ``(self, caller_id, *validated_args)`` and returns a triplet;
    it may raise ParameterInvalid itself for checks that need more than one argument.
    A validator of None passes its argument through unchecked.
    """
    arity = 1 + len(validators)

    def decorate(impl: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(impl)
        def method(self: Any, *args: Any) -> Any:
            if not args:
                return [ERROR, "missing required caller_id parameter", error_value]
            if len(args) != arity:
                return [ERROR, "Error: bad call arity", error_value]
            caller_id = args[0]
            if not isinstance(caller_id, str):
                return [ERROR, "caller_id must be a string", error_value]
            checked = [caller_id]
            try:
                for validator, value in zip(validators, args[1:]):
                    checked.append(value if validator is None else validator(value, caller_id))
                code, msg, value = impl(self, *checked)
            except ParameterInvalid as exc:
                return [ERROR, str(exc) or "error", error_value]
            except TypeError as exc:
                return [ERROR, f"Error: invalid arguments: {exc}", error_value]
            except Exception as exc:  # noqa: BLE001 - both APIs report internal failures as code 0
                return [FAILURE, f"Internal failure: {exc}", error_value]
            if value is None:
                return [ERROR, "Internal error (None value returned)", error_value]
            return [code, msg, value]
        return method
    return decorate

"""roslaunch substitution args: ``$(env)``, ``$(optenv)``, ``$(find)``, ``$(anon)``, ``$(arg)``,
``$(dirname)`` and ``$(eval)``, resolved in attribute values.

Pure functions over a :class:`SubstitutionContext` (args, anonymous names, current file,
environment and package lookup are all explicit), so they test without processes.
Semantics follow roslaunch's substitution_args: ``env``/``optenv``/``dirname``/``anon``/``arg``
are replaced first, then ``find`` (it may be followed by a path); an attribute that is exactly
``$(eval EXPR)`` is a restricted Python expression.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping

from minros import names, packages

VALID_COMMANDS = ("find", "env", "optenv", "dirname", "anon", "arg")


class SubstitutionError(ValueError):
    """A substitution arg that cannot be resolved; the text says which and why."""


class ArgError(SubstitutionError):
    """``$(arg NAME)`` of an arg that has no value; ``.name`` is the arg."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


def _default_find(pkg: str) -> Path | None:
    return packages.find_package(pkg)


@dataclass
class SubstitutionContext:
    """Everything a substitution may read. ``anon`` is shared by a whole launch so that
    ``$(anon x)`` gives the same name everywhere; ``args`` is per scope."""

    args: Dict[str, str] = field(default_factory=dict)
    anon: Dict[str, str] = field(default_factory=dict)
    filename: str | None = None
    env: Mapping[str, str] = field(default_factory=lambda: os.environ)
    find: Callable[[str], Path | None] = _default_find

    def child(self, args: Dict[str, str] | None = None) -> SubstitutionContext:
        """A context for a nested scope: own args, shared anon names, same lookups."""
        return SubstitutionContext(dict(self.args) if args is None else args, self.anon,
                                   self.filename, self.env, self.find)


def convert_value(value: str, type_: str) -> Any:
    """roslaunch's conversion of a ``<param>`` text to its value for ``type``."""
    kind = type_.lower()
    if kind == "auto":
        try:
            if "." in value:
                return float(value)
            if "_" not in value:  # '1_000' stays a string, as in roslaunch
                return int(value)
        except ValueError:
            pass
        if value.lower() in ("true", "false"):
            return value.lower() == "true"
        return value
    if kind in ("str", "string"):
        return value
    if kind == "int":
        return int(value)
    if kind == "double":
        return float(value)
    if kind in ("bool", "boolean"):
        low = value.lower().strip()
        if low in ("true", "1"):
            return True
        if low in ("false", "0"):
            return False
        raise ValueError(f"{low} is not a '{kind}' type")
    if kind == "yaml":
        from minros.launch.rosparam_yaml import load_yaml

        return load_yaml(value)
    raise ValueError(f"Unknown type '{type_}'")


# ----------------------------------------------------------------------------- parsing

def collect_args(text: str) -> List[str]:
    """The contents of every ``$(...)`` in ``text``, in order (roslaunch's scanner: no nesting,
    no escapes; a ``$`` inside a substitution is an error)."""
    found: List[str] = []
    buf: List[str] = []
    state = "out"  # out -> dollar -> lparen -> inside
    for ch in text:
        if ch == "$":
            if state == "out":
                state = "dollar"
            elif state != "dollar":
                raise SubstitutionError(f"Dollar signs '$' cannot be inside of substitution args [{text}]")
        elif ch == "(":
            if state == "dollar":
                state = "lparen"
            elif state != "out":
                raise SubstitutionError(f"Invalid left parenthesis '(' in substitution args [{text}]")
        elif ch == ")":
            if state == "inside":
                found.append("".join(buf))
                buf = []
            state = "out"
        elif state == "dollar":
            state = "out"
        elif state == "lparen":
            state = "inside"
        if state == "inside":
            buf.append(ch)
    return found


# ----------------------------------------------------------------------------- commands

def _env(name: str, ctx: SubstitutionContext) -> str:
    try:
        return ctx.env[name]
    except KeyError:
        raise SubstitutionError(f"environment variable {name} is not set") from None


def _optenv(name: str, default: str, ctx: SubstitutionContext) -> str:
    return ctx.env.get(name, default)


def _anon(id_: str, ctx: SubstitutionContext) -> str:
    if id_ not in ctx.anon:
        ctx.anon[id_] = names.anonymous_name(id_)
    return ctx.anon[id_]


def _dirname(ctx: SubstitutionContext) -> str:
    if not ctx.filename:
        raise SubstitutionError("Cannot substitute $(dirname), no file/directory information available.")
    return os.path.abspath(os.path.dirname(ctx.filename))


def _arg(name: str, ctx: SubstitutionContext) -> str:
    try:
        return ctx.args[name]
    except KeyError:
        raise ArgError(name) from None


def _find(pkg: str, ctx: SubstitutionContext) -> str:
    path = ctx.find(pkg)
    if path is None:
        raise SubstitutionError(f"$(find {pkg}): package '{pkg}' not found")
    return str(path)


def _apply(resolved: str, command_text: str, ctx: SubstitutionContext, passes: tuple) -> str:
    words = [w for w in command_text.split(" ") if w]
    if not words or words[0] not in VALID_COMMANDS:
        raise SubstitutionError(
            f"Unknown substitution command [{command_text}]. Valid commands are {list(VALID_COMMANDS)}")
    command, args = words[0], words[1:]
    if command not in passes:
        return resolved
    token = f"$({command_text})"
    if command == "env":
        if len(args) != 1:
            raise SubstitutionError(f"$(env var) command only accepts one argument [{command_text}]")
        value = _env(args[0], ctx)
    elif command == "optenv":
        if not args:
            raise SubstitutionError(f"$(optenv var) must specify an environment variable [{command_text}]")
        value = _optenv(args[0], " ".join(args[1:]), ctx)
    elif command == "anon":
        if len(args) != 1:
            what = "must specify a name" if not args else "may only specify one name"
            raise SubstitutionError(f"$(anon var) {what} [{command_text}]")
        value = _anon(args[0], ctx)
    elif command == "arg":
        if len(args) != 1:
            what = "must specify a variable name" if not args else "may only specify one arg"
            raise SubstitutionError(f"$(arg var) {what} [{command_text}]")
        value = _arg(args[0], ctx)
    elif command == "dirname":
        value = _dirname(ctx)
    else:  # find
        if len(args) != 1:
            raise SubstitutionError(f"$(find pkg) command only accepts one argument [{command_text}]")
        return _find_with_path(resolved, token, _find(args[0], ctx))
    return resolved.replace(token, value)


def _find_with_path(resolved: str, token: str, package_dir: str) -> str:
    """Replace the first ``$(find pkg)`` and the path that follows it (up to a space) with the
    file's path, as roslaunch: the path's separators are the platform's, a leading one is
    dropped, and it is joined to the package's folder (``$(find a)$(find a)`` is 'A/A')."""
    before, after = resolved.split(token, 1)
    path, space, rest = after.partition(" ")
    path = path.replace("/", os.sep).replace("\\", os.sep)
    if path.startswith(os.sep):
        path = path[1:]
    return before + (os.path.join(package_dir, path) if path else package_dir) + space + rest


def resolve_args(text: str | None, ctx: SubstitutionContext) -> str | None:
    """``text`` with every substitution arg replaced (None and '' pass through)."""
    if not text or "$" not in text:
        return text
    if text.startswith("$(eval ") and text.endswith(")"):
        return evaluate(text[7:-1], ctx)
    resolved = text
    for passes in (("env", "optenv", "dirname", "anon", "arg"), ("find",)):
        for command_text in collect_args(resolved):
            resolved = _apply(resolved, command_text, ctx, passes)
    return resolved


# ----------------------------------------------------------------------------- $(eval)

#: roslaunch lists list, dict, map, str, float and int, but its eval gets every builtin (the
#: table is in the wrong argument), and launch files and its own tests use more (round, len,
#: ...): those that compute, without files, imports or introspection
_EVAL_BUILTINS = {name: __builtins__[name] if isinstance(__builtins__, dict) else getattr(__builtins__, name)
                  for name in ("list", "dict", "map", "str", "float", "int", "bool", "tuple", "set",
                               "range", "len", "round", "abs", "min", "max", "sum", "pow",
                               "divmod", "sorted", "reversed", "enumerate", "zip", "filter",
                               "any", "all", "repr", "format", "chr", "ord", "hex", "oct", "bin")}


class _EvalNames(dict):
    """Name lookup for ``$(eval)``: functions and constants first, then the launch's args
    (converted like param values, so ``arg_x == 1`` compares numbers)."""

    def __init__(self, functions: Dict[str, Any], args: Mapping[str, str]) -> None:
        super().__init__()
        self._functions = functions
        self._args = args

    def __getitem__(self, key: str) -> Any:
        if key in self._functions:
            return self._functions[key]
        if key in self._args:
            return convert_value(self._args[key], "auto")
        raise KeyError(key)  # falls through to the restricted builtins, then NameError


def evaluate(expression: str, ctx: SubstitutionContext) -> str:
    """Value of ``$(eval expression)`` as a string (``str()`` of the Python result)."""
    if "__" in expression:
        raise SubstitutionError("$(eval ...) may not contain double underscore expressions")
    functions: Dict[str, Any] = {k: v for k, v in vars(math).items() if not k.startswith("_")}
    functions.update({
        "true": True, "false": False, "True": True, "False": False,
        "env": lambda name: _env(name, ctx),
        "optenv": lambda name, default="": _optenv(name, default, ctx),
        "find": lambda pkg: _find(pkg, ctx),
        "anon": lambda id_: _anon(id_, ctx),
        "arg": lambda name: convert_value(_arg(name, ctx), "auto"),
        "dirname": lambda: _dirname(ctx),
    })
    try:
        code = compile(expression, "<$(eval)>", "eval")
        return str(eval(code, {"__builtins__": _EVAL_BUILTINS}, _EvalNames(functions, ctx.args)))
    except SubstitutionError:
        raise
    except Exception as exc:  # the user's expression: report it, never a traceback
        raise SubstitutionError(f"$(eval {expression}) failed: {type(exc).__name__}: {exc}") from None

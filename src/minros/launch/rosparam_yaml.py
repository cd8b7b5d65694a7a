"""YAML as rosparam reads it: ``!degrees``/``deg(..)`` and ``!radians``/``rad(..)`` angles,
``!!binary`` as an XML-RPC Binary. A SafeLoader subclass, so nothing global is patched."""

from __future__ import annotations

import ast
import math
import operator
import re
import xmlrpc.client
from typing import Any

import yaml

_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
        ast.Div: operator.truediv, ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}


def _number_expression(text: str) -> float:
    """Evaluate arithmetic over numbers and ``pi`` (what rosparam allows in ``rad()``)."""

    def walk(node: ast.AST) -> float:
        if isinstance(node, ast.Expression):
            return walk(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return node.value
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](walk(node.left), walk(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](walk(node.operand))
        raise ValueError(f"invalid radian expression: {text}")

    try:
        return float(walk(ast.parse(text.strip(), mode="eval")))
    except (SyntaxError, ZeroDivisionError, OverflowError):
        raise ValueError(f"invalid radian expression: {text}") from None


class RosparamLoader(yaml.SafeLoader):
    """yaml.SafeLoader plus rosparam's angle tags and Binary values."""


def _radians(loader: RosparamLoader, node: yaml.Node) -> float:
    value = loader.construct_scalar(node).strip()
    if value.startswith("rad(") and value.endswith(")"):
        value = value[4:-1]
    return _number_expression(value)


def _degrees(loader: RosparamLoader, node: yaml.Node) -> float:
    value = loader.construct_scalar(node).strip()
    if value.startswith("deg(") and value.endswith(")"):
        value = value[4:-1]
    try:
        return float(value) * math.pi / 180.0
    except ValueError:
        raise ValueError(f"invalid degree value: {value}") from None


def _binary(loader: RosparamLoader, node: yaml.Node) -> xmlrpc.client.Binary:
    return xmlrpc.client.Binary(loader.construct_yaml_binary(node))


RosparamLoader.add_constructor("!radians", _radians)
RosparamLoader.add_constructor("!degrees", _degrees)
RosparamLoader.add_constructor("tag:yaml.org,2002:binary", _binary)
RosparamLoader.add_implicit_resolver("!degrees", re.compile(r"^deg\([^\)]*\)$"), list("d"))
RosparamLoader.add_implicit_resolver("!radians", re.compile(r"^rad\([^\)]*\)$"), list("r"))


def load_yaml(text: str) -> Any:
    """Parse ``text``; raises ValueError (with YAML's line/column) if it is not valid YAML."""
    try:
        return yaml.load(text, Loader=RosparamLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise ValueError(str(exc).replace("\n", " ")) from None

"""A small declarative XML <-> object mapping, under the names of urdf_parser_py's
``xml_reflection.core`` (ROS 1's melodic-devel/noetic release, 0.4.6).

A class says which XML attributes and child elements it has with ``reflect(cls, tag=...,
params=[Attribute(...), Element(...), AggregateElement(...)])``; ``Object`` then reads and
writes it. What a value looks like in XML is a *value type*: ``str`` and ``float`` (text),
``'vector3'`` (space-separated floats), another reflected class (a nested element), or one
of the ``ValueType`` objects below.

Errors: a value that cannot be read, a required attribute or element that is missing, or a
``check_valid`` that fails raises ``ParseError``, whose ``path`` is an XPath to the element
(``/robot[@name='r2']/link[@name='base']/inertial/origin[@xyz]``). Unknown attributes and
tags, and a scalar element given twice, go to ``on_error`` (stderr; tests and tools replace
it, e.g. with one that raises), and reading goes on.
"""

from __future__ import annotations

import copy
import sys
import xml.etree.ElementTree as ET
from typing import Any, Callable, Dict, List, Optional, Sequence
from xml.dom import minidom

__all__ = [
    "AggregateElement", "Attribute", "BasicType", "DuckTypedFactory", "Element", "FactoryType",
    "ListType", "Object", "ObjectType", "Param", "ParseError", "Path", "RawType", "Reflection",
    "SimpleElementType", "ValueType", "VectorType", "add_type", "end_namespace", "get_type",
    "node_add", "on_error", "on_error_stderr", "reflect", "start_namespace", "to_yaml",
    "xml_children", "xml_string",
]


def on_error_stderr(message: str) -> None:
    """The default ``on_error``: a line on stderr, and reading goes on."""
    sys.stderr.write(message + "\n")


#: Called with a message for what a reader can skip (unknown attribute or tag, a scalar element
#: given twice). Looked up at each call, so assigning the module attribute replaces it.
on_error: Callable[[str], Any] = on_error_stderr

#: When true, a missing optional value is left as it is rather than set to its default.
skip_default = False


# -- helpers (upstream's xml_reflection.basics) ----------------------------------------------

def xml_string(root: ET.Element, addHeader: bool = True) -> str:
    """``root`` indented by two spaces, one element a line, blank lines left out."""
    lines = minidom.parseString(ET.tostring(root)).toprettyxml(indent="  ").split("\n")
    if lines and lines[0].startswith("<?xml") and not addHeader:
        del lines[0]
    return "\n".join(line for line in lines if line.strip())


def node_add(doc: ET.Element, sub: Any) -> Optional[ET.Element]:
    """A new child of ``doc`` named ``sub`` (or ``sub`` itself, if it is an element)."""
    if sub is None:
        return None
    if isinstance(sub, str):
        return ET.SubElement(doc, sub)
    if isinstance(sub, ET.Element):
        doc.append(sub)
        return sub
    raise TypeError(f"node_add: {sub!r} is neither a tag name nor an element")


def xml_children(node: ET.Element) -> List[ET.Element]:
    return list(node)


def to_yaml(obj: Any) -> Any:
    """Plain data (for ``yaml.dump``) of an object tree: what ``str(obj)`` prints."""
    if obj is None or isinstance(obj, str):
        return str(obj)
    if isinstance(obj, (bool, int, float)):
        return obj
    if hasattr(obj, "to_yaml"):
        return obj.to_yaml()
    if isinstance(obj, ET.Element):
        return xml_string(obj, addHeader=False)
    if isinstance(obj, dict):
        return {str(key): to_yaml(value) for key, value in obj.items()}
    if hasattr(obj, "tolist"):  # numpy arrays
        return to_yaml(obj.tolist())
    if isinstance(obj, (list, tuple, set)):
        return [to_yaml(item) for item in obj]
    return str(obj)


# -- errors and paths --------------------------------------------------------------------------

class Path:
    """Where an element is, printed as an XPath: ``tag`` under ``parent``, then ``suffix``
    (``[2]`` for the second of its kind, ``[@name='base']`` once its name is read)."""

    def __init__(self, tag: Optional[str], parent: Optional[Path] = None, suffix: str = "",
                 tree: Any = None) -> None:
        self.parent = parent
        self.tag = tag
        self.suffix = suffix
        self.tree = tree

    def __str__(self) -> str:
        if self.parent is not None:
            return f"{self.parent}/{self.tag}{self.suffix}"
        if self.tag:
            return f"/{self.tag}{self.suffix}"
        return self.suffix


class ParseError(Exception):
    """A description that cannot be read: ``e`` is the cause, ``path`` where it happened."""

    def __init__(self, e: Any, path: Any) -> None:
        self.e = e
        self.path = path
        super().__init__(f"ParseError in {path}:\n{e}")


# -- value types -----------------------------------------------------------------------------

class ValueType:
    """How one value is read from and written to XML (by default: an element's text)."""

    def from_string(self, text: str) -> Any:
        raise NotImplementedError

    def to_string(self, value: Any) -> str:
        raise NotImplementedError

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        return self.from_string(node.text or "")

    def write_xml(self, node: ET.Element, value: Any) -> None:
        node.text = self.to_string(value)

    def equals(self, a: Any, b: Any) -> bool:
        return bool(a == b)


class BasicType(ValueType):
    """``str`` or ``float``: the value is the text, written back with ``str``."""

    def __init__(self, cur_type: type) -> None:
        self.type = cur_type

    def from_string(self, text: str) -> Any:
        if self.type is float:
            try:
                return float(text)
            except (TypeError, ValueError):
                raise ValueError(f"'{text}' is not a number") from None
        return self.type(text)

    def to_string(self, value: Any) -> str:
        return str(value)


class ListType(ValueType):
    """Whitespace-separated words."""

    def from_string(self, text: str) -> Any:
        return text.split()

    def to_string(self, values: Any) -> str:
        return " ".join(values)

    def equals(self, a: Any, b: Any) -> bool:
        return len(a) == len(b) and all(x == y for x, y in zip(a, b))


class VectorType(ListType):
    """Whitespace-separated numbers, ``count`` of them if given (``'vector3'``)."""

    def __init__(self, count: Optional[int] = None) -> None:
        self.count = count

    def check(self, values: Sequence[Any]) -> None:
        if self.count is not None and len(values) != self.count:
            raise ValueError(f"expected {self.count} numbers, got {len(values)}: "
                             f"'{' '.join(map(str, values))}'")

    def from_string(self, text: str) -> Any:
        words = text.split()
        self.check(words)
        try:
            return [float(word) for word in words]
        except ValueError:
            raise ValueError(f"'{text}' is not {self.count or 'a list of'} numbers") from None

    def to_string(self, values: Any) -> str:
        self.check(values)
        return " ".join(str(value) for value in values)


class RawType(ValueType):
    """The element itself (``<gazebo>`` blocks): kept as read, written back whole."""

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        return node

    def write_xml(self, node: ET.Element, value: Any) -> None:
        for key, text in value.attrib.items():
            node.set(key, text)
        node.text = value.text
        for child in value:
            node.append(child)


class SimpleElementType(ValueType):
    """A value held by one attribute of an element of its own: ``<parent link="base"/>``."""

    def __init__(self, attribute: str, value_type: Any) -> None:
        self.attribute = attribute
        self.value_type = get_type(value_type)

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        text = node.get(self.attribute)
        if text is None:
            raise ParseError(ValueError(f"<{node.tag}> has no '{self.attribute}' attribute"), path)
        try:
            return self.value_type.from_string(text)
        except Exception as exc:
            raise ParseError(exc, Path(path.tag, path.parent, f"{path.suffix}[@{self.attribute}]")) from None

    def write_xml(self, node: ET.Element, value: Any) -> None:
        node.set(self.attribute, self.value_type.to_string(value))


class ObjectType(ValueType):
    """A nested element read into a new instance of a reflected class."""

    def __init__(self, cur_type: type) -> None:
        self.type = cur_type

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        obj = self.type()
        obj.read_xml(node, path)
        return obj

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


class FactoryType(ValueType):
    """One of several classes, chosen by the element's tag (``typeMap``: tag -> class)."""

    def __init__(self, name: str, typeMap: Dict[str, Any]) -> None:
        self.name = name
        self.typeMap = typeMap
        self.nameMap = {cls: tag for tag, cls in typeMap.items()}

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        cur_type = self.typeMap.get(node.tag)
        if cur_type is None:
            raise ParseError(ValueError(f"Invalid {self.name} tag: <{node.tag}> (one of: "
                                        f"{', '.join(sorted(self.typeMap))})"), path)
        return get_type(cur_type).from_xml(node, path)

    def get_name(self, obj: Any) -> str:
        name = self.nameMap.get(type(obj))
        if name is None:
            raise TypeError(f"Invalid {self.name} type: {type(obj)}")
        return name

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


class DuckTypedFactory(ValueType):
    """The first of ``typeOrder`` that reads the element without an error."""

    def __init__(self, name: str, typeOrder: Sequence[Any]) -> None:
        if not typeOrder:
            raise ValueError("DuckTypedFactory needs at least one type")
        self.name = name
        self.type_order = list(typeOrder)

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        errors = []
        for value_type in self.type_order:
            try:
                return value_type.from_xml(node, path)
            except Exception as exc:  # the next type may fit
                errors.append(f"\nValue Type: {value_type}\nException: {exc}\n")
        raise ParseError(Exception("Could not perform duck-typed parsing." + "".join(errors)), path)

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


# -- the registry of named value types -------------------------------------------------------

value_types: Dict[Any, ValueType] = {}
value_type_prefix = ""


def start_namespace(namespace: str) -> None:
    """Type names added from here on are ``namespace.name`` (urdf and sdf keep theirs apart)."""
    global value_type_prefix
    value_type_prefix = namespace + "."


def end_namespace() -> None:
    global value_type_prefix
    value_type_prefix = ""


def add_type(key: Any, value: ValueType) -> None:
    if isinstance(key, str):
        key = value_type_prefix + key
    if key in value_types:
        raise ValueError(f"value type {key!r} is registered already")
    value_types[key] = value


def get_type(cur_type: Any) -> ValueType:
    """The ValueType for ``cur_type``: a registered name, ``'vectorN'``, ``str``, ``float``,
    ``list``, a reflected class, or a ValueType (made and registered on first use)."""
    if isinstance(cur_type, ValueType):
        return cur_type
    found = None
    if value_type_prefix and isinstance(cur_type, str):
        found = value_types.get(value_type_prefix + cur_type)
    if found is None:
        found = value_types.get(cur_type)
    if found is None:
        found = make_type(cur_type)
        add_type(cur_type, found)
    return found


def make_type(cur_type: Any) -> ValueType:
    if isinstance(cur_type, ValueType):
        return cur_type
    if isinstance(cur_type, str):
        if cur_type.startswith("vector"):
            count = cur_type[len("vector"):]
            return VectorType(int(count) if count else None)
        raise ValueError(f"Invalid value type: {cur_type}")
    if cur_type is list:
        return ListType()
    if cur_type in (str, float):
        return BasicType(cur_type)
    if isinstance(cur_type, type) and issubclass(cur_type, Object):
        return ObjectType(cur_type)
    raise ValueError(f"Invalid type: {cur_type}")


# -- parameters: what a class has in XML -----------------------------------------------------

class Param:
    """One attribute or element: ``xml_var`` in XML, ``var`` (the same by default) in Python."""

    type = "param"
    is_aggregate = False

    def __init__(self, xml_var: str, value_type: Any, required: bool = True,
                 default: Any = None, var: Optional[str] = None) -> None:
        if required and default is not None:
            raise ValueError(f"{xml_var}: a default does not make sense for a required field")
        self.xml_var = xml_var
        self.var = xml_var if var is None else var
        self.value_type = get_type(value_type)
        self.required = required
        self.default = default

    def set_default(self, obj: Any) -> None:
        if self.required:
            raise ValueError(f"Required {self.type} not set in XML: {self.xml_var}")
        if not skip_default:
            setattr(obj, self.var, copy.copy(self.default))


class Attribute(Param):
    type = "attribute"

    def set_from_string(self, obj: Any, value: str) -> None:
        setattr(obj, self.var, self.value_type.from_string(value))

    def get_value(self, obj: Any) -> Any:
        return getattr(obj, self.var)

    def add_to_xml(self, obj: Any, node: ET.Element) -> None:
        value = getattr(obj, self.var, None)
        if value is None:
            if self.required:
                raise ValueError(f"Required attribute not set in object: {self.var}")
            if not skip_default:
                value = self.default
        if value is not None:
            node.set(self.xml_var, self.value_type.to_string(value))


class Element(Param):
    type = "element"

    def __init__(self, xml_var: str, value_type: Any, required: bool = True,
                 default: Any = None, var: Optional[str] = None, is_raw: bool = False) -> None:
        super().__init__(xml_var, value_type, required, default, var)
        self.is_raw = is_raw

    def set_from_xml(self, obj: Any, node: ET.Element, path: Path) -> None:
        setattr(obj, self.var, read_value(self.value_type, node, path))

    def add_to_xml(self, obj: Any, parent: ET.Element) -> None:
        value = getattr(obj, self.var, None)
        if value is None:
            if self.required:
                raise ValueError(f"Required element not defined in object: {self.var}")
            if not skip_default:
                value = self.default
        if value is not None:
            self.add_scalar_to_xml(parent, value)

    def add_scalar_to_xml(self, parent: ET.Element, value: Any) -> None:
        node = parent if self.is_raw else ET.SubElement(parent, self.xml_var)
        self.value_type.write_xml(node, value)


class AggregateElement(Element):
    """An element that may repeat: collected in the list ``var`` (``xml_var + 's'``)."""

    is_aggregate = True

    def __init__(self, xml_var: str, value_type: Any, var: Optional[str] = None,
                 is_raw: bool = False) -> None:
        super().__init__(xml_var, value_type, required=False,
                         var=xml_var + "s" if var is None else var, is_raw=is_raw)

    def add_from_xml(self, obj: Any, node: ET.Element, path: Path) -> None:
        obj.add_aggregate(self.xml_var, read_value(self.value_type, node, path))

    def set_default(self, obj: Any) -> None:
        pass


def read_value(value_type: ValueType, node: ET.Element, path: Path) -> Any:
    """``value_type`` read from ``node``; an error that is not a ParseError yet gets the path."""
    try:
        return value_type.from_xml(node, path)
    except ParseError:
        raise
    except Exception as exc:
        raise ParseError(exc, path) from None


class Reflection:
    """The attributes and elements of one class (``parent_cls``'s first, if given)."""

    def __init__(self, params: Sequence[Param] = (), parent_cls: Any = None,
                 tag: Optional[str] = None) -> None:
        self.parent = parent_cls.XML_REFL if parent_cls is not None else None
        self.tag = tag
        self.attributes: List[Any] = [p for p in params if not isinstance(p, Element)]
        self.elements: List[Any] = [p for p in params if isinstance(p, Element)]
        self.scalars = [e for e in self.elements if not e.is_aggregate]
        self.aggregates = [e for e in self.elements if e.is_aggregate]
        self.attribute_map = {a.xml_var: a for a in self.attributes}
        self.element_map = {e.xml_var: e for e in self.elements}
        self.paramMap: Dict[str, Param] = {**self.attribute_map, **self.element_map}
        self.vars = [p.var for p in self.attributes] + [e.var for e in self.elements]
        self.scalarNames = [e.xml_var for e in self.scalars]

    def set_from_xml(self, obj: Any, node: ET.Element, path: Path,
                     info: Optional[Dict[str, list]] = None) -> Path:
        """Read ``node`` into ``obj``; returns the path, named once the name is read."""
        outermost = info is None
        if info is None:  # what is left unread, for the unknown-attribute/tag report
            info = {"attributes": list(node.attrib), "children": list(node)}
        if self.parent is not None:
            path = self.parent.set_from_xml(obj, node, path, info)

        for key in list(info["attributes"]):
            attribute = self.attribute_map.get(key)
            if attribute is None:
                continue
            try:
                attribute.set_from_string(obj, node.attrib[key])
            except Exception as exc:
                raise ParseError(exc, Path(path.tag, path.parent, f"{path.suffix}[@{key}]")) from None
            if key == "name":  # the path names the element from here on (children see it too)
                path.suffix = f"[@name='{attribute.get_value(obj)}']"
            info["attributes"].remove(key)

        unset = set(self.scalarNames)
        for child in list(info["children"]):
            element = self.element_map.get(child.tag)
            if element is None:
                continue
            if element.is_aggregate:
                index = len(obj.get_aggregate_list(element.xml_var)) + 1  # XPath counts from 1
                element.add_from_xml(obj, child, Path(child.tag, path, f"[{index}]"))
            elif child.tag in unset:
                element.set_from_xml(obj, child, Path(child.tag, path))
                unset.discard(child.tag)
            else:
                on_error(f"Scalar element defined multiple times: {child.tag}")
            info["children"].remove(child)

        missing: List[Param] = [a for a in self.attributes if a.xml_var not in node.attrib]
        missing += [e for e in self.scalars if e.xml_var in unset]
        for param in missing:
            try:
                param.set_default(obj)
            except Exception as exc:
                raise ParseError(exc, path) from None

        if outermost:
            for key in info["attributes"]:
                on_error(f'Unknown attribute "{key}" in {path}')
            for child in info["children"]:
                on_error(f'Unknown tag "{child.tag}" in {path}')
        return path

    def add_to_xml(self, obj: Any, node: ET.Element) -> None:
        if self.parent is not None:
            self.parent.add_to_xml(obj, node)
        for attribute in self.attributes:
            attribute.add_to_xml(obj, node)
        for element in self.scalars:
            element.add_to_xml(obj, node)
        if self.aggregates:
            obj.add_aggregates_to_xml(node)


def reflect(cls: type, *args: Any, **kwargs: Any) -> None:
    """Give ``cls`` its XML form: ``reflect(Cls, tag='x', params=[...])``."""
    cls.XML_REFL = Reflection(*args, **kwargs)  # type: ignore[attr-defined]


class Object:
    """A value read from and written to XML as its class's ``XML_REFL`` says.

    Repeated elements (aggregates) are kept in their lists (``links``, ``joints``, ...) and, for
    writing them back in the order read, in ``aggregate_order``: add them with
    ``add_aggregate(xml_var, obj)``.
    """

    XML_REFL: Reflection = Reflection()

    # -- reading ---------------------------------------------------------------------------
    @classmethod
    def from_xml(cls, node: ET.Element, path: Path) -> Any:
        return get_type(cls).from_xml(node, path)

    @classmethod
    def from_xml_string(cls, xml_string: Any) -> Any:
        """Read a document whose root element is this class's (``str`` or ``bytes``)."""
        node = ET.fromstring(xml_string)
        return cls.from_xml(node, Path(cls.XML_REFL.tag, tree=ET.ElementTree(node)))

    @classmethod
    def from_xml_file(cls, file_path: str) -> Any:
        with open(file_path, "rb") as f:  # bytes: the XML declaration names the encoding
            return cls.from_xml_string(f.read())

    def parse(self, xml_string: Any) -> Any:
        """Read a document into this object (older API than ``from_xml_string``)."""
        node = ET.fromstring(xml_string)
        self.read_xml(node, Path(self.XML_REFL.tag, tree=ET.ElementTree(node)))
        return self

    def read_xml(self, node: ET.Element, path: Path) -> None:
        self.XML_REFL.set_from_xml(self, node, path)
        self.post_read_xml()
        try:
            self.check_valid()
        except ParseError:
            raise
        except Exception as exc:
            raise ParseError(exc, path) from None

    def post_read_xml(self) -> None:
        """Hook: after the element is read, before ``check_valid``."""

    def check_valid(self) -> None:
        """Hook: raise if the object is not valid (on reading and before writing)."""

    # -- writing ---------------------------------------------------------------------------
    def pre_write_xml(self) -> None:
        """Hook: before writing."""

    def write_xml(self, node: ET.Element) -> None:
        """Add this object's attributes and children to ``node``."""
        self.check_valid()
        self.pre_write_xml()
        self.XML_REFL.add_to_xml(self, node)

    def to_xml(self) -> ET.Element:
        tag = self.XML_REFL.tag
        if tag is None:
            raise TypeError(f"{type(self).__name__} has no tag of its own to write")
        root = ET.Element(tag)
        self.write_xml(root)
        return root

    def to_xml_string(self, addHeader: bool = True) -> str:
        return xml_string(self.to_xml(), addHeader)

    # -- repeated elements -----------------------------------------------------------------
    def aggregate_init(self) -> None:
        """Call in ``__init__`` of a class with aggregates."""
        self.aggregate_order: List[Any] = []
        self.aggregate_type: Dict[Any, str] = {}

    def get_aggregate_list(self, xml_var: str) -> List[Any]:
        values = getattr(self, self.XML_REFL.paramMap[xml_var].var)
        if not isinstance(values, list):
            raise TypeError(f"{type(self).__name__}.{xml_var}: not a list")
        return values

    def add_aggregate(self, xml_var: str, obj: Any) -> None:
        self.get_aggregate_list(xml_var).append(obj)
        self._order(xml_var, obj)

    def _order(self, xml_var: str, obj: Any) -> None:
        self.aggregate_order.append(obj)
        self.aggregate_type[_key(obj)] = xml_var

    def remove_aggregate(self, obj: Any) -> None:
        self.aggregate_order.remove(obj)
        xml_var = self.aggregate_type.pop(_key(obj))
        self.get_aggregate_list(xml_var).remove(obj)

    def lump_aggregates(self) -> None:
        """Order the aggregates by kind (all links, then all joints, ...)."""
        self.aggregate_init()
        for element in self.XML_REFL.aggregates:
            for obj in self.get_aggregate_list(element.xml_var):
                self._order(element.xml_var, obj)

    def add_aggregates_to_xml(self, node: ET.Element) -> None:
        written = set()
        for obj in self.aggregate_order:
            self.XML_REFL.element_map[self.aggregate_type[_key(obj)]].add_scalar_to_xml(node, obj)
            written.add(id(obj))
        # what code appended to the lists directly (robot.links.append(...)) is written too
        for element in self.XML_REFL.aggregates:
            for obj in self.get_aggregate_list(element.xml_var):
                if id(obj) not in written:
                    element.add_scalar_to_xml(node, obj)
                    written.add(id(obj))

    # -- printing --------------------------------------------------------------------------
    def get_refl_vars(self) -> List[str]:
        return list(self.XML_REFL.vars)

    def to_yaml(self) -> Any:
        return to_yaml({var: getattr(self, var, None) for var in self.get_refl_vars()})

    def __str__(self) -> str:
        import yaml  # only for printing

        return str(yaml.dump(self.to_yaml())).rstrip()


def _key(obj: Any) -> Any:
    """The key of ``aggregate_type``: the object, or its id when it cannot be hashed."""
    try:
        hash(obj)
    except TypeError:
        return id(obj)
    return obj


# Common named types: an element holding a name or a number in one attribute
add_type("element_name", SimpleElementType("name", str))
add_type("element_value", SimpleElementType("value", float))
for _vector in ("vector3", "vector4", "vector6"):  # global, not in a namespace
    get_type(_vector)

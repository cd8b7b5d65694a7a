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

How it works: ``reflect`` computes once per class a table of its fields (a ``parent_cls``'s
first). Reading an element sets its declared attributes (``name`` first, so that errors
after it name the element), walks its children once in document order dispatching by tag
through the table, then gives what was not there its default (or fails if it was required),
and last reports what the table does not know. Writing walks the same table.
"""

from __future__ import annotations

import copy
import sys
import xml.etree.ElementTree as ET
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple
from xml.dom import minidom

__all__ = [
    "AggregateElement", "Attribute", "BasicType", "DuckTypedFactory", "Element", "FactoryType",
    "ListType", "Object", "ObjectType", "ParseError", "Path", "RawType", "SimpleElementType",
    "ValueType", "VectorType", "add_type", "end_namespace", "get_type", "node_add", "on_error",
    "on_error_stderr", "reflect", "start_namespace", "to_yaml", "xml_children", "xml_string",
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


# -- value types: how one value looks in XML --------------------------------------------------

class ValueType:
    """How one value is read from and written to XML. A subclass either converts text
    (``from_string``/``to_string``: the element's text, or an attribute's value) or reads and
    fills a whole element (``from_xml``/``write_xml``)."""

    def from_string(self, text: str) -> Any:
        raise NotImplementedError(f"{type(self).__name__} is not read from text")

    def to_string(self, value: Any) -> str:
        raise NotImplementedError(f"{type(self).__name__} is not written as text")

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        return self.from_string(node.text or "")

    def write_xml(self, node: ET.Element, value: Any) -> None:
        node.text = self.to_string(value)


class BasicType(ValueType):
    """``str`` or ``float``."""

    def __init__(self, cur_type: type) -> None:
        self.type = cur_type

    def from_string(self, text: str) -> Any:
        try:
            return self.type(text)
        except (TypeError, ValueError):
            if self.type is float:
                raise ValueError(f"'{text}' is not a number") from None
            raise

    def to_string(self, value: Any) -> str:
        return str(value)


class ListType(ValueType):
    """Words separated by whitespace."""

    def from_string(self, text: str) -> Any:
        return text.split()

    def to_string(self, values: Any) -> str:
        return " ".join(values)


class VectorType(ListType):
    """Numbers separated by whitespace; exactly ``count`` of them when ``count`` is given."""

    def __init__(self, count: Optional[int] = None) -> None:
        self.count = count

    def check(self, values: Sequence[Any]) -> None:
        if self.count is None or len(values) == self.count:
            return
        shown = " ".join(str(v) for v in values)
        raise ValueError(f"expected {self.count} numbers, got {len(values)}: '{shown}'")

    def from_string(self, text: str) -> Any:
        words = text.split()
        self.check(words)
        numbers = []
        for word in words:
            try:
                numbers.append(float(word))
            except ValueError:
                raise ValueError(f"'{text}' is not {self.count or 'a list of'} numbers") from None
        return numbers

    def to_string(self, values: Any) -> str:
        self.check(values)
        return " ".join(map(str, values))


class RawType(ValueType):
    """The element as it is (``<gazebo>`` blocks), copied back whole on writing."""

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        return node

    def write_xml(self, node: ET.Element, value: Any) -> None:
        node.attrib.update(value.attrib)
        node.text = value.text
        node.extend(list(value))


class SimpleElementType(ValueType):
    """A value kept in one attribute of an element of its own: ``<parent link="base"/>``."""

    def __init__(self, attribute: str, value_type: Any) -> None:
        self.attribute = attribute
        self.value_type = get_type(value_type)

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        if self.attribute not in node.attrib:
            raise ParseError(ValueError(f"<{node.tag}> has no '{self.attribute}' attribute"), path)
        try:
            return self.value_type.from_string(node.attrib[self.attribute])
        except Exception as exc:
            raise ParseError(exc, _attribute_path(path, self.attribute)) from None

    def write_xml(self, node: ET.Element, value: Any) -> None:
        node.set(self.attribute, self.value_type.to_string(value))


class ObjectType(ValueType):
    """An element read into a new instance of a reflected class."""

    def __init__(self, cur_type: type) -> None:
        self.type = cur_type

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        instance = self.type()
        instance.read_xml(node, path)
        return instance

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


class FactoryType(ValueType):
    """One of several classes, picked by the element's tag (``typeMap``: tag -> class)."""

    def __init__(self, name: str, typeMap: Dict[str, Any]) -> None:
        self.name = name
        self.typeMap = typeMap

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        if node.tag not in self.typeMap:
            choices = ", ".join(sorted(self.typeMap))
            raise ParseError(ValueError(f"Invalid {self.name} tag: <{node.tag}> (one of: "
                                        f"{choices})"), path)
        return get_type(self.typeMap[node.tag]).from_xml(node, path)

    def get_name(self, obj: Any) -> str:
        for tag, cls in self.typeMap.items():
            if type(obj) is cls:
                return tag
        raise TypeError(f"Invalid {self.name} type: {type(obj)}")

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


class DuckTypedFactory(ValueType):
    """Whichever of ``typeOrder`` reads the element first without an error."""

    def __init__(self, name: str, typeOrder: Sequence[Any]) -> None:
        if len(typeOrder) == 0:
            raise ValueError("DuckTypedFactory needs at least one type")
        self.name = name
        self.type_order = list(typeOrder)

    def from_xml(self, node: ET.Element, path: Path) -> Any:
        failures = ""
        for candidate in self.type_order:
            try:
                return candidate.from_xml(node, path)
            except Exception as exc:  # try the next one
                failures += f"\nValue Type: {candidate}\nException: {exc}\n"
        raise ParseError(Exception("Could not perform duck-typed parsing." + failures), path)

    def write_xml(self, node: ET.Element, obj: Any) -> None:
        obj.write_xml(node)


# -- named value types -------------------------------------------------------------------------

#: Registered value types: a name (``'urdf.geometric'``, ``'vector3'``), or a class/type.
value_types: Dict[Any, ValueType] = {}
_namespace: List[str] = []  # the current namespace, if any (one at a time)


def start_namespace(namespace: str) -> None:
    """Names registered from here on are ``namespace.name`` and found first in lookups
    (urdf and sdf each keep their own ``'pose'``)."""
    _namespace[:] = [namespace]


def end_namespace() -> None:
    _namespace.clear()


def _qualified(name: str) -> str:
    return f"{_namespace[0]}.{name}" if _namespace else name


def add_type(key: Any, value: ValueType) -> None:
    """Register ``value`` under ``key`` (a name, in the current namespace, or a type)."""
    if isinstance(key, str):
        key = _qualified(key)
    if key in value_types:
        raise ValueError(f"value type {key!r} is registered already")
    value_types[key] = value


def get_type(cur_type: Any) -> ValueType:
    """The ValueType for ``cur_type``: a ValueType itself, a registered name (the current
    namespace's first), ``'vectorN'``/``'vector'``, ``str``, ``float``, ``list`` or a reflected
    class; the ones made here are registered for next time."""
    if isinstance(cur_type, ValueType):
        return cur_type
    if isinstance(cur_type, str):
        for key in (_qualified(cur_type), cur_type):
            if key in value_types:
                return value_types[key]
    elif cur_type in value_types:
        return value_types[cur_type]
    made = _new_type(cur_type)
    add_type(cur_type, made)
    return made


def _new_type(cur_type: Any) -> ValueType:
    if isinstance(cur_type, str):
        if not cur_type.startswith("vector"):
            raise ValueError(f"Invalid value type: {cur_type}")
        digits = cur_type[len("vector"):]
        return VectorType(int(digits) if digits else None)
    if cur_type in (str, float):
        return BasicType(cur_type)
    if cur_type is list:
        return ListType()
    if isinstance(cur_type, type) and issubclass(cur_type, Object):
        return ObjectType(cur_type)
    raise ValueError(f"Invalid type: {cur_type}")


# -- fields: the attributes and elements a class declares --------------------------------------

class Attribute:
    """An XML attribute ``xml_var``, held in the Python attribute ``var`` (the same name unless
    given). A required one must be in the XML; an optional one missing gets ``default``."""

    kind = "attribute"
    repeats = False

    def __init__(self, xml_var: str, value_type: Any, required: bool = True,
                 default: Any = None, var: Optional[str] = None) -> None:
        if required and default is not None:
            raise ValueError(f"{xml_var}: a required {self.kind} has no default")
        self.xml_var = xml_var
        self.var = var or xml_var
        self.value_type = get_type(value_type)
        self.required = required
        self.default = default

    def fill_default(self, obj: Any) -> None:
        """What to do when the XML lacks this field."""
        if self.required:
            raise ValueError(f"Required {self.kind} not set in XML: {self.xml_var}")
        if not skip_default:
            setattr(obj, self.var, copy.copy(self.default))

    def value_to_write(self, obj: Any) -> Any:
        """The value to write (None: nothing to write)."""
        value = getattr(obj, self.var, None)
        if value is not None:
            return value
        if self.required:
            noun = "attribute not set" if self.kind == "attribute" else "element not defined"
            raise ValueError(f"Required {noun} in object: {self.var}")
        return None if skip_default else self.default


class Element(Attribute):
    """A child element ``<xml_var>`` that appears at most once. ``is_raw``: the value is
    written into the parent element itself rather than a child of its own."""

    kind = "element"

    def __init__(self, xml_var: str, value_type: Any, required: bool = True,
                 default: Any = None, var: Optional[str] = None, is_raw: bool = False) -> None:
        super().__init__(xml_var, value_type, required, default, var)
        self.is_raw = is_raw

    def emit(self, parent: ET.Element, value: Any) -> None:
        """Write ``value`` as this element under ``parent``."""
        target = parent if self.is_raw else ET.SubElement(parent, self.xml_var)
        self.value_type.write_xml(target, value)


class AggregateElement(Element):
    """A child element that may repeat; its values go, in document order, to the list ``var``
    (``xml_var + 's'`` unless given) through ``Object.add_aggregate``."""

    repeats = True

    def __init__(self, xml_var: str, value_type: Any, var: Optional[str] = None,
                 is_raw: bool = False) -> None:
        super().__init__(xml_var, value_type, required=False, var=var or xml_var + "s",
                         is_raw=is_raw)

    def fill_default(self, obj: Any) -> None:
        pass  # the list stays as the constructor made it


class _Schema:
    """What ``reflect`` computes once per class: its fields, its base class's first, split
    into lookups by XML name. Reading and writing walk these tables only."""

    def __init__(self, tag: Optional[str], fields: Sequence[Attribute]) -> None:
        self.tag = tag
        self.fields = list(fields)
        self.attributes = {f.xml_var: f for f in self.fields if not isinstance(f, Element)}
        self.children = {f.xml_var: f for f in self.fields if isinstance(f, Element)}
        self.scalars = [f for f in self.children.values() if not f.repeats]
        self.aggregates = [f for f in self.children.values() if f.repeats]

    def read(self, obj: Any, node: ET.Element, path: Path) -> None:
        """Fill ``obj`` from ``node``; names ``path`` after the ``name`` attribute."""
        # `name` first: errors in the other attributes and in children then name the element
        keys = sorted(node.attrib, key=lambda key: key != "name")
        unknown_attributes = []
        for key in keys:
            field = self.attributes.get(key)
            if field is None:
                unknown_attributes.append(key)
                continue
            try:
                value = field.value_type.from_string(node.attrib[key])
            except Exception as exc:
                raise ParseError(exc, _attribute_path(path, key)) from None
            setattr(obj, field.var, value)
            if key == "name":
                path.suffix = f"[@name='{value}']"

        seen = set()
        counts: Dict[str, int] = {}
        unknown_tags = []
        for child in node:
            field = self.children.get(child.tag)
            if field is None:
                unknown_tags.append(child.tag)
            elif field.repeats:
                counts[child.tag] = counts.get(child.tag, 0) + 1  # XPath counts from 1
                where = Path(child.tag, path, f"[{counts[child.tag]}]")
                obj.add_aggregate(child.tag, _read_value(field.value_type, child, where))
            elif child.tag in seen:
                on_error(f"Scalar element defined multiple times: {child.tag}")
            else:
                seen.add(child.tag)
                setattr(obj, field.var, _read_value(field.value_type, child, Path(child.tag, path)))

        absent = [f for f in self.attributes.values() if f.xml_var not in node.attrib]
        absent += [f for f in self.scalars if f.xml_var not in seen]
        for field in absent:
            try:
                field.fill_default(obj)
            except Exception as exc:
                raise ParseError(exc, path) from None

        for key in unknown_attributes:
            on_error(f'Unknown attribute "{key}" in {path}')
        for tag in unknown_tags:
            on_error(f'Unknown tag "{tag}" in {path}')

    def write(self, obj: Any, node: ET.Element) -> None:
        for field in self.attributes.values():
            value = field.value_to_write(obj)
            if value is not None:
                node.set(field.xml_var, field.value_type.to_string(value))
        for field in self.scalars:
            value = field.value_to_write(obj)
            if value is not None:
                field.emit(node, value)
        if self.aggregates:
            obj.add_aggregates_to_xml(node)


def _attribute_path(path: Path, key: str) -> Path:
    """``path`` narrowed to one of its element's attributes: ``.../origin[@xyz]``."""
    return Path(path.tag, path.parent, f"{path.suffix}[@{key}]")


def _read_value(value_type: ValueType, node: ET.Element, path: Path) -> Any:
    try:
        return value_type.from_xml(node, path)
    except ParseError:
        raise
    except Exception as exc:  # give it the path
        raise ParseError(exc, path) from None


def reflect(cls: type, tag: Optional[str] = None, params: Sequence[Attribute] = (),
            parent_cls: Optional[type] = None) -> None:
    """Declare ``cls``'s XML form: ``reflect(Cls, tag='x', params=[Attribute(...),
    Element(...), AggregateElement(...)], parent_cls=Base)`` (``Base``'s fields come first)."""
    inherited = parent_cls.XML_REFL.fields if parent_cls is not None else []  # type: ignore[attr-defined]
    cls.XML_REFL = _Schema(tag, [*inherited, *params])  # type: ignore[attr-defined]


class Object:
    """A value read from and written to XML as its class's ``reflect`` declared.

    Repeated elements (aggregates) live in their lists (``links``, ``joints``, ...); the order
    they were read or added in (``add_aggregate``) is kept too, so that they are written back
    in it. A class with aggregates calls ``aggregate_init()`` in its ``__init__``.
    """

    XML_REFL = _Schema(None, [])

    # -- reading ---------------------------------------------------------------------------
    @classmethod
    def from_xml(cls, node: ET.Element, path: Path) -> Any:
        return get_type(cls).from_xml(node, path)

    @classmethod
    def from_xml_string(cls, xml_string: Any) -> Any:
        """Read a document (``str`` or ``bytes``) whose root element is this class's."""
        root = ET.fromstring(xml_string)
        return cls.from_xml(root, Path(cls.XML_REFL.tag, tree=ET.ElementTree(root)))

    @classmethod
    def from_xml_file(cls, file_path: str) -> Any:
        with open(file_path, "rb") as f:  # bytes: the XML declaration names the encoding
            return cls.from_xml_string(f.read())

    def parse(self, xml_string: Any) -> Any:
        """Read a document into this object (the API before ``from_xml_string``)."""
        root = ET.fromstring(xml_string)
        self.read_xml(root, Path(self.XML_REFL.tag, tree=ET.ElementTree(root)))
        return self

    def read_xml(self, node: ET.Element, path: Path) -> None:
        self.XML_REFL.read(self, node, path)
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
        """Hook: raise if the object is not valid (after reading, before writing)."""

    # -- writing ---------------------------------------------------------------------------
    def pre_write_xml(self) -> None:
        """Hook: before writing."""

    def write_xml(self, node: ET.Element) -> None:
        """Put this object's attributes and children into ``node``."""
        self.check_valid()
        self.pre_write_xml()
        self.XML_REFL.write(self, node)

    def to_xml(self) -> ET.Element:
        if self.XML_REFL.tag is None:
            raise TypeError(f"{type(self).__name__} has no tag of its own to write")
        root = ET.Element(self.XML_REFL.tag)
        self.write_xml(root)
        return root

    def to_xml_string(self, addHeader: bool = True) -> str:
        return xml_string(self.to_xml(), addHeader)

    # -- repeated elements -----------------------------------------------------------------
    def aggregate_init(self) -> None:
        """Start the record of aggregates: (xml_var, value) pairs in the order added."""
        self._aggregates: List[Tuple[str, Any]] = []

    def _aggregate_record(self) -> List[Tuple[str, Any]]:
        if "_aggregates" not in self.__dict__:
            self.aggregate_init()
        return self._aggregates

    def get_aggregate_list(self, xml_var: str) -> List[Any]:
        field = self.XML_REFL.children.get(xml_var)
        if field is None or not field.repeats:
            raise KeyError(f"{type(self).__name__} has no repeated element <{xml_var}>")
        values = getattr(self, field.var)
        if not isinstance(values, list):
            raise TypeError(f"{type(self).__name__}.{field.var}: not a list")
        return values

    def add_aggregate(self, xml_var: str, obj: Any) -> None:
        self.get_aggregate_list(xml_var).append(obj)
        self._aggregate_record().append((xml_var, obj))

    def remove_aggregate(self, obj: Any) -> None:
        record = self._aggregate_record()
        for i, (xml_var, value) in enumerate(record):
            if value is obj:
                del record[i]
                values = self.get_aggregate_list(xml_var)
                del values[next(j for j, v in enumerate(values) if v is obj)]
                return
        raise ValueError(f"{obj!r} is not one of {type(self).__name__}'s aggregates")

    def lump_aggregates(self) -> None:
        """Order the aggregates by kind (all links, then all joints, ...)."""
        self._aggregates = [(field.xml_var, value) for field in self.XML_REFL.aggregates
                            for value in self.get_aggregate_list(field.xml_var)]

    def add_aggregates_to_xml(self, node: ET.Element) -> None:
        """Write the aggregates in the order added; then those put into the lists directly
        (``robot.links.append(...)``), kind by kind."""
        children = self.XML_REFL.children
        done = set()
        for xml_var, value in self._aggregate_record():
            children[xml_var].emit(node, value)
            done.add(id(value))
        for field in self.XML_REFL.aggregates:
            for value in self.get_aggregate_list(field.xml_var):
                if id(value) not in done:
                    field.emit(node, value)
                    done.add(id(value))

    # -- printing --------------------------------------------------------------------------
    def get_refl_vars(self) -> List[str]:
        return [field.var for field in self.XML_REFL.fields]

    def to_yaml(self) -> Any:
        return to_yaml({var: getattr(self, var, None) for var in self.get_refl_vars()})

    def __str__(self) -> str:
        import yaml  # only for printing

        return str(yaml.dump(self.to_yaml())).rstrip()


# Named types that every description can use: an element holding a name or a number
add_type("element_name", SimpleElementType("name", str))
add_type("element_value", SimpleElementType("value", float))
for _vector in ("vector3", "vector4", "vector6"):  # registered outside any namespace
    get_type(_vector)

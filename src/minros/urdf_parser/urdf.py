"""The URDF model of urdf_parser_py (ROS 1's ``urdf_parser_py.urdf``, melodic-devel/noetic 0.4.6):
``URDF.from_xml_string``/``from_xml_file``/``from_parameter_server``, the robot's links and
joints with their maps, ``get_chain``/``get_root``, and ``to_xml_string``.

The names, constructor keywords, defaults and XML forms are upstream's; each class lists its
XML with ``xmlr.reflect`` (see ``xml_reflection.core``).
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple

from . import xml_reflection as xmlr
from .xml_reflection.core import node_add, xml_children, xml_string

__all__ = [
    "Actuator", "Box", "Collision", "Color", "Cylinder", "GeometricType", "Inertia", "Inertial",
    "Joint", "JointCalibration", "JointDynamics", "JointLimit", "JointMimic", "Link",
    "LinkMaterial", "Material", "Mesh", "PR2Transmission", "Pose", "Robot", "SafetyController",
    "Sphere", "Texture", "Transmission", "TransmissionJoint", "URDF", "Visual", "node_add",
    "xml_children", "xml_string",
]

xmlr.start_namespace("urdf")
xmlr.add_type("element_link", xmlr.SimpleElementType("link", str))
xmlr.add_type("element_xyz", xmlr.SimpleElementType("xyz", "vector3"))

verbose = True


def _alias(attribute: str, doc: str) -> Any:
    """A property that is another name of ``attribute`` (an older API's name)."""
    return property(lambda self: getattr(self, attribute),
                    lambda self, value: setattr(self, attribute, value), doc=doc)


class Pose(xmlr.Object):
    """``<origin xyz="..." rpy="..."/>``; ``position``/``rotation`` are older names."""

    def __init__(self, xyz: Optional[List[float]] = None, rpy: Optional[List[float]] = None) -> None:
        self.xyz = xyz
        self.rpy = rpy

    def check_valid(self) -> None:
        for name in ("xyz", "rpy"):
            value = getattr(self, name)
            if value is not None and len(value) != 3:
                raise ValueError(f"origin {name} needs 3 numbers, not {list(value)}")

    position = _alias("xyz", "``xyz`` under its older name.")
    rotation = _alias("rpy", "``rpy`` under its older name.")


xmlr.reflect(Pose, tag="origin", params=[
    xmlr.Attribute("xyz", "vector3", False, default=[0, 0, 0]),
    xmlr.Attribute("rpy", "vector3", False, default=[0, 0, 0]),
])

name_attribute = xmlr.Attribute("name", str)
origin_element = xmlr.Element("origin", Pose, False)


class Color(xmlr.Object):
    """``<color rgba="r g b a"/>``: ``Color(r, g, b[, a])`` or ``Color([r, g, b[, a]])``."""

    def __init__(self, *args: Any) -> None:
        if len(args) in (3, 4):
            rgba: Any = list(args)
        elif len(args) == 1:
            rgba = args[0]
        elif not args:
            rgba = None
        else:
            raise ValueError(f"Color takes 3 or 4 numbers, or one list of them; got {len(args)}")
        if rgba is not None:
            rgba = list(rgba)
            if len(rgba) == 3:
                rgba.append(1.0)
            if len(rgba) != 4:
                raise ValueError(f"Color needs 3 or 4 numbers (r g b [a]), got {rgba}")
        self.rgba = rgba


xmlr.reflect(Color, tag="color", params=[xmlr.Attribute("rgba", "vector4")])


class JointDynamics(xmlr.Object):
    def __init__(self, damping: Optional[float] = None, friction: Optional[float] = None) -> None:
        self.damping = damping
        self.friction = friction


xmlr.reflect(JointDynamics, tag="dynamics", params=[
    xmlr.Attribute("damping", float, False),
    xmlr.Attribute("friction", float, False),
])


# -- geometry ----------------------------------------------------------------------------------

class Box(xmlr.Object):
    def __init__(self, size: Optional[List[float]] = None) -> None:
        self.size = size


xmlr.reflect(Box, tag="box", params=[xmlr.Attribute("size", "vector3")])


class Cylinder(xmlr.Object):
    def __init__(self, radius: float = 0.0, length: float = 0.0) -> None:
        self.radius = radius
        self.length = length


xmlr.reflect(Cylinder, tag="cylinder", params=[
    xmlr.Attribute("radius", float),
    xmlr.Attribute("length", float),
])


class Sphere(xmlr.Object):
    def __init__(self, radius: float = 0.0) -> None:
        self.radius = radius


xmlr.reflect(Sphere, tag="sphere", params=[xmlr.Attribute("radius", float)])


class Mesh(xmlr.Object):
    def __init__(self, filename: Optional[str] = None, scale: Optional[List[float]] = None) -> None:
        self.filename = filename
        self.scale = scale


xmlr.reflect(Mesh, tag="mesh", params=[
    xmlr.Attribute("filename", str),
    xmlr.Attribute("scale", "vector3", required=False),
])


class GeometricType(xmlr.ValueType):
    """``<geometry>`` holding exactly one of ``<box>``, ``<cylinder>``, ``<sphere>``, ``<mesh>``."""

    def __init__(self) -> None:
        self.factory = xmlr.FactoryType("geometric", {
            "box": Box, "cylinder": Cylinder, "sphere": Sphere, "mesh": Mesh})

    def from_xml(self, node: Any, path: xmlr.Path) -> Any:
        shapes = list(node)
        if len(shapes) != 1:
            found = ", ".join(f"<{s.tag}>" for s in shapes) or "none"
            raise xmlr.ParseError(ValueError(
                f"<geometry> holds one shape (box, cylinder, sphere or mesh); found {found}"), path)
        return self.factory.from_xml(shapes[0], xmlr.Path(shapes[0].tag, path))

    def write_xml(self, node: Any, obj: Any) -> None:
        obj.write_xml(node_add(node, self.factory.get_name(obj)))


xmlr.add_type("geometric", GeometricType())


class Collision(xmlr.Object):
    def __init__(self, geometry: Any = None, origin: Optional[Pose] = None,
                 name: Optional[str] = None) -> None:
        self.geometry = geometry
        self.name = name
        self.origin = origin


xmlr.reflect(Collision, tag="collision", params=[
    xmlr.Attribute("name", str, False),
    origin_element,
    xmlr.Element("geometry", "geometric"),
])


class Texture(xmlr.Object):
    def __init__(self, filename: Optional[str] = None) -> None:
        self.filename = filename


xmlr.reflect(Texture, tag="texture", params=[xmlr.Attribute("filename", str)])


class Material(xmlr.Object):
    """A robot-level ``<material>``: a name, and a color or a texture (or both)."""

    def __init__(self, name: Optional[str] = None, color: Optional[Color] = None,
                 texture: Optional[Texture] = None) -> None:
        self.name = name
        self.color = color
        self.texture = texture

    def check_valid(self) -> None:
        if self.color is None and self.texture is None:
            # through the package's hook, looked up now: callers replace it
            xmlr.on_error("Material has neither a color nor texture.")


xmlr.reflect(Material, tag="material", params=[
    name_attribute,
    xmlr.Element("color", Color, False),
    xmlr.Element("texture", Texture, False),
])


class LinkMaterial(Material):
    """A visual's ``<material>``: may be only a name, of a robot-level material."""

    def check_valid(self) -> None:
        pass


class Visual(xmlr.Object):
    def __init__(self, geometry: Any = None, material: Optional[Material] = None,
                 origin: Optional[Pose] = None, name: Optional[str] = None) -> None:
        self.geometry = geometry
        self.material = material
        self.name = name
        self.origin = origin


xmlr.reflect(Visual, tag="visual", params=[
    xmlr.Attribute("name", str, False),
    origin_element,
    xmlr.Element("geometry", "geometric"),
    xmlr.Element("material", LinkMaterial, False),
])


class Inertia(xmlr.Object):
    KEYS = ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]

    def __init__(self, ixx: float = 0.0, ixy: float = 0.0, ixz: float = 0.0, iyy: float = 0.0,
                 iyz: float = 0.0, izz: float = 0.0) -> None:
        self.ixx, self.ixy, self.ixz = ixx, ixy, ixz
        self.iyy, self.iyz, self.izz = iyy, iyz, izz

    def to_matrix(self) -> List[List[float]]:
        """The symmetric 3x3 inertia matrix, row by row."""
        return [[self.ixx, self.ixy, self.ixz],
                [self.ixy, self.iyy, self.iyz],
                [self.ixz, self.iyz, self.izz]]


xmlr.reflect(Inertia, tag="inertia", params=[xmlr.Attribute(key, float) for key in Inertia.KEYS])


class Inertial(xmlr.Object):
    def __init__(self, mass: float = 0.0, inertia: Optional[Inertia] = None,
                 origin: Optional[Pose] = None) -> None:
        self.mass = mass
        self.inertia = inertia
        self.origin = origin


xmlr.reflect(Inertial, tag="inertial", params=[
    origin_element,
    xmlr.Element("mass", "element_value"),
    xmlr.Element("inertia", Inertia, False),
])


# -- joints ------------------------------------------------------------------------------------

class JointCalibration(xmlr.Object):
    def __init__(self, rising: Optional[float] = None, falling: Optional[float] = None) -> None:
        self.rising = rising
        self.falling = falling


xmlr.reflect(JointCalibration, tag="calibration", params=[
    xmlr.Attribute("rising", float, False, 0),
    xmlr.Attribute("falling", float, False, 0),
])


class JointLimit(xmlr.Object):
    def __init__(self, effort: Optional[float] = None, velocity: Optional[float] = None,
                 lower: Optional[float] = None, upper: Optional[float] = None) -> None:
        self.effort = effort
        self.velocity = velocity
        self.lower = lower
        self.upper = upper


xmlr.reflect(JointLimit, tag="limit", params=[
    xmlr.Attribute("effort", float),
    xmlr.Attribute("lower", float, False, 0),
    xmlr.Attribute("upper", float, False, 0),
    xmlr.Attribute("velocity", float),
])


class JointMimic(xmlr.Object):
    def __init__(self, joint_name: Optional[str] = None, multiplier: Optional[float] = None,
                 offset: Optional[float] = None) -> None:
        self.joint = joint_name
        self.multiplier = multiplier
        self.offset = offset


xmlr.reflect(JointMimic, tag="mimic", params=[
    xmlr.Attribute("joint", str),
    xmlr.Attribute("multiplier", float, False),
    xmlr.Attribute("offset", float, False),
])


class SafetyController(xmlr.Object):
    def __init__(self, velocity: Optional[float] = None, position: Optional[float] = None,
                 lower: Optional[float] = None, upper: Optional[float] = None) -> None:
        self.k_velocity = velocity
        self.k_position = position
        self.soft_lower_limit = lower
        self.soft_upper_limit = upper


xmlr.reflect(SafetyController, tag="safety_controller", params=[
    xmlr.Attribute("k_velocity", float),
    xmlr.Attribute("k_position", float, False, 0),
    xmlr.Attribute("soft_lower_limit", float, False, 0),
    xmlr.Attribute("soft_upper_limit", float, False, 0),
])


class Joint(xmlr.Object):
    TYPES = ["unknown", "revolute", "continuous", "prismatic", "floating", "planar", "fixed"]

    def __init__(self, name: Optional[str] = None, parent: Optional[str] = None,
                 child: Optional[str] = None, joint_type: Optional[str] = None,
                 axis: Optional[List[float]] = None, origin: Optional[Pose] = None,
                 limit: Optional[JointLimit] = None, dynamics: Optional[JointDynamics] = None,
                 safety_controller: Optional[SafetyController] = None,
                 calibration: Optional[JointCalibration] = None,
                 mimic: Optional[JointMimic] = None) -> None:
        self.name = name
        self.parent = parent
        self.child = child
        self.type = joint_type
        self.axis = axis
        self.origin = origin
        self.limit = limit
        self.dynamics = dynamics
        self.safety_controller = safety_controller
        self.calibration = calibration
        self.mimic = mimic

    def check_valid(self) -> None:
        if self.type not in self.TYPES:
            raise ValueError(f"Invalid joint type: {self.type} (one of: {', '.join(self.TYPES[1:])})")

    joint_type = _alias("type", "``type``, under the constructor keyword's name.")


xmlr.reflect(Joint, tag="joint", params=[
    name_attribute,
    xmlr.Attribute("type", str),
    origin_element,
    xmlr.Element("axis", "element_xyz", False),
    xmlr.Element("parent", "element_link"),
    xmlr.Element("child", "element_link"),
    xmlr.Element("limit", JointLimit, False),
    xmlr.Element("dynamics", JointDynamics, False),
    xmlr.Element("safety_controller", SafetyController, False),
    xmlr.Element("calibration", JointCalibration, False),
    xmlr.Element("mimic", JointMimic, False),
])


# -- links -------------------------------------------------------------------------------------

class Link(xmlr.Object):
    """A link: ``visuals``/``collisions`` (all of them), ``visual``/``collision`` (the first)."""

    def __init__(self, name: Optional[str] = None, visual: Optional[Visual] = None,
                 inertial: Optional[Inertial] = None, collision: Optional[Collision] = None,
                 origin: Optional[Pose] = None) -> None:
        self.aggregate_init()
        self.name = name
        self.visuals: List[Any] = []
        self.collisions: List[Any] = []
        self.inertial = inertial
        self.origin = origin
        if visual:
            self.visual = visual
        if collision:
            self.collision = collision

    def _replace_first(self, xml_var: str, value: Any) -> None:
        # The first of the list becomes ``value``, and ``value`` joins the write order, while
        # whatever it replaced stays there: setting ``link.visual`` twice writes two visuals,
        # which upstream's own tests expect.
        values = self.get_aggregate_list(xml_var)
        values[:1] = [value]
        if value is not None:
            self._aggregate_record().append((xml_var, value))

    visual = property(lambda self: self.visuals[0] if self.visuals else None,
                      lambda self, value: self._replace_first("visual", value),
                      doc="The first of ``visuals`` (None if there is none).")
    collision = property(lambda self: self.collisions[0] if self.collisions else None,
                         lambda self, value: self._replace_first("collision", value),
                         doc="The first of ``collisions`` (None if there is none).")


xmlr.reflect(Link, tag="link", params=[
    name_attribute,
    origin_element,
    xmlr.AggregateElement("visual", Visual),
    xmlr.AggregateElement("collision", Collision),
    xmlr.Element("inertial", Inertial, False),
])


# -- transmissions -----------------------------------------------------------------------------

class PR2Transmission(xmlr.Object):
    """The older transmission form: ``type`` attribute, one joint and actuator by name."""

    def __init__(self, name: Optional[str] = None, joint: Optional[str] = None,
                 actuator: Optional[str] = None, type: Optional[str] = None,
                 mechanicalReduction: float = 1) -> None:
        self.name = name
        self.type = type
        self.joint = joint
        self.actuator = actuator
        self.mechanicalReduction = mechanicalReduction


xmlr.reflect(PR2Transmission, tag="pr2_transmission", params=[
    name_attribute,
    xmlr.Attribute("type", str),
    xmlr.Element("joint", "element_name"),
    xmlr.Element("actuator", "element_name"),
    xmlr.Element("mechanicalReduction", float),
])


class Actuator(xmlr.Object):
    def __init__(self, name: Optional[str] = None,
                 mechanicalReduction: Optional[float] = None) -> None:
        self.name = name
        self.mechanicalReduction = mechanicalReduction


xmlr.reflect(Actuator, tag="actuator", params=[
    name_attribute,
    xmlr.Element("mechanicalReduction", float, required=False),
])


class TransmissionJoint(xmlr.Object):
    def __init__(self, name: Optional[str] = None) -> None:
        self.aggregate_init()
        self.name = name
        self.hardwareInterfaces: List[str] = []

    def check_valid(self) -> None:
        if not self.hardwareInterfaces:
            raise ValueError(f"transmission joint '{self.name}' has no <hardwareInterface>")


xmlr.reflect(TransmissionJoint, tag="joint", params=[
    name_attribute,
    xmlr.AggregateElement("hardwareInterface", str),
])


class Transmission(xmlr.Object):
    """The transmission form of http://wiki.ros.org/urdf/XML/Transmission."""

    def __init__(self, name: Optional[str] = None) -> None:
        self.aggregate_init()
        self.name = name
        self.type: Optional[str] = None
        self.joints: List[TransmissionJoint] = []
        self.actuators: List[Actuator] = []

    def check_valid(self) -> None:
        if not self.joints:
            raise ValueError(f"transmission '{self.name}' has no <joint>")
        if not self.actuators:
            raise ValueError(f"transmission '{self.name}' has no <actuator>")


xmlr.reflect(Transmission, tag="new_transmission", params=[
    name_attribute,
    xmlr.Element("type", str),
    xmlr.AggregateElement("joint", TransmissionJoint),
    xmlr.AggregateElement("actuator", Actuator),
])

xmlr.add_type("transmission", xmlr.DuckTypedFactory("transmission", [Transmission, PR2Transmission]))


# -- the robot ---------------------------------------------------------------------------------

class Robot(xmlr.Object):
    """A URDF ``<robot>``: its ``links``, ``joints``, ``materials``, ``transmissions`` and
    ``gazebos`` (raw elements), with ``link_map``/``joint_map`` by name, ``parent_map``
    (child link -> (joint, parent link)) and ``child_map`` (link -> [(joint, child link)])."""

    SUPPORTED_VERSIONS = ["1.0"]

    def __init__(self, name: Optional[str] = None, version: Optional[str] = "1.0") -> None:
        self.aggregate_init()
        if version not in self.SUPPORTED_VERSIONS:
            raise ValueError(f"Invalid version; only {','.join(self.SUPPORTED_VERSIONS)} is supported")
        self.name = name
        self.version = version
        self.joints: List[Joint] = []
        self.links: List[Link] = []
        self.materials: List[Material] = []
        self.gazebos: List[Any] = []
        self.transmissions: List[Any] = []
        self.joint_map: Dict[str, Joint] = {}
        self.link_map: Dict[str, Link] = {}
        self.parent_map: Dict[str, Tuple[str, str]] = {}
        self.child_map: Dict[str, List[Tuple[str, str]]] = {}

    def add_aggregate(self, typeName: str, elem: Any) -> None:
        """Add a link, joint, ... (``typeName`` is its tag), keeping the maps up to date."""
        super().add_aggregate(typeName, elem)
        if typeName == "link":
            self.link_map[elem.name] = elem
        if typeName != "joint":
            return
        name, parent, child = elem.name, elem.parent, elem.child
        self.joint_map[name] = elem
        self.parent_map[child] = (name, parent)
        if parent not in self.child_map:
            self.child_map[parent] = []
        self.child_map[parent].append((name, child))

    def add_link(self, link: Link) -> None:
        self.add_aggregate("link", link)

    def add_joint(self, joint: Joint) -> None:
        self.add_aggregate("joint", joint)

    def get_chain(self, root: str, tip: str, joints: bool = True, links: bool = True,
                  fixed: bool = True) -> List[str]:
        """The names from ``root`` down to ``tip``: links and joints alternating (as chosen;
        ``fixed=False`` leaves fixed joints out)."""
        steps: List[Tuple[str, str]] = []  # (joint, its child link), from tip upwards
        link = tip
        while link != root:
            above = self.parent_map.get(link)
            if above is None:
                why = "" if tip in self.link_map else f" ('{tip}' is not a link)"
                raise KeyError(f"no chain from link '{root}' to '{tip}': '{link}' has no "
                               f"parent joint{why}")
            steps.append((above[0], link))
            link = above[1]
        names = [root] if links else []
        for joint, child in reversed(steps):
            if joints and (fixed or self.joint_map[joint].type != "fixed"):
                names.append(joint)
            if links:
                names.append(child)
        return names

    def get_root(self) -> str:
        """The one link that is no joint's child."""
        roots = set(self.link_map) - set(self.parent_map)
        if not roots:
            raise AssertionError("No roots detected, invalid URDF.")
        if len(roots) > 1:
            names = ", ".join(name for name in self.link_map if name in roots)
            raise AssertionError(f"Multiple roots detected, invalid URDF: {names}")
        return roots.pop()

    def post_read_xml(self) -> None:
        if self.version is None:
            self.version = "1.0"
        parts = self.version.split(".")
        if len(parts) != 2:
            raise ValueError(f"The version attribute should be in the form 'x.y', not '{self.version}'")
        if not parts[0] or not parts[1]:
            raise ValueError(f"Empty major or minor number is not allowed: version '{self.version}'")
        try:
            numbers = [int(part) for part in parts]
        except ValueError:
            raise ValueError(f"The version attribute should be two numbers 'x.y', not "
                             f"'{self.version}'") from None
        if min(numbers) < 0:
            raise ValueError(f"Version number must be positive: '{self.version}'")
        if self.version not in self.SUPPORTED_VERSIONS:
            raise ValueError(f"Invalid version; only {','.join(self.SUPPORTED_VERSIONS)} is supported")

    @classmethod
    def from_parameter_server(cls, key: str = "robot_description") -> Robot:
        """The robot described by the parameter ``key`` (KeyError when it is not set).
        Needs a master, as any parameter read does."""
        import minros  # the client API: the node's parameter server

        return cls.from_xml_string(minros.get_param(key))


xmlr.reflect(Robot, tag="robot", params=[
    xmlr.Attribute("name", str),
    xmlr.Attribute("version", str, False),
    xmlr.AggregateElement("link", Link),
    xmlr.AggregateElement("joint", Joint),
    xmlr.AggregateElement("gazebo", xmlr.RawType()),
    xmlr.AggregateElement("transmission", "transmission"),
    xmlr.AggregateElement("material", Material),
])

URDF = Robot

xmlr.end_namespace()

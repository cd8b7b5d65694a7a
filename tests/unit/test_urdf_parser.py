"""urdf_parser_py (minros.urdf_parser behind the ``urdf_parser_py`` stand-in): a realistic robot
read into upstream's object model, written back and read again, chains and roots, and one
clear error naming the element for each kind of broken description."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

import urdf_parser_py.xml_reflection as xmlr
from urdf_parser_py import urdf
from urdf_parser_py.urdf import URDF

# A mobile manipulator: every element urdf_parser_py knows (geometries, materials by name and
# inline, inertials, limits, safety controller, calibration, dynamics, mimic, both
# transmission forms, a <gazebo> block kept raw).
ROBOT = """<?xml version="1.0"?>
<robot name="mobile_arm">
  <material name="blue"><color rgba="0.1 0.2 0.8 1"/></material>
  <material name="wood"><texture filename="package://mobile_arm/textures/wood.png"/></material>
  <link name="base_footprint"/>
  <link name="base_link">
    <inertial>
      <origin xyz="0 0 0.1"/>
      <mass value="12.5"/>
      <inertia ixx="0.2" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.4"/>
    </inertial>
    <visual name="body">
      <origin xyz="0 0 0.1" rpy="0 0 0"/>
      <geometry><box size="0.5 0.4 0.2"/></geometry>
      <material name="blue"/>
    </visual>
    <visual name="deck">
      <origin xyz="0 0 0.21"/>
      <geometry><mesh filename="package://mobile_arm/meshes/deck.stl" scale="0.001 0.001 0.001"/></geometry>
      <material name="wood"/>
    </visual>
    <collision name="body_collision">
      <geometry><box size="0.5 0.4 0.2"/></geometry>
    </collision>
  </link>
  <link name="wheel_left">
    <visual>
      <origin rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.08" length="0.04"/></geometry>
      <material name="black"><color rgba="0 0 0 1"/></material>
    </visual>
    <collision><geometry><cylinder radius="0.08" length="0.04"/></geometry></collision>
  </link>
  <link name="caster"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
  <link name="shoulder"/>
  <link name="upper_arm"/>
  <link name="tool0"/>
  <link name="finger_left"/>
  <link name="finger_right"/>
  <joint name="base_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.08"/>
  </joint>
  <joint name="wheel_left_joint" type="continuous">
    <parent link="base_link"/><child link="wheel_left"/>
    <origin xyz="0 0.22 0"/><axis xyz="0 1 0"/>
    <dynamics damping="0.1" friction="0.05"/>
  </joint>
  <joint name="caster_joint" type="fixed">
    <parent link="base_link"/><child link="caster"/><origin xyz="-0.2 0 -0.05"/>
  </joint>
  <joint name="shoulder_pan" type="revolute">
    <parent link="base_link"/><child link="shoulder"/>
    <origin xyz="0.1 0 0.25" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 1"/>
    <limit lower="-3.1" upper="3.1" effort="30" velocity="1.5"/>
    <safety_controller k_velocity="10" k_position="15" soft_lower_limit="-3.0" soft_upper_limit="3.0"/>
    <calibration rising="0.05"/>
  </joint>
  <joint name="elbow" type="prismatic">
    <parent link="shoulder"/><child link="upper_arm"/><axis xyz="1 0 0"/>
    <limit upper="0.4" effort="100" velocity="0.2"/>
  </joint>
  <joint name="tool_joint" type="fixed"><parent link="upper_arm"/><child link="tool0"/></joint>
  <joint name="finger_left_joint" type="prismatic">
    <parent link="tool0"/><child link="finger_left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/>
  </joint>
  <joint name="finger_right_joint" type="prismatic">
    <parent link="tool0"/><child link="finger_right"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/>
    <mimic joint="finger_left_joint" multiplier="1" offset="0"/>
  </joint>
  <transmission name="pan_trans">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="shoulder_pan"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="pan_motor"><mechanicalReduction>50.0</mechanicalReduction></actuator>
  </transmission>
  <transmission name="wheel_trans" type="pr2_mechanism_model/SimpleTransmission">
    <joint name="wheel_left_joint"/>
    <actuator name="wheel_motor"/>
    <mechanicalReduction>20.0</mechanicalReduction>
  </transmission>
  <gazebo reference="base_link"><material>Gazebo/Blue</material></gazebo>
</robot>
"""


def _numbers(text: str) -> list:
    """Each element of a document: its tag, and its attributes with numbers read as numbers."""

    def value(text: str) -> object:
        try:
            return [float(word) for word in text.split()]
        except ValueError:
            return text

    return [(e.tag, {k: value(v) for k, v in e.attrib.items()}, (e.text or "").strip())
            for e in ET.fromstring(text).iter()]


def _keys(root: ET.Element) -> set:
    """(tag, attribute name) of every attribute in a document."""
    return {(e.tag, key) for e in root.iter() for key in e.attrib}


@pytest.fixture
def raising_on_error(monkeypatch):
    """What a reader can skip (unknown tags) raises instead of going to stderr."""

    def fail(message: str) -> None:
        raise xmlr.core.ParseError(message, "")

    monkeypatch.setattr(xmlr.core, "on_error", fail)
    monkeypatch.setattr(xmlr, "on_error", fail)


def test_a_realistic_robot_reads_into_upstreams_object_model(raising_on_error) -> None:
    robot = URDF.from_xml_string(ROBOT)
    assert (robot.name, robot.version) == ("mobile_arm", "1.0")
    assert [link.name for link in robot.links][:3] == ["base_footprint", "base_link", "wheel_left"]
    assert len(robot.joints) == 8 and set(robot.link_map) == {link.name for link in robot.links}
    assert robot.get_root() == "base_footprint"

    pan = robot.joint_map["shoulder_pan"]
    assert (pan.type, pan.joint_type, pan.parent, pan.child) == ("revolute", "revolute", "base_link", "shoulder")
    assert pan.axis == [0.0, 0.0, 1.0]
    assert pan.origin.xyz == [0.1, 0.0, 0.25] and pan.origin.position is pan.origin.xyz
    assert pan.origin.rotation == pan.origin.rpy == [0.0, 0.0, 1.5707963267948966]
    assert (pan.limit.lower, pan.limit.upper, pan.limit.effort, pan.limit.velocity) == (-3.1, 3.1, 30.0, 1.5)
    sc = pan.safety_controller
    assert (sc.k_velocity, sc.k_position, sc.soft_lower_limit, sc.soft_upper_limit) == (10.0, 15.0, -3.0, 3.0)
    assert (pan.calibration.rising, pan.calibration.falling) == (0.05, 0)  # upstream's default 0
    elbow = robot.joint_map["elbow"]
    assert (elbow.limit.lower, elbow.limit.upper) == (0, 0.4) and elbow.origin is None
    wheel = robot.joint_map["wheel_left_joint"]
    assert (wheel.dynamics.damping, wheel.dynamics.friction) == (0.1, 0.05) and wheel.limit is None
    mimic = robot.joint_map["finger_right_joint"].mimic
    assert (mimic.joint, mimic.multiplier, mimic.offset) == ("finger_left_joint", 1.0, 0.0)

    base = robot.link_map["base_link"]
    assert [v.name for v in base.visuals] == ["body", "deck"] and base.visual is base.visuals[0]
    assert isinstance(base.visual.geometry, urdf.Box) and base.visual.geometry.size == [0.5, 0.4, 0.2]
    assert base.visual.material.name == "blue" and base.visual.material.color is None
    deck = base.visuals[1]
    assert isinstance(deck.geometry, urdf.Mesh)
    assert deck.geometry.filename == "package://mobile_arm/meshes/deck.stl"
    assert deck.geometry.scale == [0.001, 0.001, 0.001]
    assert base.collision.name == "body_collision" and base.collision.origin is None
    inertial = base.inertial
    assert inertial.mass == 12.5 and inertial.origin.xyz == [0, 0, 0.1] and inertial.origin.rpy == [0, 0, 0]
    assert inertial.inertia.to_matrix() == [[0.2, 0, 0], [0, 0.3, 0], [0, 0, 0.4]]
    wheel_link = robot.link_map["wheel_left"]
    assert (wheel_link.visual.geometry.radius, wheel_link.visual.geometry.length) == (0.08, 0.04)
    assert wheel_link.visual.material.color.rgba == [0, 0, 0, 1]
    assert robot.link_map["caster"].collision.geometry.radius == 0.03
    assert robot.link_map["tool0"].visual is None and robot.link_map["tool0"].inertial is None

    blue, wood = robot.materials
    assert blue.color.rgba == [0.1, 0.2, 0.8, 1.0] and blue.texture is None
    assert wood.texture.filename == "package://mobile_arm/textures/wood.png"

    new, old = robot.transmissions
    assert isinstance(new, urdf.Transmission) and new.type == "transmission_interface/SimpleTransmission"
    assert [j.name for j in new.joints] == ["shoulder_pan"]
    assert new.joints[0].hardwareInterfaces == ["hardware_interface/EffortJointInterface"]
    assert new.actuators[0].name == "pan_motor" and new.actuators[0].mechanicalReduction == 50.0
    assert isinstance(old, urdf.PR2Transmission)
    assert (old.joint, old.actuator, old.mechanicalReduction) == ("wheel_left_joint", "wheel_motor", 20.0)
    (gazebo,) = robot.gazebos
    assert gazebo.get("reference") == "base_link" and gazebo.find("material").text == "Gazebo/Blue"


def test_maps_and_chains() -> None:
    robot = URDF.from_xml_string(ROBOT)
    assert robot.parent_map["shoulder"] == ("shoulder_pan", "base_link")
    assert robot.child_map["tool0"] == [("finger_left_joint", "finger_left"),
                                        ("finger_right_joint", "finger_right")]
    assert robot.get_chain("base_footprint", "tool0") == [
        "base_footprint", "base_joint", "base_link", "shoulder_pan", "shoulder", "elbow",
        "upper_arm", "tool_joint", "tool0"]
    assert robot.get_chain("base_link", "tool0", links=False) == ["shoulder_pan", "elbow", "tool_joint"]
    assert robot.get_chain("base_footprint", "tool0", links=False, fixed=False) == ["shoulder_pan", "elbow"]
    assert robot.get_chain("base_link", "upper_arm", joints=False) == ["base_link", "shoulder", "upper_arm"]
    assert robot.get_chain("tool0", "tool0") == ["tool0"]
    with pytest.raises(KeyError, match="'shoulder' to 'caster'"):
        robot.get_chain("shoulder", "caster")  # caster is not below the shoulder
    with pytest.raises(KeyError, match="'nowhere' is not a link"):
        robot.get_chain("base_link", "nowhere")


def test_round_trip_through_to_xml_string() -> None:
    robot = URDF.from_xml_string(ROBOT)
    text = robot.to_xml_string()
    assert text.startswith('<?xml version="1.0" ?>\n<robot name="mobile_arm" version="1.0">\n  <material name="blue">')
    assert '    <mimic joint="finger_left_joint" multiplier="1.0" offset="0.0"/>' in text.splitlines()
    again = URDF.from_xml_string(text)
    # the same document, but for the defaults written as read ("0 0 0" comes back "0.0 0.0 0.0")
    assert _numbers(again.to_xml_string()) == _numbers(text)
    assert URDF.from_xml_string(again.to_xml_string()).to_xml_string() == again.to_xml_string()
    assert again.get_chain("base_footprint", "finger_right") == robot.get_chain("base_footprint", "finger_right")
    # every element and attribute of the original is in the output (a joint's children in the
    # order upstream writes them: origin first), and nothing else but defaults
    original, written = ET.fromstring(ROBOT), ET.fromstring(text)
    assert sorted(e.tag for e in original.iter()) == sorted(e.tag for e in written.iter())
    assert _keys(original) <= _keys(written)
    assert _keys(written) - _keys(original) == {("robot", "version"), ("calibration", "falling")}
    assert not robot.to_xml_string(addHeader=False).startswith("<?xml")


def test_a_robot_built_in_code_writes_urdf() -> None:
    robot = URDF(name="built")
    robot.add_link(urdf.Link(name="base", visual=urdf.Visual(
        geometry=urdf.Sphere(radius=0.5), material=urdf.Material(name="red", color=urdf.Color(1, 0, 0)))))
    robot.add_link(urdf.Link(name="arm", inertial=urdf.Inertial(mass=2.0, inertia=urdf.Inertia(ixx=1.0))))
    robot.add_joint(urdf.Joint(name="j", parent="base", child="arm", joint_type="revolute", axis=[0, 0, 1],
                               origin=urdf.Pose(xyz=[0, 0, 1]), limit=urdf.JointLimit(effort=1, velocity=2)))
    robot.links.append(urdf.Link(name="appended"))  # not through add_link: written all the same
    assert robot.get_root() == "base" and robot.get_chain("base", "arm") == ["base", "j", "arm"]
    assert robot.to_xml_string() == """<?xml version="1.0" ?>
<robot name="built" version="1.0">
  <link name="base">
    <visual>
      <geometry>
        <sphere radius="0.5"/>
      </geometry>
      <material name="red">
        <color rgba="1 0 0 1.0"/>
      </material>
    </visual>
  </link>
  <link name="arm">
    <inertial>
      <mass value="2.0"/>
      <inertia ixx="1.0" ixy="0.0" ixz="0.0" iyy="0.0" iyz="0.0" izz="0.0"/>
    </inertial>
  </link>
  <joint name="j" type="revolute">
    <origin xyz="0 0 1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <parent link="base"/>
    <child link="arm"/>
    <limit effort="1" lower="0" upper="0" velocity="2"/>
  </joint>
  <link name="appended"/>
</robot>"""
    assert "name: built" in str(robot) and "radius: 0.5" in str(robot)


def test_from_xml_file_reads_utf8(tmp_path) -> None:
    path = tmp_path / "robot.urdf"
    path.write_text('<?xml version="1.0" encoding="utf-8"?>\n<robot name="r\u00f6bot"><link name="\u00e4"/></robot>',
                    encoding="utf-8")
    robot = URDF.from_xml_file(str(path))
    assert robot.name == "r\u00f6bot" and robot.get_root() == "\u00e4"


@pytest.mark.parametrize("body, path, message", [
    ('<link name="a"><inertial><origin xyz="0 0 x"/><mass value="1"/></inertial></link>',
     "/robot[@name='r']/link[@name='a']/inertial/origin[@xyz]", "'0 0 x' is not 3 numbers"),
    ('<link name="a"><visual><origin xyz="1 2"/><geometry><box size="1 1 1"/></geometry></visual></link>',
     "/robot[@name='r']/link[@name='a']/visual[1]/origin[@xyz]", "expected 3 numbers, got 2"),
    ('<link name="a"/><link/>', "/robot[@name='r']/link[2]", "Required attribute not set in XML: name"),
    ('<joint name="j" type="hinge"><parent link="a"/><child link="b"/></joint>',
     "/robot[@name='r']/joint[@name='j']", "Invalid joint type: hinge"),
    ('<joint name="j" type="fixed"><parent link="a"/></joint>',
     "/robot[@name='r']/joint[@name='j']", "Required element not set in XML: child"),
    ('<joint name="j" type="fixed"><parent/><child link="b"/></joint>',
     "/robot[@name='r']/joint[@name='j']/parent", "<parent> has no 'link' attribute"),
    ('<joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit effort="big" velocity="1"/></joint>',
     "/robot[@name='r']/joint[@name='j']/limit[@effort]", "'big' is not a number"),
    ('<link name="a"><collision><geometry/></collision></link>',
     "/robot[@name='r']/link[@name='a']/collision[1]/geometry", "holds one shape"),
    ('<link name="a"><collision><geometry><cone/></geometry></collision></link>',
     "/robot[@name='r']/link[@name='a']/collision[1]/geometry/cone", "Invalid geometric tag: <cone>"),
    ('<transmission name="t"><type>x</type><actuator name="m"/></transmission>',
     "/robot[@name='r']/transmission[@name='t']", "transmission 't' has no <joint>"),
])
def test_broken_descriptions_name_the_element(body: str, path: str, message: str) -> None:
    with pytest.raises(xmlr.ParseError) as info:
        URDF.from_xml_string(f'<robot name="r">{body}</robot>')
    assert str(info.value.path) == path
    assert message in str(info.value) and str(info.value).startswith(f"ParseError in {path}:\n")


def test_what_can_be_skipped_goes_to_on_error(capsys) -> None:
    robot = URDF.from_xml_string('<robot name="r" colour="red"><link name="a"><sensor/></link>'
                                 '<material name="m"/></robot>')
    assert robot.link_map["a"].name == "a"  # read all the same
    assert capsys.readouterr().err.splitlines() == [
        'Unknown tag "sensor" in /robot[@name=\'r\']/link[@name=\'a\']',
        "Material has neither a color nor texture.",
        'Unknown attribute "colour" in /robot[@name=\'r\']',
    ]


def test_versions_and_bad_xml() -> None:
    assert URDF.from_xml_string('<robot name="r" version="1.0"/>').version == "1.0"
    for version, message in [("2.0", "only 1.0 is supported"), ("1", "form 'x.y'"),
                             ("1.x", "two numbers"), ("-1.0", "must be positive")]:
        with pytest.raises(ValueError, match=message):
            URDF.from_xml_string(f'<robot name="r" version="{version}"/>')
    with pytest.raises(ValueError, match="only 1.0 is supported"):
        URDF(name="r", version="2.0")
    with pytest.raises(ET.ParseError):
        URDF.from_xml_string("<robot name='r'><link>")
    with pytest.raises(AssertionError, match="Multiple roots detected, invalid URDF: a, b"):
        URDF.from_xml_string('<robot name="r"><link name="a"/><link name="b"/></robot>').get_root()


def test_display_urdf_prints_the_model_and_writes_xml(tmp_path, capsys) -> None:
    from minros.nodes.urdfdom_py.display_urdf import main

    source, out = tmp_path / "robot.urdf", tmp_path / "out.urdf"
    source.write_text(ROBOT)
    assert main([str(source), "-o", str(out), "__name:=display"]) == 0
    printed = capsys.readouterr().out
    assert "\nname: mobile_arm\n" in printed and "\n  name: shoulder_pan\n" in printed
    assert out.read_text() == URDF.from_xml_string(ROBOT).to_xml_string()


@pytest.mark.parametrize("text, message", [
    (None, "cannot read {path}: No such file or directory"),
    ("<robot name='r'><link>", "{path} is not XML: no element found: line 1, column 22"),
    ('<robot name="r"><link/></robot>', "{path}: ParseError in /robot[@name='r']/link[1]:\n"
                                        "Required attribute not set in XML: name"),
    ('<robot name="r" version="2.0"/>', "{path}: Invalid version; only 1.0 is supported"),
])
def test_display_urdf_names_what_is_wrong(tmp_path, capsys, text, message) -> None:
    from minros.nodes.urdfdom_py.display_urdf import main

    path = tmp_path / "robot.urdf"
    if text is not None:
        path.write_text(text)
    assert main([str(path)]) == 1
    captured = capsys.readouterr()
    assert captured.err == "display_urdf: " + message.format(path=path) + "\n"
    assert captured.out == ""


def test_display_urdf_reads_a_file_whose_name_starts_with_two_underscores(tmp_path, capsys,
                                                                            monkeypatch) -> None:
    from minros.nodes.urdfdom_py.display_urdf import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "__robot.urdf").write_text(ROBOT)
    # only `__name:=value` remappings are roslaunch's; `__robot.urdf` is the file to read
    assert main(["__robot.urdf", "__log:=/tmp/x.log"]) == 0
    assert "\nname: mobile_arm\n" in capsys.readouterr().out


def test_aggregates_keep_their_order_and_can_be_removed_or_lumped() -> None:
    robot = URDF.from_xml_string('<robot name="r"><link name="a"/><joint name="j" type="fixed">'
                                 '<parent link="a"/><child link="b"/></joint><link name="b"/>'
                                 '</robot>')
    tags = [child.tag for child in robot.to_xml()]
    assert tags == ["link", "joint", "link"]
    robot.lump_aggregates()
    assert [child.tag for child in robot.to_xml()] == ["link", "link", "joint"]
    robot.remove_aggregate(robot.links[0])
    assert [link.name for link in robot.links] == ["b"]
    assert [child.get("name") for child in robot.to_xml()] == ["b", "j"]
    with pytest.raises(ValueError, match="is not one of Robot's aggregates"):
        robot.remove_aggregate(urdf.Link(name="c"))


def test_reflect_with_a_parent_class_reads_and_writes_its_fields_first(capsys) -> None:
    class Base(xmlr.Object):
        pass

    class Derived(Base):
        pass

    xmlr.reflect(Base, tag="base", params=[xmlr.Attribute("name", str),
                                           xmlr.Element("size", float, False, default=1.0)])
    xmlr.reflect(Derived, tag="derived", parent_cls=Base, params=[
        xmlr.Attribute("color", str, False), xmlr.AggregateElement("item", str)])
    Derived.__init__ = lambda self: (self.aggregate_init(), setattr(self, "items", []))[0]
    obj = Derived.from_xml_string('<derived color="red" name="d" odd="1"><item>x</item>'
                                  '<size>2</size><size>3</size><item>y</item><what/></derived>')
    assert (obj.name, obj.color, obj.size, obj.items) == ("d", "red", 2.0, ["x", "y"])
    assert capsys.readouterr().err == (
        "Scalar element defined multiple times: size\n"
        "Unknown attribute \"odd\" in /derived[@name='d']\n"
        "Unknown tag \"what\" in /derived[@name='d']\n")
    assert obj.get_refl_vars() == ["name", "size", "color", "items"]
    assert ET.tostring(obj.to_xml()) == (b'<derived name="d" color="red"><size>2.0</size>'
                                         b'<item>x</item><item>y</item></derived>')

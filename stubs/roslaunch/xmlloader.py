"""roslaunch.xmlloader: launch XML into a ROSLaunchConfig (minros.launch.rosmodel over
minros's loader)."""

from minros.launch.rosmodel import XmlLoader, XmlParseException  # noqa: F401

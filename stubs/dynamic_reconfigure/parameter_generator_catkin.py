"""dynamic_reconfigure.parameter_generator_catkin: what ``.cfg`` scripts import
(``from dynamic_reconfigure.parameter_generator_catkin import *``); minros.dynamic_reconfigure.generator.

The star import also hands out the modules ROS's generator module imports (``sys``, ``os``, ...),
which some ``.cfg`` scripts use without importing them."""

import inspect  # noqa: F401
import os  # noqa: F401
import re  # noqa: F401
import sys  # noqa: F401
import textwrap  # noqa: F401
from string import Template  # noqa: F401

from minros.dynamic_reconfigure.generator import (  # noqa: F401
    ParameterGenerator,
    bool_t,
    check_description,
    check_name,
    double_t,
    int_t,
    str_t,
)

LINEDEBUG = "//#line"

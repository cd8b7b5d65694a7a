"""roslib.rosenv: the ROS environment (minros.rosenv)."""

from __future__ import annotations

import os
import sys
from typing import Mapping, Sequence

from minros import rosenv

ROS_ROOT = "ROS_ROOT"
ROS_MASTER_URI = "ROS_MASTER_URI"
ROS_PACKAGE_PATH = "ROS_PACKAGE_PATH"
ROS_HOME = "ROS_HOME"
ROS_IP = "ROS_IP"
ROS_HOSTNAME = "ROS_HOSTNAME"
ROS_NAMESPACE = "ROS_NAMESPACE"
ROS_LOG_DIR = "ROS_LOG_DIR"
ROS_TEST_RESULTS_DIR = "ROS_TEST_RESULTS_DIR"


class ROSEnvException(Exception):
    """A required environment variable is not set."""


def _env(env: Mapping[str, str] | None) -> Mapping[str, str]:
    return os.environ if env is None else env


def get_ros_root(required: bool = False, env: Mapping[str, str] | None = None) -> str | None:
    """ROS_ROOT (catkin-era ROS has none; minros never requires it)."""
    value = _env(env).get(ROS_ROOT)
    if required and not value:
        raise ROSEnvException(f"{ROS_ROOT} is not set")
    return value


def get_ros_package_path(required: bool = False, env: Mapping[str, str] | None = None) -> str | None:
    value = _env(env).get(ROS_PACKAGE_PATH)
    if required and not value:
        raise ROSEnvException(f"{ROS_PACKAGE_PATH} is not set")
    return value


def get_master_uri(required: bool = True, env: Mapping[str, str] | None = None,
                   argv: Sequence[str] | None = None) -> str:
    return rosenv.get_master_uri(env, rosenv.remapped_master(sys.argv if argv is None else argv))


def get_ros_home(env: Mapping[str, str] | None = None) -> str:
    return str(rosenv.ros_home(env))


def get_log_dir(env: Mapping[str, str] | None = None) -> str:
    return str(rosenv.ros_log_dir(env))


def get_test_results_dir(env: Mapping[str, str] | None = None) -> str:
    return str(rosenv.test_results_dir(env))


ROS_BINDEPS_PATH = "ROS_BINDEPS_PATH"
ROS_BOOST_ROOT = "ROS_BOOST_ROOT"

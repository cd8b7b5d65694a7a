"""roswtf.py_pip_deb_checks: ROS's Python tools installed, and how (minros.cli.wtfsource)."""

from minros.cli.wtfsource import (  # noqa: F401
    deb_install_check_on_ubuntu,
    get_host_os,
    is_a_pip_path_on_ubuntu,
    is_debian_package_installed,
    is_host_os_ubuntu,
    is_python_package_installed,
    is_python_package_installed_via_pip_on_ubuntu,
    pip_install_check_on_ubuntu,
    py_to_deb_core_packages,
    py_to_deb_optional_packages,
    py_to_deb_release_packages,
    python_module_install_check,
    python_prefix,
)
from minros.cli.wtfsource import pip_deb_errors as errors  # noqa: F401
from minros.cli.wtfsource import pip_deb_warnings as warnings  # noqa: F401
from minros.cli.wtfsource import wtf_check_pip_deb as wtf_check  # noqa: F401

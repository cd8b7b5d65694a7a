"""rosunit.core: where results go and the runner that writes them (minros.tools.junitxml)."""

from minros.tools.junitxml import (  # noqa: F401
    create_xml_runner,
    makedirs_with_parent_perms,
    printerrlog,
    printlog,
    printlog_bold,
    rostest_name_from_path,
    xml_results_file,
)
from rosunit.xmlrunner import XMLTestRunner  # noqa: E402, F401

XML_OUTPUT_FLAG = "--gtest_output=xml:"

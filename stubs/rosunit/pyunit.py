"""rosunit.pyunit: unittest cases run as a rosunit test."""

from rosunit import unitrun  # noqa: F401
from rosunit.baretest import print_unittest_summary  # noqa: E402, F401
from rosunit.core import create_xml_runner  # noqa: E402, F401

XML_OUTPUT_FLAG = "--gtest_output=xml:"

"""rosunit.junitxml: JUnit results with rosunit's classes (minros.tools.junitxml)."""

from minros.tools.junitxml import (  # noqa: F401
    Result,
    TestCaseResult,
    TestError,
    TestFailure,
    TestInfo,
    cdata,
    filter_nonprintable_text,
    invalid_char_replacer,
    print_summary,
    read,
    read_all,
    test_failure_junit_xml,
    test_success_junit_xml,
)

python2 = False

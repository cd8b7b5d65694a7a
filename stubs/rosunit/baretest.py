"""rosunit.baretest's summaries (minros.tools.junitxml)."""

from minros.tools.junitxml import print_runner_summary, print_unittest_summary  # noqa: F401

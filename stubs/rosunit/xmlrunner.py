"""rosunit.xmlrunner: a unittest runner writing JUnit XML (minros.tools.junitxml)."""

from minros.tools.junitxml import XMLTestRunner, cdata  # noqa: F401

python2 = False

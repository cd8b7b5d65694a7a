"""rostest's test nodes (``<test pkg="rostest" type="hztest">`` and its siblings): unittest
cases run as rostest runs a ``<test>``, their results where rostest asks for them."""

"""Stand-in for rostopic's Python API (minros.cli.topic: the code the command runs)."""

from minros.cli.topic import (  # noqa: F401
    ROSTopicException,
    ROSTopicHz,
    ROSTopicIOException,
    get_info_text,
    get_topic_class,
    get_topic_type,
    msgevalgen,
    rostopicmain,
)

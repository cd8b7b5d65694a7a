"""The rosbag exception hierarchy and compression names (the names rosbag.bag exports)."""

from __future__ import annotations

from minros.exceptions import DeserializationError

__all__ = ["Compression", "ROSBagDeserializationException", "ROSBagEncryptException",
           "ROSBagEncryptNotSupportedException", "ROSBagException", "ROSBagFormatException",
           "ROSBagUnindexedException"]


class ROSBagException(Exception):
    """Base class for exceptions in rosbag."""

    def __init__(self, value: str | None = None) -> None:
        super().__init__(value)
        self.value = value

    def __str__(self) -> str:
        return str(self.value)


class ROSBagFormatException(ROSBagException):
    """The bag's records do not follow the format."""


class ROSBagDeserializationException(ROSBagFormatException, DeserializationError):
    """A message in the bag does not deserialize with its class (the bag is damaged, or the
    definition is wrong). Of rosbag's family, and a genpy DeserializationError, the kind
    ROS's rosbag lets through from ``read_messages``."""


class ROSBagUnindexedException(ROSBagException):
    """The bag has no index (still being recorded, or the recorder died): run ``rosbag reindex``."""

    def __init__(self, *args: object) -> None:
        super().__init__("Unindexed bag")


class ROSBagEncryptNotSupportedException(ROSBagException):
    pass


class ROSBagEncryptException(ROSBagException):
    pass


class Compression:
    """Chunk compression names as they appear in a bag's CHUNK records."""

    NONE = "none"
    BZ2 = "bz2"
    LZ4 = "lz4"


COMPRESSIONS = (Compression.NONE, Compression.BZ2, Compression.LZ4)

"""rosbag for minros: record and play (bytes in, bytes out), the ``Bag`` API, MCAP files.

Bag format 2.0 goes through the ``rosbags`` library and MCAP through ``mcap``; see
:mod:`minros.bag.bag1` and :mod:`minros.bag.mcapfile` for the little minros adds to them.
``import rosbag`` (the stand-in package) re-exports these names.
"""

from __future__ import annotations

from minros.bag.bag import (
    Bag,
    BagMessage,
    BagMessageWithConnectionHeader,
)
from minros.bag.errors import (
    Compression,
    ROSBagEncryptException,
    ROSBagEncryptNotSupportedException,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)

__all__ = ["Bag", "BagMessage", "BagMessageWithConnectionHeader", "Compression",
           "ROSBagEncryptException", "ROSBagEncryptNotSupportedException", "ROSBagException",
           "ROSBagFormatException", "ROSBagUnindexedException"]

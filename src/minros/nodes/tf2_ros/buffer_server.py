"""buffer_server: a tf2 buffer fed by /tf and /tf_static, served on the
``tf2_buffer_server`` action (tf2_msgs/LookupTransform). Parameter ``~buffer_size``
(seconds of history, 120 by default); the node is called ``tf_buffer`` as tf2_ros's."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.tf.buffer import Buffer
from minros.tf.listener import TransformListener
from minros.tf2_buffer import BufferServer


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    if any(a in ("-h", "--help") for a in minros.myargv(argv)[1:]):
        print(__doc__)
        return 0
    minros.init_node("tf_buffer", argv=argv)
    buffer = Buffer(minros.Duration.from_sec(float(minros.get_param("~buffer_size", 120.0))))
    TransformListener(buffer)
    BufferServer(buffer, "tf2_buffer_server")
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""tf2_web_republisher: transforms for web clients (roslibjs's and roslibpy's TFClient),
thresholded and rate-limited; see minros.tf2_web_republisher."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.tf.buffer import Buffer
from minros.tf.listener import TransformListener
from minros.tf2_web_republisher import TFRepublisher


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    if any(a in ("-h", "--help") for a in minros.myargv(argv)[1:]):
        print(__doc__)
        return 0
    minros.init_node("tf2_web_republisher", argv=argv)
    buffer = Buffer()
    TransformListener(buffer)
    TFRepublisher(buffer, minros.get_name())
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())

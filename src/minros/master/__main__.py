"""``python -m minros.master [-p PORT]``: a master alone, like ``rosmaster --core``."""

import sys

from minros.master.server import main

if __name__ == "__main__":
    sys.exit(main(prog="python -m minros.master"))

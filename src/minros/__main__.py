import sys

from minros.cli.main import main

sys.exit(main())

import sys

from rftstatic.cli import main

sys.exit(main())

import sys

from drakecreep.cli import main

sys.exit(main())

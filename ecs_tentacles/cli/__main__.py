"""`python -m ecs_tentacles.cli` runs the command line."""

import sys

from ecs_tentacles.cli import main

sys.exit(main())

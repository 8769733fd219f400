"""`python -m ecs_tentacles` runs the command line (the same as `ecs-tentacles`)."""

import sys

from ecs_tentacles.cli import main

sys.exit(main())

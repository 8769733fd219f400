"""`python -m ecs_tentacles` runs the command line (the same as `ecs-tentacles`)."""

import sys

from ecs_tentacles.processes import working_folder_off_path

working_folder_off_path()  # a `numpy.py` where the user stands must not be imported

from ecs_tentacles.cli import main  # noqa: E402  (after the working folder is off the path)

sys.exit(main())

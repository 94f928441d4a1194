"""`python -m sim` is the same as the `cellsim` command."""

import sys

from sim.cli import main

sys.exit(main())

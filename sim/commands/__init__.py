"""Sub-commands of the ``cellsim`` command line, one module each (see :mod:`sim.cli`)."""

"""Old import path of :mod:`sim.robots.mjcf.builder`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.mjcf import builder

sys.modules[__name__] = builder

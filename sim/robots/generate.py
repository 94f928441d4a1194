"""Old import path of :mod:`sim.robots.mjcf.generate`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.mjcf import generate

sys.modules[__name__] = generate

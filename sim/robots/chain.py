"""Old import path of :mod:`sim.robots.kinematics.chain`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import chain

sys.modules[__name__] = chain

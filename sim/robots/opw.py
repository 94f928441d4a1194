"""Old import path of :mod:`sim.robots.kinematics.opw`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import opw

sys.modules[__name__] = opw

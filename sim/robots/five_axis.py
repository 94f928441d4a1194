"""Old import path of :mod:`sim.robots.kinematics.five_axis`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import five_axis

sys.modules[__name__] = five_axis

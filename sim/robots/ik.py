"""Old import path of :mod:`sim.robots.kinematics.ik`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import ik

sys.modules[__name__] = ik

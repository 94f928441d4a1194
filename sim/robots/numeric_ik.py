"""Old import path of :mod:`sim.robots.kinematics.numeric_ik`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import numeric_ik

sys.modules[__name__] = numeric_ik

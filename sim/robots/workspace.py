"""Old import path of :mod:`sim.robots.kinematics.workspace`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import workspace

sys.modules[__name__] = workspace

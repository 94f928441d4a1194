"""Old import path of :mod:`sim.robots.kinematics.mujoco_fk`, kept for the callers outside
:mod:`sim.robots`: this name is that very module (new code imports it from its package)."""

import sys

from sim.robots.kinematics import mujoco_fk

sys.modules[__name__] = mujoco_fk

"""Kinematic families, one module each: :class:`FiveR` (seed 000) and :class:`Fanuc6`
(seed 004), both implementing :class:`KinematicFamily`."""

from sim.robots.families.base import KinematicFamily
from sim.robots.families.fanuc6 import Fanuc6
from sim.robots.families.five_r import FiveR

__all__ = ["Fanuc6", "FiveR", "KinematicFamily"]

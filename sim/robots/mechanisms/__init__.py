"""Mechanisms: turntables, tilt-rotate positioners and linear tracks, a cell's external axes
(layer ``robots``: imports ``sim.core``, ``sim.errors`` and ``sim.robots.drive`` only).

* :mod:`~sim.robots.mechanisms.spec`: what a mechanism is (:class:`MechanismSpec`).
"""

from sim.robots.mechanisms.spec import MECHANISM_KINDS, AxisSpec, LinkSpec, MechanismSpec, Shape

__all__ = ["MECHANISM_KINDS", "AxisSpec", "LinkSpec", "MechanismSpec", "Shape"]

"""Mechanisms: turntables, tilt-rotate positioners and linear tracks, a cell's external axes
(layer ``robots``: imports ``sim.core``, ``sim.errors``, ``sim.robots.drive`` and
``sim.robots.schema`` only).

* :mod:`~sim.robots.mechanisms.spec`: what a mechanism is (:class:`MechanismSpec`).
* :mod:`~sim.robots.mechanisms.schema`: the mechanism file's keys and their ranges.
* :mod:`~sim.robots.mechanisms.mechfile`: reading a file, :func:`read_mechanism`.
* :mod:`~sim.robots.mechanisms.registry`: the shipped ones, :data:`MECHANISMS`, and
  :func:`mechanism_from_ref`.
"""

from sim.robots.mechanisms.mechfile import read_mechanism
from sim.robots.mechanisms.registry import MECHANISMS, mechanism_from_ref
from sim.robots.mechanisms.spec import MECHANISM_KINDS, AxisSpec, LinkSpec, MechanismSpec, Shape

__all__ = ["MECHANISMS", "MECHANISM_KINDS", "AxisSpec", "LinkSpec", "MechanismSpec", "Shape",
           "mechanism_from_ref", "read_mechanism"]

"""Base layer: where the shipped data lives, rotation/transform helpers, index intervals.

Owns: :mod:`~sim.core.resources` (models/ and scenarios/ folders), :mod:`~sim.core.rotations`
(rotation matrices, Euler angles, homogeneous transforms), :mod:`~sim.core.intervals` (runs
of True in a boolean series). May import: planners and
:mod:`sim.errors` only.
"""

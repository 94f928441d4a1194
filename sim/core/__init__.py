"""Base layer: where the shipped data lives and the rotation/transform helpers.

Owns: :mod:`~sim.core.resources` (models/ and scenarios/ folders), :mod:`~sim.core.rotations`
(rotation matrices, Euler angles, homogeneous transforms). May import: planners and
:mod:`sim.errors` only.
"""

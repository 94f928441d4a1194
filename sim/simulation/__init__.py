"""Simulation layer: the reference motion, the compiled cell, the simulation, its metrics and
the run folder.

Owns: :mod:`~sim.simulation.motion` (every phase planned on one clock),
:mod:`~sim.simulation.compile` (the cell compiled once, ids resolved once),
:mod:`~sim.simulation.simulate` (position servos with feed-forward, recording),
:mod:`~sim.simulation.metrics` (tracking, seams, parts, singularities, the summary),
:mod:`~sim.simulation.runfolder` (the run folder's schema: file and array names, units).
May import: planners, :mod:`sim.errors`, :mod:`sim.core`, :mod:`sim.robots`, :mod:`sim.cells`,
:mod:`sim.scenario`.
"""

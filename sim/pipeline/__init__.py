"""Pipeline layer: what a command does end to end.

Owns: :mod:`~sim.pipeline.run` (``run_scenario``: compile, plan, simulate, write the run
folder, plots, video and sizing report), :mod:`~sim.pipeline.sweep` (payload x speed sweeps).
May import every lower layer: planners, core, robots, cells, scenario, simulation, analysis,
render.
"""

"""Analysis layer: actuator sizing, the run's checks and verdict, the report and the plots.

Owns: :mod:`~sim.analysis.sizing` (torque/speed/power statistics, drive trains, margins, the
sizing checks), :mod:`~sim.analysis.verdict` (the run's checks and verdict),
:mod:`~sim.analysis.report` (sizing.md/.csv/.json, report.html, charts),
:mod:`~sim.analysis.plots` (joint, tool-path, tracking and torque plots). Everything takes a
:class:`sim.simulation.runfolder.RunRecord` (in memory, or read through the run-folder module).
May import: planners and every layer up to :mod:`sim.simulation`.
"""

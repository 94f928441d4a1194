"""Analysis layer: actuator sizing, its checks and verdict, the report and the run's plots.

Owns: :mod:`~sim.analysis.sizing` (torque/speed/power statistics, drive trains, margins,
verdict), :mod:`~sim.analysis.report` (sizing.md/.csv/.json, report.html, charts),
:mod:`~sim.analysis.plots` (joint, tool-path, tracking and torque plots). Everything takes a
:class:`sim.simulation.runfolder.RunRecord` (in memory, or read through the run-folder module).
May import: planners and every layer up to :mod:`sim.simulation`.
"""

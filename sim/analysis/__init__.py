"""Analysis layer: actuator sizing, the run's checks and verdict, the report and the plots.

Owns: :mod:`~sim.analysis.statistics` (time-weighted integrals, RMS, peaks, sustained signals,
margins), :mod:`~sim.analysis.sizing` (drive trains, the sizing checks of a run; its result types
and verdict in :mod:`~sim.analysis.sizing_result`, the model's limits in
:mod:`~sim.analysis.model_limits`), :mod:`~sim.analysis.verdict` (the run's checks and verdict),
:mod:`~sim.analysis.catalog` and :mod:`~sim.analysis.selection` (actuator selection),
:mod:`~sim.analysis.report` (sizing.md/.csv/.json, report.html; charts in
:mod:`~sim.analysis.sizing_charts`), :mod:`~sim.analysis.plots` (joint, tool-path, tracking and
torque plots). Everything takes a :class:`sim.simulation.runfolder.RunRecord` (in memory, or
read through the run-folder package).
May import: planners and every layer up to :mod:`sim.simulation`.
"""

"""API layer: what scripts import as ``sim.<name>`` (``sim.evaluate``, ``sim.RunResult``, ...).

Owns: :mod:`~sim.api.runs` (:func:`evaluate`, :func:`run`, :func:`sweep`) and
:mod:`~sim.api.results` (:class:`RunResult` and the typed records it holds). May import every
lower layer: planners, core, robots, cells, scenario, simulation, analysis, render, pipeline.
The package root ``sim`` exports these names lazily (``import sim`` loads none of them).
"""

from sim.api.results import (
    Check,
    Collision,
    MechanismAxis,
    MechanismResult,
    RobotResult,
    RunResult,
    Saturation,
    SelectedDrive,
    SizedJoint,
    SizingCheck,
    WeldResult,
)
from sim.api.runs import evaluate, run, sweep
from sim.pipeline.run import RunOptions
from sim.pipeline.sweep import SweepResult
from sim.scenario import Scenario, load_scenario

__all__ = [
    "Check", "Collision", "MechanismAxis", "MechanismResult", "RobotResult", "RunOptions",
    "RunResult", "Saturation", "Scenario", "SelectedDrive", "SizedJoint", "SizingCheck",
    "SweepResult", "WeldResult", "evaluate", "load_scenario", "run", "sweep",
]

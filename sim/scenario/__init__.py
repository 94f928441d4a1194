"""Scenario layer: the scenario file's declared schema, its units, and loading.

Owns: :mod:`~sim.scenario.loader` (TOML -> validated :class:`Scenario` whose robot, tool and
cell are resolved into spec objects once). May import: planners, :mod:`sim.errors`,
:mod:`sim.core`, :mod:`sim.robots`, :mod:`sim.cells`.
"""

from sim.scenario.loader import (
    Action,
    ActionSpec,
    CartesianPhase,
    CircularPhaseSpec,
    DriveOverrideSpec,
    HoldPhase,
    HoldPhaseSpec,
    JointPhase,
    JointPhaseSpec,
    LinearPhaseSpec,
    Phase,
    PlannedPhase,
    PoseTarget,
    Scenario,
    ScenarioSpec,
    SimulationSpec,
    VideoSpec,
    load_scenario,
    parse_scenario,
    plan_phase,
    plan_scenario,
    resolve_scenario,
)

__all__ = [
    "Action", "ActionSpec", "CartesianPhase", "CircularPhaseSpec", "DriveOverrideSpec",
    "HoldPhase", "HoldPhaseSpec", "JointPhase", "JointPhaseSpec", "LinearPhaseSpec", "Phase",
    "PlannedPhase", "PoseTarget", "Scenario", "ScenarioSpec", "SimulationSpec", "VideoSpec",
    "load_scenario", "parse_scenario", "plan_phase", "plan_scenario", "resolve_scenario",
]

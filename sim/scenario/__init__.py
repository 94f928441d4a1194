"""Scenario layer: the scenario file's schema (keys, types, units), the validated scenario,
and loading.

Owns: :mod:`~sim.scenario.schema` (the declared keys, pydantic), :mod:`~sim.scenario.model`
(:class:`Scenario` in SI units, with its robot, cell and tool resolved into spec objects
once), :mod:`~sim.scenario.loader` (TOML -> :class:`Scenario`, one-line errors naming the file
and key), :mod:`~sim.scenario.phases` (the phases built from their entries, in SI units),
:mod:`~sim.scenario.planning` (planning of joint phases), :mod:`~sim.scenario.fanuc_ls`,
:mod:`~sim.scenario.fanuc_pos` (its positions: motion groups, extended axes) and
:mod:`~sim.scenario.program` (FANUC TP programs as phases). May import: planners,
:mod:`sim.errors`, :mod:`sim.core`, :mod:`sim.robots`, :mod:`sim.cells`.
"""

from sim.scenario.loader import load_scenario, parse_scenario, resolve_scenario
from sim.scenario.model import (
    Action,
    CartesianPhase,
    HoldPhase,
    JointPhase,
    Phase,
    PoseTarget,
    RobotWork,
    Scenario,
)
from sim.scenario.planning import PlannedPhase, plan_phase, plan_scenario
from sim.scenario.schema import (
    ActionSpec,
    CircularPhaseSpec,
    DriveOverrideSpec,
    ExpectSpec,
    HoldPhaseSpec,
    JointPhaseSpec,
    LinearPhaseSpec,
    ScenarioSpec,
    SimulationSpec,
    SizingSpec,
    VideoSpec,
    WeaveSpec,
)

__all__ = [
    "Action", "ActionSpec", "CartesianPhase", "CircularPhaseSpec", "DriveOverrideSpec",
    "ExpectSpec", "HoldPhase", "HoldPhaseSpec", "JointPhase", "JointPhaseSpec", "LinearPhaseSpec",
    "Phase", "PlannedPhase", "PoseTarget", "RobotWork", "Scenario", "ScenarioSpec",
    "SimulationSpec", "SizingSpec", "VideoSpec", "WeaveSpec", "load_scenario", "parse_scenario",
    "plan_phase", "plan_scenario", "resolve_scenario",
]

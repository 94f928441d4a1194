"""Planning a scenario's joint phases with their planners (:mod:`planners`): one trajectory
per phase, a planner's refusal as one line naming the phase."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from planners.errors import PlannerError
from planners.registry import get_planner
from sim.errors import ScenarioError
from sim.scenario.model import JointPhase, Scenario, phase_label


@dataclass(frozen=True)
class PlannedPhase:
    """A phase with its trajectory."""

    phase: JointPhase
    trajectory: Any  # planners.trajectory.PiecewisePolynomialTrajectory


def plan_phase(phase: JointPhase, where: str = "") -> Any:
    """Plan one joint phase with its planner.

    Raises:
        ScenarioError: The planner rejected the phase (message prefixed with ``where``).
    """
    try:
        return get_planner(phase.planner)(phase.times, phase.q, **phase.boundary)
    except PlannerError as exc:
        label = phase_label(where, phase) if where else phase_label("", phase)[2:]
        raise ScenarioError(f"{label}: {exc}") from None


def plan_scenario(scenario: Scenario) -> list[PlannedPhase]:
    """Plan every phase of a scenario, in order."""
    where = scenario.source.name
    return [PlannedPhase(p, plan_phase(p, where)) for p in scenario.phases]


__all__ = ["PlannedPhase", "plan_phase", "plan_scenario"]

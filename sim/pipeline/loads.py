"""The masses a run's checks weigh at the tool: what the tool holds against its rating, and the
part a gripper adds at the robot's flange (:mod:`sim.analysis.verdict`'s ``tool_payload`` and
``payload``), read from the compiled model (a BuiltCell). May import: nothing of cellsim.
"""

from __future__ import annotations

from typing import Any


def tool_load(built: Any, payload_kg: float) -> tuple[str, float, float] | None:
    """The tool's name, the mass it holds (the payload and the heaviest part of the cell,
    from the compiled model) and its rating, kg; None for a tool without a rating."""
    tool = built.cell.tool
    if tool is None or tool.max_payload_kg is None:
        return None
    return tool.name, float(payload_kg) + _parts_kg(built), float(tool.max_payload_kg)


def _parts_kg(built: Any) -> float:
    """The heaviest part of the cell (the compiled model's mass), kg; 0 without parts."""
    model = built.model
    return max((float(model.body(name).mass[0]) for name in built.cell.parts
                if _has_body(model, name)), default=0.0)


def heaviest_part_kg(built: Any) -> float:
    """What a gripper adds at the flange while it carries a part: the heaviest part, kg (0 for
    a torch or no tool)."""
    tool = built.cell.tool
    return _parts_kg(built) if tool is not None and tool.kind == "gripper" else 0.0


def _has_body(model: Any, name: str) -> bool:
    try:
        model.body(name)
    except KeyError:
        return False
    return True


__all__ = ["heaviest_part_kg", "tool_load"]

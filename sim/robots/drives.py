"""The drive each joint really has: the robot's default drive trains with a scenario's
``[drives.jN]`` overrides applied (docs/scenario-format.md).

One place decides it, and everything uses its result: the compiled model's actuator
``forcerange`` (peak motor torque x ratio x efficiency at the joint) and joint ``armature``
(the rotor's reflected inertia, ``J_r N^2``), the simulation's torque-speed limit, sizing and
the report (:attr:`sim.scenario.model.Scenario.drive_train`). The physics of a drive (its
torque-speed curve, the motor torque of a joint torque) is :mod:`sim.robots.drive`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

from sim.core.tomlschema import (
    EFFICIENCY,
    GEAR_RATIO,
    ROTOR_INERTIA_KG_M2,
    SPEED_RPM,
    TORQUE_NM,
)
from sim.errors import CellsimError, ScenarioError, UnknownNameError
from sim.robots.drive import Drive

_DRIVE_FIELDS = tuple(f.name for f in dataclasses.fields(Drive))

#: Key names of a scenario's ``[drives.jN]`` table (docs/scenario-format.md) -> Drive fields.
#: The bare Drive field names are accepted too.
DRIVE_KEYS = {
    "gear_ratio": "gear_ratio",
    "efficiency": "efficiency",
    "rotor_inertia_kg_m2": "rotor_inertia",
    "rated_torque_nm": "rated_torque",
    "peak_torque_nm": "peak_torque",
    "max_speed_rpm": "max_speed_rpm",
}
_KEY_OF_FIELD = {v: k for k, v in DRIVE_KEYS.items()}


#: The range of each drive field (the robot file's and the mechanism file's: a gear ratio of
#: 1e308 is a typo, and would only fail later, in the model's armature or force range).
_QUANTITY = {"gear_ratio": GEAR_RATIO, "efficiency": EFFICIENCY,
             "rotor_inertia": ROTOR_INERTIA_KG_M2, "rated_torque": TORQUE_NM,
             "peak_torque": TORQUE_NM, "max_speed_rpm": SPEED_RPM}


def _check_drive(d: Drive, where: str) -> None:
    k = _KEY_OF_FIELD
    for name in _DRIVE_FIELDS:
        _QUANTITY[name].read(getattr(d, name), f"{where}.{k[name]}", ScenarioError)
    if d.peak_torque < d.rated_torque:
        raise ScenarioError(f"{where}.peak_torque_nm: {d.peak_torque!r} N m is below "
                            f"rated_torque_nm {d.rated_torque!r} N m")


def apply_overrides(drives: Sequence[Drive], overrides: Mapping[str, Any] | None,
                    joint_names: Sequence[str]) -> tuple[Drive, ...]:
    """Drives with a scenario's ``[drives.jN]`` tables applied.

    Args:
        drives: Default drive per joint (``RobotSpec.drives``), same order as ``joint_names``.
            May be empty when the robot has no drive data; then every joint named in
            ``overrides`` must give all fields.
        overrides: ``{"j2": {"gear_ratio": 120, "rated_torque_nm": 1.3}, ...}`` (the parsed
            ``[drives]`` table, keys as in docs/scenario-format.md: :data:`DRIVE_KEYS`; the bare
            :class:`Drive` field names are accepted too); None or empty leaves the defaults.
        joint_names: The robot's joint names.

    Returns:
        One :class:`Drive` per joint (``len(joint_names)``), or ``()`` when there are neither
        defaults nor overrides.

    Raises:
        UnknownNameError: An unknown joint or field name (lists the valid ones).
        ScenarioError: A bad value (non-number, efficiency outside (0, 1], ...) or a missing
            field when there is no default to complete it.
    """
    names = tuple(joint_names)
    base: list[Drive | None] = list(drives) if drives else [None] * len(names)
    if len(base) != len(names):
        raise CellsimError(f"{len(base)} drives for {len(names)} joints ({', '.join(names)})")
    overrides = overrides or {}
    if not isinstance(overrides, Mapping):
        raise ScenarioError(f"drives: must be a table of joint tables, got {type(overrides).__name__}")
    for joint, table in overrides.items():
        if joint not in names:
            raise UnknownNameError("joint in [drives]", str(joint), names)
        where = f"drives.{joint}"
        if not isinstance(table, Mapping):
            raise ScenarioError(f"{where}: must be a table of drive keys "
                                f"({', '.join(DRIVE_KEYS)}), got {table!r}")
        values: dict[str, float] = {}
        for key, value in table.items():
            fname = DRIVE_KEYS.get(key, key if key in _DRIVE_FIELDS else None)
            if fname is None:
                raise UnknownNameError(f"key in [{where}]", str(key), DRIVE_KEYS)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ScenarioError(f"{where}.{key}: must be a number, got {value!r}")
            values[fname] = float(value)
        i = names.index(joint)
        if base[i] is None:
            missing = [_KEY_OF_FIELD[f] for f in _DRIVE_FIELDS if f not in values]
            if missing:
                raise ScenarioError(f"{where}: the robot has no default drive, give "
                                    f"{', '.join(missing)} too")
            base[i] = Drive(**values)
        else:
            base[i] = dataclasses.replace(base[i], **values)
        _check_drive(base[i], where)
    if all(d is None for d in base):
        return ()
    if any(d is None for d in base):
        missing = [n for n, d in zip(names, base) if d is None]
        raise ScenarioError(f"drives: no drive data for {', '.join(missing)}; give a full "
                            f"[drives.{missing[0]}] table ({', '.join(DRIVE_KEYS)})")
    return tuple(base)  # type: ignore[arg-type]




__all__ = ["DRIVE_KEYS", "apply_overrides"]

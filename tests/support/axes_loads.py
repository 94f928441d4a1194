"""Generated loads on a MotoPos D500 (issue 28's second acceptance test): workpieces of steel
on its faceplate, moves of its axes, and the torques the Newton-Euler oracle of
:mod:`support.mechanism_oracle` gives for them from the mechanism file's own numbers and the
workpieces' shapes (:class:`support.axes_cells.Solid`; the compiled model's inertias are not
used).

:func:`loads` draws a plate and a box or cylinder workpiece (up to ~200 kg) 40-120 mm off the
faceplate's centre in x and y (its centre of mass off the tilt and the rotate axes: gravity
loads both) and turned about every axis, the positioner's placement (position and Z-Y-X
angles; ``tilted`` also turns its base about x and y, a positioner on a slope or a wall) and two
moves of the axes. :func:`axes_scenario` writes the cell and a scenario of joint phases that
hold the robot at home and move the axes.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from support.axes_cells import (
    D500_FILE,
    HOME_DEG,
    Solid,
    combined,
    mechanism_file,
    pose,
    positioner_cell,
)
from support.mechanism_oracle import OracleAxis, OraclePayload, inverse_dynamics
from support.scenarios import joint_phase, scenario_text
from support.seam_oracle import rot_zyx

D500 = mechanism_file(D500_FILE)
#: Each move of the axes, s.
MOVE_S = 4.0


def oracle_chain(mech: dict[str, Any]) -> list[OracleAxis]:
    """The oracle's chain from a mechanism file's own numbers (mm -> m; armature = the drive's
    rotor inertia times its ratio squared; damping; Coulomb friction)."""
    out = []
    for ax in mech["axes"]:
        d, link = ax["drive"], ax["link"]
        out.append(OracleAxis(ax["kind"], np.asarray(ax.get("pos_mm", (0, 0, 0))) * 1e-3,
                              ax["axis"], link["mass_kg"], np.asarray(link["com_mm"]) * 1e-3,
                              link["inertia_kg_m2"],
                              armature=d["rotor_inertia_kg_m2"] * d["gear_ratio"] ** 2,
                              damping=ax.get("damping", 0.0),
                              friction=ax.get("friction_nm", ax.get("friction_n", 0.0))))
    return out


def positioner_torques(arrays: Any, solids: Sequence[Solid], euler_zyx_deg: Sequence[float],
                       scale_mass: float = 1.0, columns: slice = slice(6, 8)) -> np.ndarray:
    """The oracle's tilt and rotate torques along the recorded reference (``q_ref``,
    ``qd_ref``, ``qdd_ref``), gravity turned into the positioner's base frame; every solid's
    mass times ``scale_mass`` (a planted fault)."""
    m, c, inertia = combined(solids, scale_mass)
    mount = D500["mount"]
    gravity = rot_zyx(tuple(euler_zyx_deg)).T @ np.array([0.0, 0.0, -9.81])
    return inverse_dynamics(oracle_chain(D500), arrays["q_ref"][:, columns],
                            arrays["qd_ref"][:, columns], arrays["qdd_ref"][:, columns],
                            mount=pose(mount["pos_mm"], mount["euler_zyx_deg"]),
                            payload=OraclePayload(m, c, inertia), gravity=gravity)


@st.composite
def loads(draw: Any, tilted: bool = False
          ) -> tuple[list[Solid], tuple[float, ...], tuple[float, float, float],
                     list[tuple[float, float]]]:
    """``(solids, pos_mm, euler_zyx_deg, targets)`` (module docstring): the moves tilt
    30-120 deg and rotate 45-180 deg either way, then on by up to 90 and 150 deg (within the
    axes' ranges)."""
    fl = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))  # noqa: E731
    sign = lambda: draw(st.sampled_from((-1.0, 1.0)))  # noqa: E731
    plate = Solid("box", (fl(-30, 30), fl(-30, 30), 10.0), (fl(-180, 180), 0.0, 0.0),
                  size_mm=(fl(200, 400), fl(200, 400), 20.0))
    centre = (sign() * fl(40, 120), sign() * fl(40, 120), fl(80, 220))
    turn = (fl(-180, 180), fl(-60, 60), fl(-60, 60))
    if draw(st.booleans()):
        work = Solid("cylinder", centre, turn, radius_mm=fl(60, 150), length_mm=fl(80, 300))
    else:
        work = Solid("box", centre, turn, size_mm=(fl(80, 300), fl(80, 300), fl(80, 300)))
    first = (sign() * fl(30, 120), sign() * fl(45, 180))
    second = (first[0] - sign() * fl(30, 90), first[1] - sign() * fl(45, 150))
    second = (float(np.clip(second[0], -130, 130)), float(np.clip(second[1], -195, 195)))
    euler = (fl(-180, 180), fl(-90, 90) if tilted else 0.0, fl(-90, 90) if tilted else 0.0)
    return [plate, work], (fl(500, 900), fl(-300, 300), 0.0), euler, [first, second]


def axes_scenario(folder: Path, solids: Sequence[Solid], pos_mm: Sequence[float],
                  euler_zyx_deg: Sequence[float], targets: Sequence[tuple[float, float]]
                  ) -> Path:
    """The cell (the solids on the positioner, named ``w0``, ``w1``, ...) and a scenario that
    moves the axes to each target (tilt, rotate; deg) in :data:`MOVE_S`, the robot at home."""
    objects = [dict(name=f"w{k}", role="workpiece", on="positioner", **s.fields())
               for k, s in enumerate(solids)]
    (folder / "cell.toml").write_text(positioner_cell(pos_mm, euler_zyx_deg, objects))
    H = list(HOME_DEG)
    phases = []
    for k, (tilt, rot) in enumerate(targets):
        axes = {"positioner_tilt_deg": tilt, "positioner_rotate_deg": rot}
        phases.append(joint_phase([H, H], name=f"move{k}", time_s=[0.0, MOVE_S], axes=axes)
                      if k == 0 else joint_phase([H], name=f"move{k}", durations_s=[MOVE_S],
                                                 axes=axes))
    path = folder / "axes.toml"
    path.write_text(scenario_text("lrmate200ic5l", phases, cell="cell.toml", tool="mig_torch"))
    return path


__all__ = ["D500", "MOVE_S", "axes_scenario", "loads", "oracle_chain", "positioner_torques"]

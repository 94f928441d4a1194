"""Two robots in one cell, for the collision tests (issue 28): the cell and scenario files of
two LR Mate 200iC/5L with MIG torches facing each other (:func:`write_pair`), and an oracle
of the distance between the two robots computed from a run's recorded ``qpos`` without
cellsim's collision code (:func:`pair_distances`).

The oracle selects the geoms itself (a robot's collision geoms, group 3, and every geom of its
tool, by the prefixes ``robot/`` and ``r2/``), poses them from ``qpos`` with
``mj_kinematics`` and measures every pair of the two robots with ``mj_geomDistance`` (GJK on
the geoms' own shapes) where the geoms' bounding spheres come closer than the range; its own
geometry gives a lower bound (the bounding spheres: ``|c_a - c_b| - r_a - r_b``) and the tool
points' distance (the wire tips: two wires whose tips meet overlap).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from support.scenarios import joint_phase, scenario_text

#: The robots' home (torch pointing down in front of each).
HOME_DEG = (0.0, 0.0, 0.0, 0.0, -90.0, 0.0)
#: The oracle measures up to this distance, m (cellsim's clearance range).
RANGE_M = 0.1


@dataclass(frozen=True)
class Pair:
    """Two robots facing each other along x, ``distance_mm`` apart, each turned by its yaw
    off facing the other (deg), their tool tips commanded to ``point_mm`` (world) at
    ``t_cross_s``, ``sep_mm`` apart along x (each on its own side): 0 is a planted crossing."""

    distance_mm: float
    yaw1_deg: float
    yaw2_deg: float
    point_mm: tuple[float, float, float]
    sep_mm: float
    reach_s: float = 1.0

    @property
    def t_cross_s(self) -> float:
        return 0.5 + self.reach_s


def cell_text(pair: Pair) -> str:
    return f'''name = "duo"
description = "two robots facing each other"
tool = "mig_torch"

[robot]
model = "lrmate200ic5l"
base_pos_mm = [{-pair.distance_mm / 2!r}, 0.0, 0.0]
base_euler_zyx_deg = [{pair.yaw1_deg!r}, 0.0, 0.0]

[[robots]]
name = "r2"
model = "lrmate200ic5l"
tool = "mig_torch"
base_pos_mm = [{pair.distance_mm / 2!r}, 0.0, 0.0]
base_euler_zyx_deg = [{180.0 + pair.yaw2_deg!r}, 0.0, 0.0]
'''


def _scenario(q1: Any, q2: Any, reach_s: float, clearance_mm: float | None = None) -> str:
    def phases(q: Any) -> list[dict[str, Any]]:
        out = [joint_phase([HOME_DEG, HOME_DEG], name="start", time_s=[0.0, 0.5])]
        if q is not None:
            out.append(joint_phase([[float(v) for v in q], HOME_DEG], name="cross",
                                   durations_s=[reach_s, reach_s]))
        return out

    extra: dict[str, Any] = ({} if clearance_mm is None
                             else {"simulation": {"clearance_mm": clearance_mm}})
    return scenario_text("lrmate200ic5l", phases(q1), name="duo", cell="cell.toml",
                         tool="mig_torch", **extra, robots={"r2": {"phases": phases(q2)}})


def write_pair(folder: Path, pair: Pair, clearance_mm: float | None = None) -> Path:
    """The cell and the scenario of ``pair`` in ``folder`` (``simulation.clearance_mm``, when
    given); returns the scenario's path.

    Each robot's joints at the crossing come from its own inverse kinematics (the torch
    pointing down, its x axis along the robot's facing direction), its tip at ``point_mm``
    moved by ``sep_mm / 2`` along x towards its own base; each robot goes there from home in
    ``reach_s`` and back.
    """
    from sim.robots.kinematics.ik import solve_ik
    from sim.scenario import load_scenario
    from sim.simulation.compile import build

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "cell.toml").write_text(cell_text(pair))
    path = folder / "s.toml"
    path.write_text(_scenario(None, None, pair.reach_s))
    built = build(load_scenario(path))
    p = np.array(pair.point_mm) * 1e-3
    off = np.array([pair.sep_mm / 2, 0.0, 0.0]) * 1e-3
    qs = []
    for ctx, tip, yaw in ((built.context, p - off, pair.yaw1_deg),
                          (built.context.partners["r2"], p + off, 180.0 + pair.yaw2_deg)):
        a = np.radians(yaw)
        T = np.eye(4)
        T[:3, :3] = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0],
                              [0.0, 0.0, 1.0]]) @ np.diag([1.0, -1.0, -1.0])
        T[:3, 3] = tip
        sols = [s for s in solve_ik(ctx.kinematics, np.linalg.inv(ctx.world_from_frame0) @ T,
                                    current=np.radians(HOME_DEG)) if s.within_limits]
        qs.append(np.degrees(sols[0].q))
    path.write_text(_scenario(qs[0], qs[1], pair.reach_s, clearance_mm))
    return path


def robot_geoms(model: Any, prefix: str) -> NDArray[np.int64]:
    """A robot's geoms as the oracle selects them: its links' collision geoms (group 3) and
    every geom of its tool (body or geom named ``<prefix>/tool/...``)."""
    out = []
    for g in range(model.ngeom):
        body = model.body(int(model.geom_bodyid[g])).name
        name = model.geom(g).name
        if body.startswith(f"{prefix}/tool/") or name.startswith(f"{prefix}/tool/"):
            out.append(g)
        elif body.startswith(f"{prefix}/") and model.geom_group[g] == 3:
            out.append(g)
    return np.array(out, int)


def tool_geoms(model: Any, prefix: str) -> NDArray[np.int64]:
    return np.array([g for g in robot_geoms(model, prefix)
                     if model.body(int(model.geom_bodyid[g])).name.startswith(f"{prefix}/tool/")],
                    int)


@dataclass
class PairDistances:
    """The oracle's distances along a run, m, (N,) each (``RANGE_M`` where farther).

    Attributes:
        robots: Between any geom of one robot and any of the other.
        tools: Between the two tools.
        bound: The bounding spheres' lower bound of :attr:`robots`.
        tips: Between the two tool points (tcp sites).
    """

    robots: NDArray[np.float64]
    tools: NDArray[np.float64]
    bound: NDArray[np.float64]
    tips: NDArray[np.float64]


def pair_distances(model: Any, qpos: NDArray[np.float64], a: str = "robot", b: str = "r2",
                   drop: frozenset[int] = frozenset()) -> PairDistances:
    """The oracle at every row of ``qpos`` (module docstring); ``drop``: geoms left out."""
    import mujoco

    ga = np.array([g for g in robot_geoms(model, a) if g not in drop], int)
    gb = np.array([g for g in robot_geoms(model, b) if g not in drop], int)
    ta, tb = set(tool_geoms(model, a).tolist()), set(tool_geoms(model, b).tolist())
    sa, sb = model.site(f"{a}/tcp").id, model.site(f"{b}/tcp").id
    d = mujoco.MjData(model)
    n = qpos.shape[0]
    out = PairDistances(np.full(n, RANGE_M), np.full(n, RANGE_M), np.full(n, RANGE_M),
                        np.zeros(n))
    fromto = np.zeros(6)
    ra, rb = model.geom_rbound[ga], model.geom_rbound[gb]
    for i in range(n):
        d.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, d)
        out.tips[i] = float(np.linalg.norm(d.site_xpos[sa] - d.site_xpos[sb]))
        gap = (np.linalg.norm(d.geom_xpos[ga][:, None] - d.geom_xpos[gb][None], axis=2)
               - ra[:, None] - rb[None])
        out.bound[i] = min(RANGE_M, float(gap.min()))
        for ia, ib in zip(*np.nonzero(gap < RANGE_M), strict=True):
            x, y = int(ga[ia]), int(gb[ib])
            dist = float(mujoco.mj_geomDistance(model, d, x, y, RANGE_M, fromto))
            out.robots[i] = min(out.robots[i], dist)
            if x in ta and y in tb:
                out.tools[i] = min(out.tools[i], dist)
    return out

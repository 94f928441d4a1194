"""Two-robot tee cells generated from seeded numbers, and an oracle independent of cellsim's
kinematics: the LR Mate 200iC/5L's forward kinematics as the product of its MJCF's link
offsets and joint rotations (models/fanuc_lrmate200ic/lrmate200ic5l.xml), the flange site and
the MIG torch's 145 mm tool point (models/tools/mig_torch.toml) typed in here.

Each cell: a table, a flange plate and a web (a tee) of length ``L`` centred at ``xc``; the
first robot on the -y side (yaw 90 deg) welds seam ``left`` (y = -5 mm), the second, ``r2``,
on the +y side (yaw -90 deg) welds seam ``right`` (y = +5 mm) the other way; both seams at
z = 462 mm, the flange's top.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

#: The LR Mate 200iC/5L's links (MJCF body offsets, m) and joint axes, base to link 6.
CHAIN = (((0.0, 0.0, 0.33), (0, 0, 1)), ((0.075, 0.0, 0.0), (0, -1, 0)),
         ((0.0, 0.0, 0.4), (0, -1, 0)), ((0.0, 0.0, 0.075), (1, 0, 0)),
         ((0.41, 0.0, 0.0), (0, -1, 0)), ((0.0, 0.0, 0.0), (1, 0, 0)))
#: The flange site in link 6 (pos, quat w x y z) and the torch's tool point on the flange, m.
FLANGE = ((0.08, 0.0, 0.0), (0.0, 0.707106781, 0.0, 0.707106781))
TORCH_TCP = (0.0, 0.0, 0.145)
#: The seams' height: the flange plate's top (456 + 6 mm), m.
SEAM_Z = 0.462


def _T(R: NDArray[np.float64] | None = None, p: tuple[float, ...] = (0, 0, 0)
       ) -> NDArray[np.float64]:
    M = np.eye(4)
    if R is not None:
        M[:3, :3] = R
    M[:3, 3] = p
    return M


def base_pose(pos_mm: tuple[float, float, float], yaw_deg: float) -> NDArray[np.float64]:
    """A floor robot's base in world from a cell file's numbers (a yaw only), (4, 4)."""
    return _T(Rotation.from_euler("z", yaw_deg, degrees=True).as_matrix(),
              tuple(np.asarray(pos_mm, float) * 1e-3))


def tool_points(base: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The torch's tool point in world at joint rows ``q`` (N, 6), m."""
    out = np.empty((len(q), 3))
    fl = _T(Rotation.from_quat(FLANGE[1], scalar_first=True).as_matrix(), FLANGE[0])
    tcp = _T(p=TORCH_TCP)
    for i, row in enumerate(q):
        M = base.copy()
        for (p, axis), qi in zip(CHAIN, row, strict=True):
            M = M @ _T(p=p) @ _T(Rotation.from_rotvec(np.asarray(axis, float) * qi).as_matrix())
        out[i] = (M @ fl @ tcp)[:3, 3]
    return out


def line_distance(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distances of points ``p`` from the line ``a``-``b`` and their progress along it from
    ``a``, m."""
    u = (b - a) / np.linalg.norm(b - a)
    r = p - a
    s = r @ u
    return np.linalg.norm(r - np.outer(s, u), axis=1), s


@dataclass(frozen=True)
class TwoCell:
    """A generated cell's numbers (mm, mm/s, deg)."""

    r1_pos: tuple[float, float, float]
    r2_pos: tuple[float, float, float]
    length: float
    xc: float
    speed1: float
    speed2: float
    start2_s: float

    @property
    def r2_base(self) -> NDArray[np.float64]:
        return base_pose(self.r2_pos, -90.0)

    @property
    def r1_base(self) -> NDArray[np.float64]:
        return base_pose(self.r1_pos, 90.0)

    @property
    def right(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Seam ``right`` (r2's): from +x to -x at y = +5 mm, world, m."""
        h = self.length / 2
        return (np.array([self.xc + h, 5.0, SEAM_Z * 1e3]) * 1e-3,
                np.array([self.xc - h, 5.0, SEAM_Z * 1e3]) * 1e-3)

    @property
    def left(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        h = self.length / 2
        return (np.array([self.xc - h, -5.0, SEAM_Z * 1e3]) * 1e-3,
                np.array([self.xc + h, -5.0, SEAM_Z * 1e3]) * 1e-3)


def generate(seed: int) -> TwoCell:
    """A reachable two-robot tee from seeded numbers."""
    rng = np.random.default_rng(seed)

    def u(lo: float, hi: float) -> float:  # written to the files exactly (3 decimals)
        return round(float(rng.uniform(lo, hi)), 3)

    return TwoCell(r1_pos=(u(-60, 60), -u(650, 730), 0.0), r2_pos=(u(-60, 60), u(650, 730), 0.0),
                   length=u(80, 160), xc=u(-60, 60), speed1=u(15, 35), speed2=u(15, 35),
                   start2_s=u(0.5, 1.5))


def _tee(c: TwoCell) -> str:
    h = c.length / 2
    xs = (c.xc - h, c.xc + h)
    return f"""
[[objects]]
name = "table"
shape = "box"
size_mm = [1000, 500, 450]
pos_mm = [0, 0, 225]
material = "table"

[[objects]]
name = "flange"
shape = "box"
size_mm = [{c.length + 100:.6f}, 300, 12]
pos_mm = [{c.xc:.6f}, 0, 456]
role = "workpiece"

[[objects]]
name = "web"
shape = "box"
size_mm = [{c.length + 100:.6f}, 10, 200]
pos_mm = [{c.xc:.6f}, 0, 562]
role = "workpiece"

[[seams]]
name = "left"
object = "web"
kind = "line"
points_mm = [[{xs[0] - c.xc:.6f}, -5, -100], [{xs[1] - c.xc:.6f}, -5, -100]]
normal = [0, 0, 1]
joins = ["flange"]
work_angle_deg = 45
lean = "right"

[[seams]]
name = "right"
object = "web"
kind = "line"
points_mm = [[{xs[1] - c.xc:.6f}, 5, -100], [{xs[0] - c.xc:.6f}, 5, -100]]
normal = [0, 0, 1]
joins = ["flange"]
work_angle_deg = 45
lean = "right"
"""


def _phases(prefix: str, seam: str, speed: float, hold_s: float) -> str:
    return f"""
[[{prefix}actions]]
action = "arc_on"
phase = "weld"

[[{prefix}actions]]
action = "arc_off"
phase = "weld"
at = "end"

[[{prefix}phases]]
name = "start"
planner = "434"
time_s = [0.0, {hold_s:.6f}]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0]]

[[{prefix}phases]]
name = "to_seam"
planner = "434"
durations_s = [2.0]
to_seam = "{seam}"
approach_mm = 60

[[{prefix}phases]]
name = "touch"
kind = "linear"
to_seam = "{seam}"
orientation = "seam"
speed_mm_s = 40.0

[[{prefix}phases]]
name = "weld"
kind = "linear"
seam = "{seam}"
orientation = "seam"
speed_mm_s = {speed:.6f}
"""


def write_two(c: TwoCell, folder: Path) -> Path:
    """The two-robot cell and scenario in ``folder``; returns the scenario file."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "cell.toml").write_text(f"""name = "two_gen"
tool = "mig_torch"

[robot]
model = "lrmate200ic5l"
base_pos_mm = [{c.r1_pos[0]:.6f}, {c.r1_pos[1]:.6f}, 0]
base_euler_zyx_deg = [90, 0, 0]

[[robots]]
name = "r2"
model = "lrmate200ic5l"
base_pos_mm = [{c.r2_pos[0]:.6f}, {c.r2_pos[1]:.6f}, 0]
base_euler_zyx_deg = [-90, 0, 0]
""" + _tee(c))
    (folder / "two.toml").write_text(
        'name = "two_gen"\ndescription = "generated"\nrobot = "lrmate200ic5l"\ncell = "cell.toml"\n'
        + _phases("", "left", c.speed1, 1.0)
        + _phases("robots.r2.", "right", c.speed2, c.start2_s))
    return folder / "two.toml"


def write_alone(c: TwoCell, folder: Path) -> Path:
    """The same cell with only r2's robot (as its first robot, at r2's base) doing r2's
    phases; returns the scenario file."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "cell.toml").write_text(f"""name = "two_gen_alone"
tool = "mig_torch"

[robot]
model = "lrmate200ic5l"
base_pos_mm = [{c.r2_pos[0]:.6f}, {c.r2_pos[1]:.6f}, 0]
base_euler_zyx_deg = [-90, 0, 0]
""" + _tee(c))
    (folder / "alone.toml").write_text(
        'name = "two_gen_alone"\ndescription = "generated"\nrobot = "lrmate200ic5l"\n'
        'cell = "cell.toml"\n'
        + _phases("", "right", c.speed2, c.start2_s))
    return folder / "alone.toml"

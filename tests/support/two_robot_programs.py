"""Two robots welding both sides of a tee (issue 28), as TOML text for generated cases: the cell
(two LR Mate 200iC/5L facing each other across a table, a flange and a web on it), the scenario
whose phases weld the two seams (the first robot ``left``, ``r2`` ``right``), and a TP program
for ``r2`` written by hand in the web's user frame, with the numbers the tests check the
recorded runs against.

The web's frame is at ``WEB_MM`` in the world, unturned; the seams run along x at the foot of
the web (``y = -5`` and ``y = +5``, ``z = -100`` mm in the web's frame), welded at 45 deg work
angle. The oracles are these numbers, never cellsim's planned values.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The web's frame in the world, mm (its box's centre).
WEB_MM = (0.0, 0.0, 562.0)
#: The seams' foot in the web's frame: y of the left and right seams, and z, mm.
LEFT_Y_MM, RIGHT_Y_MM, SEAM_Z_MM = -5.0, 5.0, -100.0


@dataclass(frozen=True)
class Tee:
    """One generated case.

    Attributes:
        x0: The seams' middle along x (web frame), mm. length: Their length, mm.
        speed1, speed2: The two robots' weld speeds, mm/s.
        base1, base2: The robots' bases (x, y) in the world, mm (the first near y = -700
            turned 90 deg, r2 near y = +700 turned -90 deg).
        home2: r2's home (deg) in the cell file, or None (its own).
    """

    x0: float = 0.0
    length: float = 120.0
    speed1: float = 25.0
    speed2: float = 25.0
    base1: tuple[float, float] = (0.0, -700.0)
    base2: tuple[float, float] = (0.0, 700.0)
    home2: tuple[float, ...] | None = None

    def seam(self, side: str) -> np.ndarray:
        """The seam's start and end in the world, m, (2, 3): ``left`` runs +x, ``right``
        runs -x."""
        a, b = self.x0 - self.length / 2, self.x0 + self.length / 2
        if side == "left":
            pts = [[a, LEFT_Y_MM, SEAM_Z_MM], [b, LEFT_Y_MM, SEAM_Z_MM]]
        else:
            pts = [[b, RIGHT_Y_MM, SEAM_Z_MM], [a, RIGHT_Y_MM, SEAM_Z_MM]]
        return (np.array(pts) + WEB_MM) * 1e-3

    def cell_toml(self) -> str:
        home = "" if self.home2 is None else f"home_deg = {list(self.home2)}\n"
        a, b = self.x0 - self.length / 2, self.x0 + self.length / 2
        return f'''name = "two_tee"
description = "a tee joint welded on both sides by two robots"
tool = "mig_torch"

[robot]
model = "lrmate200ic5l"
base_pos_mm = [{self.base1[0]}, {self.base1[1]}, 0]
base_euler_zyx_deg = [90, 0, 0]

[[robots]]
name = "r2"
model = "lrmate200ic5l"
base_pos_mm = [{self.base2[0]}, {self.base2[1]}, 0]
base_euler_zyx_deg = [-90, 0, 0]
{home}
[[objects]]
name = "table"
shape = "box"
size_mm = [1000, 500, 450]
pos_mm = [0, 0, 225]
material = "table"

[[objects]]
name = "flange"
shape = "box"
size_mm = [600, 300, 12]
pos_mm = [0, 0, 456]
role = "workpiece"

[[objects]]
name = "web"
shape = "box"
size_mm = [600, 10, 200]
pos_mm = {list(WEB_MM)}
role = "workpiece"

[[seams]]
name = "left"
object = "web"
kind = "line"
points_mm = [[{a}, {LEFT_Y_MM}, {SEAM_Z_MM}], [{b}, {LEFT_Y_MM}, {SEAM_Z_MM}]]
normal = [0, 0, 1]
joins = ["flange"]
work_angle_deg = 45
lean = "right"

[[seams]]
name = "right"
object = "web"
kind = "line"
points_mm = [[{b}, {RIGHT_Y_MM}, {SEAM_Z_MM}], [{a}, {RIGHT_Y_MM}, {SEAM_Z_MM}]]
normal = [0, 0, 1]
joins = ["flange"]
work_angle_deg = 45
lean = "right"
'''

    def first_robot(self) -> str:
        """The first robot's work: its phases welding ``left``."""
        return _weld_phases("", "left", self.speed1, 1.0)

    def r2_phases(self) -> str:
        """r2's work as phases welding ``right``."""
        return _weld_phases("robots.r2.", "right", self.speed2, 1.5)

    def scenario_toml(self, r2: str | None = None, first: str | None = None) -> str:
        """The scenario: the first robot's work (``first``: its phases by default), then r2's
        (``r2``: its phases by default; a ``[robots.r2]`` table's text)."""
        return ('name = "two"\ndescription = "two robots weld both sides of a tee"\n'
                'robot = "lrmate200ic5l"\ncell = "cell.toml"\n'
                + (self.first_robot() if first is None else first)
                + (self.r2_phases() if r2 is None else r2))

    def r2_program(self, approach_mm: float = 60.0) -> str:
        """r2's TP program in user frame 1 (the web): J to the approach point above the seam's
        start, L to the start, ``Arc Start``, ``L .. WELD_SPEED`` to the end, ``Arc End``, L up
        above the end, C back over the seam's middle to above its start, and J to ``PR[1]``
        (the scenario's register, :meth:`r2_register`). The torch's W, P, R are fixed in the
        web's frame."""
        (xs, ys, zs), (xe, _, _) = (self.seam("right") * 1e3 - WEB_MM)
        d = approach_mm / np.sqrt(2.0)
        xm = 0.5 * (xs + xe)
        pos = [(xs, ys + d, zs + d), (xs, ys, zs), (xe, ys, zs), (xe, ys + d, zs + d),
               (xm, ys + 1.5 * d, zs + 1.5 * d), (xs, ys + d, zs + d)]
        body = "".join(
            f"P[{k}]{{\n   GP1:\n\tUF : 1, UT : 1,\t\tCONFIG : 'F U T, 0, 0, 0',\n"
            f"\tX = {x:.3f}  mm,\tY = {y:.3f}  mm,\tZ = {z:.3f}  mm,\n"
            f"\tW = -135.000 deg,\tP = 0.000 deg,\tR = 180.000 deg\n}};\n"
            for k, (x, y, z) in enumerate(pos, start=1))
        return ("/PROG  R2WELD\n/ATTR\nCOMMENT\t\t= \"r2 welds the right seam\";\n"
                "DEFAULT_GROUP\t= 1,*,*,*,*;\n/MN\n"
                "   1:  UFRAME_NUM=1 ;\n   2:  UTOOL_NUM=1 ;\n   3:  J P[1] 30% FINE ;\n"
                "   4:  L P[2] 40mm/sec FINE ;\n   5:  Arc Start[1] ;\n"
                "   6:  L P[3] WELD_SPEED FINE ;\n   7:  Arc End[1] ;\n"
                "   8:  L P[4] 50mm/sec FINE ;\n   9:  C P[5] ;\n    :  P[6] 50mm/sec FINE ;\n"
                "  10:  J PR[1] 30% FINE ;\n/POS\n" + body + "/END\n")

    def r2_register(self, rise_mm: float = 150.0) -> list[float]:
        """``PR[1]``: above the seam's middle (web frame), [X, Y, Z, W, P, R] mm and deg."""
        (xs, ys, zs), (xe, _, _) = (self.seam("right") * 1e3 - WEB_MM)
        return [round(float(0.5 * (xs + xe)), 3), round(float(ys + rise_mm), 3),
                round(float(zs + rise_mm), 3), -135.0, 0.0, 180.0]

    def r2_program_table(self) -> str:
        """``[robots.r2]`` running :meth:`r2_program` from ``r2.ls``."""
        return ('\n[robots.r2]\nprogram = "r2.ls"\nprogram_frames = { "1" = "web" }\n'
                f'program_registers = {{ "1" = {self.r2_register()} }}\n'
                f"program_weld_speed_mm_s = {self.speed2}\n")

    def write(self, root: Path, scenario: str) -> Path:
        """The cell and ``scenario`` (and r2's program) under ``root``; the scenario's path."""
        root.mkdir(parents=True, exist_ok=True)
        (root / "cell.toml").write_text(self.cell_toml())
        (root / "r2.ls").write_text(self.r2_program())
        (root / "two.toml").write_text(scenario)
        return root / "two.toml"


def _weld_phases(prefix: str, seam: str, speed: float, start_s: float) -> str:
    actions = "".join(f'\n[[{prefix}actions]]\naction = "{a}"\nphase = "weld"\n{at}'
                      for a, at in (("arc_on", ""), ("arc_off", 'at = "end"\n')))
    return actions + f'''
[[{prefix}phases]]
name = "start"
planner = "434"
time_s = [0.0, {start_s}]
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
speed_mm_s = {speed}
'''


def run(scenario_path: Path, out: Path) -> tuple[dict, dict]:
    """Run a scenario (no video, plots or sizing); its summary and recorded arrays."""
    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario

    run_scenario(load_scenario(scenario_path), RunOptions(out_dir=out, video=False, plots=False,
                                                          sizing=False, progress=False))
    return json.loads((out / "summary.json").read_text()), dict(np.load(out / "trajectory.npz"))


def arc_path(a: dict, robot: str | None) -> np.ndarray:
    """The recorded tool point of ``robot`` (None: the first) while its arc is on, m, (N, 3)."""
    pre = "" if robot is None else f"{robot}_"
    on = np.asarray(a[f"{pre}arc_on"], dtype=bool)
    return np.asarray(a[f"{pre}tcp_pos"], dtype=float)[on]


def distance_to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Each point's distance to the polyline through ``line`` (its segments)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    den = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30)
    out = np.empty(len(points))
    for k, p in enumerate(points):
        u = np.clip(np.einsum("ij,ij->i", p - a, ab) / den, 0.0, 1.0)
        out[k] = np.linalg.norm(a + u[:, None] * ab - p, axis=1).min()
    return out


def path_gap(orig: np.ndarray, back: np.ndarray) -> float:
    """The two paths' Hausdorff distance, and their ends' distances, the largest, m."""
    return float(max(distance_to_polyline(back, orig).max(),
                     distance_to_polyline(orig, back).max(),
                     np.linalg.norm(orig[0] - back[0]), np.linalg.norm(orig[-1] - back[-1])))

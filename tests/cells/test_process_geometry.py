"""Process geometry (issue 25): the contact-tip-to-work distance puts the tool point where the
cell's own numbers say, on every kind of seam, and the contacts the welding process makes are
allowed while the nozzle, contact tip and torch body never are.

The cell of :data:`CELL`: the LR Mate 200iC/5L on a 600 mm riser, a 10 mm plate (top at
z = 780 mm) with a 60 mm wall standing on it along x (a fillet along the line y = 0, z = 780)
and a second wall across at x = 520 (an inside corner). Expected tool points, torch axes and
wire depths are computed here with numpy from the file's numbers (the AWS angles as
docs/cell-format.md defines them); the motion checked is the reference motion without dynamics,
as ``cellsim check`` checks it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from support.limits import run_limited

from sim.pipeline.check import check_scenario
from sim.scenario import load_scenario

PLATE_MM = np.array([450.0, 50.0, 775.0])  # the plate's centre (its frame's origin)
NOMINAL_MM = 15.0  # mig_torch's nominal stick-out
WIRE_R_MM = 0.6  # mig_torch's wire radius
TOUCH_MM = 0.5  # the default touch depth

#: Seams, in the plate's frame: (kind, points mm, work deg, travel deg, lean, distance key).
SEAMS = {
    "fillet": ("line", [[-70, -50, 5], [50, -50, 5]], 45, 12, "left", ""),
    "fillet_ctwd": ("line", [[-70, -50, 5], [50, -50, 5]], 45, 12, "left", "ctwd_mm = 20"),
    "bead_stickout": ("line", [[-60, 40, 5], [40, 40, 5]], 60, -10, "right", "stickout_mm = 18"),
    "ring": ("arc", [[60 * np.cos(np.deg2rad(a)), 60 + 60 * np.sin(np.deg2rad(a)), 5]
                     for a in (210, 270, 330)], 70, 5, "left", "ctwd_mm = 22"),
    "flat": ("polyline", [[-60, 120, 5], [20, 120, 5], [20, 60, 5]], 90, 0, "left",
             "stickout_mm = 20"),
    "corner": ("polyline", [[-70, -50, 5], [70, -50, 5], [70, 30, 5]], 45, 12, "left",
               "ctwd_mm = 18"),
}
#: The stand-off each seam's file gives, mm (its distance less the nominal stick-out).
STANDOFF_MM = {"fillet": 0.0, "fillet_ctwd": 5.0, "bead_stickout": 3.0, "ring": 7.0,
               "flat": 5.0, "corner": 3.0}


def _seam_toml(name: str) -> str:
    kind, pts, work, travel, lean, dist = SEAMS[name]
    pts_s = ", ".join(f"[{p[0]:.9f}, {p[1]:.9f}, {p[2]:.9f}]" for p in pts)
    return f"""
[[seams]]
name = "{name}"
object = "plate"
joins = ["wall", "wall2"]
kind = "{kind}"
points_mm = [{pts_s}]
normal = [0, 0, 1]
work_angle_deg = {work}
travel_angle_deg = {travel}
lean = "{lean}"
{dist}
"""


CELL = """
name = "fillet_cell"
tool = "mig_torch"

[robot]
base_pos_mm = [0, 0, 600]

[[objects]]
name = "riser"
shape = "box"
size_mm = [320, 320, 600]
pos_mm = [0, 0, 300]

[[objects]]
name = "plate"
shape = "box"
role = "workpiece"
size_mm = [300, 300, 10]
pos_mm = [450, 50, 775]

[[objects]]
name = "wall"
shape = "box"
role = "workpiece"
size_mm = [230, 10, 60]
pos_mm = [415, -5, 810]

[[objects]]
name = "wall2"
shape = "box"
role = "workpiece"
size_mm = [10, 110, 60]
pos_mm = [525, 45, 810]
""" + "".join(_seam_toml(n) for n in SEAMS)


# ---------------------------------------------------------------------------- the oracle
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


class Expected:
    """A seam from the file's numbers: world points, tangents and torch axes (numpy, the
    formulas of docs/cell-format.md: ``a = cos(tau) a_perp + sin(tau) t``,
    ``a_perp = -(sin(w) n + cos(w) e)``, ``e = +-(n x t)``, w the file's work angle)."""

    def __init__(self, name: str) -> None:
        kind, pts, work, travel, lean, _ = SEAMS[name]
        self.kind = kind
        self.pts = (np.asarray(pts, float) + PLATE_MM) * 1e-3
        self.w, self.tau = np.deg2rad(work), np.deg2rad(travel)
        self.side = 1.0 if lean == "left" else -1.0
        self.n = np.array([0.0, 0.0, 1.0])
        self.h = STANDOFF_MM[name] * 1e-3
        if kind == "arc":  # circumcentre of the three points (all at one height)
            (x1, y1), (x2, y2), (x3, y3) = self.pts[:, :2]
            d = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
            ux = ((x1**2 + y1**2) * (y2 - y3) + (x2**2 + y2**2) * (y3 - y1)
                  + (x3**2 + y3**2) * (y1 - y2)) / d
            uy = ((x1**2 + y1**2) * (x3 - x2) + (x2**2 + y2**2) * (x1 - x3)
                  + (x3**2 + y3**2) * (x2 - x1)) / d
            self.c = np.array([ux, uy, self.pts[0, 2]])
            self.r = float(np.linalg.norm(self.pts[0] - self.c))
            ang = [np.arctan2(*(p - self.c)[1::-1]) for p in self.pts]
            self.th0, self.th1 = ang[0], ang[0] + np.mod(ang[2] - ang[0], 2 * np.pi)

    def axis(self, t: np.ndarray) -> np.ndarray:
        e = self.side * _unit(np.cross(self.n, t))
        a_perp = -(np.sin(self.w) * self.n + np.cos(self.w) * e)
        return np.cos(self.tau) * a_perp + np.sin(self.tau) * t

    def legs(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Straight legs (start, end) of a line or polyline."""
        return list(zip(self.pts[:-1], self.pts[1:], strict=True))

    def dense(self, m: int = 2000) -> tuple[np.ndarray, np.ndarray]:
        """Seam points and their tool points, (M, 3) each, densely along the seam."""
        if self.kind == "arc":
            th = np.linspace(self.th0, self.th1, m)
            p = self.c + self.r * np.column_stack([np.cos(th), np.sin(th), np.zeros(m)])
            t = np.column_stack([-np.sin(th), np.cos(th), np.zeros(m)])
            a = np.array([self.axis(v) for v in t])
            return p, p - self.h * a
        seam, tool = [], []
        for p0, p1 in self.legs():
            u = np.linspace(0.0, 1.0, m)[:, None]
            p = p0 + u * (p1 - p0)
            seam.append(p)
            tool.append(p - self.h * self.axis(_unit(p1 - p0)))
        return np.vstack(seam), np.vstack(tool)

    def start_tool(self) -> tuple[np.ndarray, np.ndarray]:
        """The tool point and the torch axis at the seam's start."""
        if self.kind == "arc":
            t = np.array([-np.sin(self.th0), np.cos(self.th0), 0.0])
        else:
            t = _unit(self.pts[1] - self.pts[0])
        a = self.axis(t)
        return self.pts[0] - self.h * a, a

    def end_tool(self) -> tuple[np.ndarray, np.ndarray]:
        if self.kind == "arc":
            t = np.array([-np.sin(self.th1), np.cos(self.th1), 0.0])
        else:
            t = _unit(self.pts[-1] - self.pts[-2])
        a = self.axis(t)
        return self.pts[-1] - self.h * a, a


def _euler_deg(a: np.ndarray, t: np.ndarray) -> list[float]:
    """Z-Y-X Euler angles (deg) of the torch frame z = a, x = t made perpendicular to a."""
    x = _unit(t - (t @ a) * a)
    R = np.column_stack([x, np.cross(a, x), a])
    return np.rad2deg([np.arctan2(R[1, 0], R[0, 0]), -np.arcsin(R[2, 0]),
                       np.arctan2(R[2, 1], R[2, 2])]).tolist()


def _mm(v: np.ndarray) -> str:
    return "[" + ", ".join(f"{x:.6f}" for x in np.asarray(v) * 1e3) + "]"


HEAD = """name = "pg_{name}"
description = "process geometry"
robot = "lrmate200ic5l"
cell = "cell.toml"
{tool}
[[phases]]
name = "ready"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 5, -10, 0, -75, 0], [0, 10, -20, 0, -60, 0]]

[[phases]]
name = "above"
planner = "434"
durations_s = [2.0]
to_mm = {above}
euler_zyx_deg = {euler}
frame = "world"

[[phases]]
name = "down"
kind = "linear"
to_mm = {down}
frame = "world"
speed_mm_s = 20
"""


def scenario_text(name: str, *, weld: str = "", plant_mm: float = 0.0,
                  standoff_mm: float | None = None, tool: str = "") -> str:
    """Down along the torch axis onto seam ``name``'s start (``plant_mm`` further, into the
    part), then ``weld`` (extra keys of a weld phase along the seam, arc on; no weld if empty)
    and back up 40 mm along the torch axis."""
    ex = Expected(name)
    if standoff_mm is not None:
        ex.h = standoff_mm * 1e-3
    start, a0 = ex.start_tool()
    t0 = _unit(ex.pts[1] - ex.pts[0]) if ex.kind != "arc" else np.cross(ex.n, ex.pts[0] - ex.c)
    text = HEAD.format(name=name, tool=tool, above=_mm(start - 0.04 * a0),
                       euler=_euler_deg(a0, _unit(t0)), down=_mm(start + plant_mm * 1e-3 * a0))
    end, a1 = start + plant_mm * 1e-3 * a0, a0
    if weld:
        text = text.replace("[[phases]]\nname = \"ready\"", (
            '[[actions]]\naction = "arc_on"\nphase = "weld"\n[[actions]]\naction = "arc_off"\n'
            'phase = "weld"\nat = "end"\n\n[[phases]]\nname = "ready"'))
        kind = "circular" if ex.kind == "arc" else "linear"
        orient = "follow" if ex.kind == "arc" else "seam"
        text += (f'\n[[phases]]\nname = "weld"\nkind = "{kind}"\nseam = "{name}"\n'
                 f'orientation = "{orient}"\n{weld}\n')
        end, a1 = ex.end_tool()
    return text + (f'\n[[phases]]\nname = "up"\nkind = "linear"\nto_mm = {_mm(end - 0.04 * a1)}'
                   '\nframe = "world"\nspeed_mm_s = 50\n')


def write(root: Path, text: str, cell: str = CELL) -> Path:
    (root / "cell.toml").write_text(cell)
    path = root / "scenario.toml"
    path.write_text(text)
    return path


def reference(path: Path, dt: float = 0.002):
    """The reference motion of a scenario, sampled: (built, motion, samples, phase names)."""
    from sim.simulation.collisions import samples_from_motion
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    scenario = load_scenario(path)
    built = build(scenario)
    motion = build_motion(scenario, built.context)
    return built, motion, samples_from_motion(built, motion, dt), [p.name for p in motion.phases]


def tcp_frames(built, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's tool point and tcp z axis (the torch axis of the LR Mate 200iC) per row."""
    import mujoco

    m, d = built.model, mujoco.MjData(built.model)
    pos, axis = [], []
    for q in qpos:
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        pos.append(d.site_xpos[built.tcp_site].copy())
        axis.append(d.site_xmat[built.tcp_site].reshape(3, 3)[:, 2].copy())
    return np.array(pos), np.array(axis)


def _nearest(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance of each point to a dense curve (the chords between its points), m."""
    a, ab = curve[:-1], np.diff(curve, axis=0)
    ab2 = np.maximum(np.sum(ab * ab, axis=1), 1e-30)
    out = []
    for p in points:
        u = np.clip(np.sum((p - a) * ab, axis=1) / ab2, 0.0, 1.0)
        out.append(np.min(np.linalg.norm(a + u[:, None] * ab - p, axis=1)))
    return np.array(out)


# ---------------------------------------------------------------------------- stand-off
def test_the_seams_tool_points_follow_the_files_distances(tmp_path):
    """Every seam with a distance (ctwd_mm or stickout_mm; lines, an arc, polylines): the cell's
    seam puts the tool point ``distance - 15 mm`` back along the file's torch axis from the seam
    point, at every point of every leg."""
    from sim.cells import build_cell, load_cell
    from sim.robots.registry import ROBOTS

    (tmp_path / "cell.toml").write_text(CELL)
    cell = build_cell(load_cell(tmp_path / "cell.toml"), ROBOTS["lrmate200ic5l"])
    for name in SEAMS:
        seam, ex = cell.seams[name], Expected(name)
        assert seam.standoff_m == pytest.approx(ex.h, abs=1e-12)
        pieces = [seam] if seam.kind != "polyline" else seam.segments()
        legs = [None] if ex.kind == "arc" else ex.legs()
        for sg, leg in zip(pieces, legs, strict=True):
            for s in np.linspace(0.0, sg.length(), 7):
                p = sg.point(s)
                if leg is None:
                    t = np.cross(ex.n, _unit(p - ex.c))
                else:
                    t = _unit(leg[1] - leg[0])
                    assert np.linalg.norm(np.cross(p - leg[0], t)) < 1e-12  # on the file's leg
                want = p - ex.h * ex.axis(t)
                np.testing.assert_allclose(sg.tcp_point(s), want, atol=1e-12, err_msg=name)
                np.testing.assert_allclose(sg.pose(s)[:3, 2], ex.axis(t), atol=1e-12)
                # the contact tip, the nominal stick-out behind the tool point: ctwd from the seam
                tip = sg.tcp_point(s) - NOMINAL_MM * 1e-3 * ex.axis(t)
                assert np.linalg.norm(tip - p) == pytest.approx(ex.h + NOMINAL_MM * 1e-3)


@pytest.mark.parametrize("name", ["fillet_ctwd", "bead_stickout", "ring", "flat"])
def test_a_weld_keeps_the_tool_point_at_the_stand_off(name, tmp_path):
    """The reference motion welding each seam: the tool point within 0.05 mm of the seam
    offset by its stand-off along the file's torch axis, ends within 0.05 mm, and the point
    ``stand-off`` ahead of it along the recorded torch axis on the seam itself (the wire reaches
    the seam), outside a polyline's 2 mm corner blend."""
    ex = Expected(name)
    path = write(tmp_path, scenario_text(name, weld="speed_mm_s = 20"))
    built, motion, samples, names = reference(path)
    k = names.index("weld")
    pm = motion.phases[k]
    sel = samples.phase == k
    pos, axis = tcp_frames(built, samples.qpos[sel])
    seam_pts, tool_pts = ex.dense()
    far = np.ones(len(pos), bool)
    for corner in ex.pts[1:-1] if ex.kind == "polyline" else []:
        far &= np.linalg.norm(pos + ex.h * axis - corner, axis=1) > 3e-3
    assert far.sum() > 0.8 * len(pos)
    assert _nearest(pos[far], tool_pts).max() < 5e-5
    assert _nearest(pos[far] + ex.h * axis[far], seam_pts).max() < 5e-5
    ends, _ = tcp_frames(built, _qpos_at(built, motion, samples, [pm.t0, pm.t1]))
    assert np.linalg.norm(ends[0] - ex.start_tool()[0]) < 5e-5
    assert np.linalg.norm(ends[1] - ex.end_tool()[0]) < 5e-5


def _qpos_at(built, motion, samples, times) -> np.ndarray:
    q = np.tile(samples.qpos[0], (len(times), 1))
    q[:, built.robot_qpos] = motion.at(np.asarray(times)).q
    return q


def test_a_fillet_polyline_with_a_ctwd_is_welded_round_its_corner(tmp_path):
    """The user's case: ctwd_mm on a fillet polyline whose torch axis turns at the corner (the
    stand-off turns with it; it was refused at the seam's own corner: 'corner/2 starts 3.06 mm
    away'). The torch turns 112 deg at this inside corner: a 10 mm blend gives the wrist room
    (the default 2 mm is refused as too sharp), and the tool point is on the seam's stand-off
    path outside that zone."""
    ex = Expected("corner")
    path = write(tmp_path, scenario_text("corner", weld="speed_mm_s = 20\nblend_mm = 10"))
    built, motion, samples, names = reference(path)
    sel = samples.phase == names.index("weld")
    pos, axis = tcp_frames(built, samples.qpos[sel])
    far = np.linalg.norm(pos + ex.h * axis - ex.pts[1], axis=1) > 10e-3 + ex.h
    assert _nearest(pos[far], ex.dense()[1]).max() < 5e-5


def test_a_weld_phase_sets_its_own_ctwd(tmp_path):
    """``ctwd_mm`` on a weld phase: the phase's stand-off is that distance less the torch's
    15 mm, and the seam it welds (:meth:`CartesianPhase.seam_as_welded`) puts the tool point
    that far back along the file's torch axis, on a seam whose file gives no distance."""
    from sim.cells import build_cell

    path = write(tmp_path, scenario_text("fillet", weld="speed_mm_s = 20\nctwd_mm = 21",
                                         standoff_mm=6.0))
    scenario = load_scenario(path)
    weld = next(p for p in scenario.phases if p.name == "weld")
    assert weld.standoff == pytest.approx(0.006)
    cell = build_cell(scenario.cell, scenario.robot, tool=scenario.tool)
    seam = weld.seam_as_welded(cell.seams["fillet"])
    assert cell.seams["fillet"].standoff_m == 0.0  # the cell's seam is left as it is
    ex = Expected("fillet")
    a = ex.axis(_unit(ex.pts[1] - ex.pts[0]))
    for s in np.linspace(0.0, seam.length(), 5):
        np.testing.assert_allclose(seam.tcp_point(s), seam.point(s) - 0.006 * a, atol=1e-12)


def test_a_weld_phases_ctwd_moves_the_welding_tool_point(tmp_path):
    """A weld phase's own ``ctwd_mm`` moves the planned tool point back along the torch axis."""
    path = write(tmp_path, scenario_text("fillet", weld="speed_mm_s = 20\nctwd_mm = 21",
                                         standoff_mm=6.0))
    built, motion, samples, names = reference(path)
    ex = Expected("fillet")
    ex.h = 0.006
    pos, _ = tcp_frames(built, samples.qpos[samples.phase == names.index("weld")])
    assert _nearest(pos, ex.dense()[1]).max() < 5e-5


BAD = {
    "both keys": (CELL.replace('"fillet_ctwd"', '"fillet_ctwd"\nstickout_mm = 20', 1), "",
                  "seams[1].ctwd_mm: give one of stickout_mm or ctwd_mm"),
    "ctwd shorter than the nominal stick-out": (
        CELL.replace("ctwd_mm = 20", "ctwd_mm = 12"), "",
        "seams[1].ctwd_mm: 12 mm is shorter than the nominal stick-out of tool 'mig_torch', 15 mm"),
    "a phase's ctwd without a seam": (
        CELL, 'to_mm = [0, 0, 0]\nframe = "world"', "phases[3].ctwd_mm: only used with seam"),
    "a phase's ctwd shorter than the nominal": (
        CELL, "", "phases[3].ctwd_mm: 10 mm is shorter than the nominal stick-out of tool "
        "'mig_torch'"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_distances_are_one_line_naming_the_key(case, tmp_path):
    """One line naming the file and the key, exit 2."""
    cell, weld_to, want = BAD[case]
    weld = "speed_mm_s = 20"
    if "phase" in case:
        weld += "\nctwd_mm = " + ("21" if weld_to else "10")
    text = scenario_text("fillet", weld=weld)
    if weld_to:
        text = text.replace('seam = "fillet"\norientation = "seam"', weld_to)
    path = write(tmp_path, text, cell)
    r = run_limited([sys.executable, "-m", "sim", "check", str(path)], capture_output=True,
                       text=True, cpu_s=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert "Traceback" not in r.stderr and want in lines[0], lines[0]
    assert ("cell.toml" if "seams[" in want else "scenario.toml") in lines[0]


# ---------------------------------------------------------------------------- contacts
def _rim_depth(a: np.ndarray, normal: np.ndarray) -> float:
    """How deep a flat-ended wire of radius r whose tip centre is on a plane reaches into it:
    its end disc's rim, ``r sin(angle between the wire and the plane's normal)``, m."""
    return WIRE_R_MM * 1e-3 * float(np.sqrt(1.0 - (a @ normal) ** 2))


def _wire_depths(built, samples, rows) -> dict[str, float]:
    """The deepest the wire reaches into each cell object over the given samples, m
    (``mj_geomDistance`` on the check model, no allowance applied)."""
    from sim.simulation.collisions import CollisionModel

    cm = CollisionModel(built)
    c = cm.scan(samples.qpos, np.asarray(rows))
    out: dict[str, float] = {}
    for g1, g2, d in zip(c.g1, c.g2, c.dist, strict=True):
        names = {cm.geoms[int(g1)].name, cm.geoms[int(g2)].name}
        if "robot/tool/wire" in names:
            (other,) = names - {"robot/tool/wire"}
            out[other] = max(out.get(other, 0.0), -float(d))
    return out


def test_the_wire_at_a_fillets_root_with_the_arc_off_is_no_collision(tmp_path):
    """Tool point on the corner line of plate and wall, torch at 45 deg work and 12 deg travel
    angle, arc off: the wire's end disc reaches r sin(phi) into each (0.433 mm), measured per
    wall (never summed), and this touch is no collision."""
    path = write(tmp_path, scenario_text("fillet"))
    res = check_scenario(load_scenario(path))
    assert res.ok, [f.line for f in res.findings]
    built, motion, samples, names = reference(path)
    pm = motion.phases[names.index("down")]
    row = int(np.argmin(np.abs(samples.t - pm.t1)))
    assert not samples.arc_on[row]
    a = Expected("fillet").axis(np.array([1.0, 0.0, 0.0]))
    depth = _wire_depths(built, samples, [row])
    assert depth["plate"] == pytest.approx(_rim_depth(a, np.array([0, 0, 1.0])), abs=2e-6)
    assert depth["wall"] == pytest.approx(_rim_depth(a, np.array([0, 1.0, 0])), abs=2e-6)


def test_the_nozzle_planted_in_the_fillet_is_a_collision(tmp_path):
    """The same approach with the tool point 20 mm further along the torch axis, into the
    part: a collision of the torch naming the nozzle (never allowed), exit 1 from check."""
    path = write(tmp_path, scenario_text("fillet", plant_mm=20.0))
    res = check_scenario(load_scenario(path))
    hits = [c for c in res.collisions if c["bodies"][0] == "robot/tool/torch"]
    assert hits, [f.line for f in res.findings]
    assert any("robot/tool/nozzle" in c["all_geoms"] and c["bodies"][1] in ("plate", "wall")
               for c in hits)
    assert any(c["geoms"][0] != "robot/tool/wire" for c in hits)
    assert any("robot/tool/nozzle" in f.line or "robot/tool/contact_tip" in f.line
               for f in res.findings if f.kind == "collision")


TOOL_FILE = """
name = "touchy_torch"
kind = "torch"
mass_kg = 1.0
tcp_mm = [0, 0, 145]
stickout_mm = 15
touch_depth_mm = {touch}
[[shapes]]
name = "body"
shape = "cylinder"
from_mm = [0, 0, 0]
to_mm = [0, 0, 85]
radius_mm = 30
[[shapes]]
name = "nozzle"
shape = "cylinder"
from_mm = [0, 0, 85]
to_mm = [0, 0, 128]
radius_mm = 11
"""


@pytest.mark.parametrize("touch_mm", [None, 0.1])
def test_the_touch_depth_is_the_tools(touch_mm, tmp_path):
    """The tip set 0.8 mm further into the fillet's corner, arc off: the wire reaches
    ``r sin(phi) + 0.8 |a . n|`` into the plate (beyond its radius); with the default touch
    depth (0.5 mm over the radius) that is allowed, with a tool file's 0.1 mm it is a
    collision of the wire."""
    tool = ""
    if touch_mm is not None:
        (tmp_path / "torch.toml").write_text(TOOL_FILE.format(touch=touch_mm))
        tool = 'tool = "torch.toml"'
    path = write(tmp_path, scenario_text("fillet", plant_mm=0.8, tool=tool))
    built, motion, samples, names = reference(path)
    pm = motion.phases[names.index("down")]
    row = int(np.argmin(np.abs(samples.t - pm.t1)))
    a = Expected("fillet").axis(np.array([1.0, 0.0, 0.0]))
    want = _rim_depth(a, np.array([0, 0, 1.0])) + 0.8e-3 * abs(a[2])
    got = _wire_depths(built, samples, [row])["plate"]
    assert got == pytest.approx(want, abs=5e-6)
    assert WIRE_R_MM * 1e-3 < got < (WIRE_R_MM + TOUCH_MM) * 1e-3
    res = check_scenario(load_scenario(path))
    if touch_mm is None:
        assert res.ok, [f.line for f in res.findings]
    else:
        assert res.collisions and all(c["geoms"] == ["robot/tool/wire", "plate"]
                                      for c in res.collisions if c["bodies"][1] == "plate")


def test_weaving_across_a_fillet_with_the_arc_on_is_no_collision(tmp_path):
    """A 2 mm sine weave at 1.5 Hz across the fillet, arc on: the wire swings
    ``r sin(phi) + A |l . n|`` (1.85 mm) into plate and wall, deeper than radius + 1 mm, within
    radius + weave reach + 1 mm: no collision (it was one per half cycle)."""
    path = write(tmp_path, scenario_text(
        "fillet", weld='speed_mm_s = 8\nweave = { pattern = "sine", amplitude_mm = 2.0, '
                       'frequency_hz = 1.5 }'))
    res = check_scenario(load_scenario(path))
    assert res.ok, [f.line for f in res.findings]
    built, motion, samples, names = reference(path, dt=0.001)
    rows = np.flatnonzero(samples.phase == names.index("weld"))
    depth = _wire_depths(built, samples, rows)
    a = Expected("fillet").axis(np.array([1.0, 0.0, 0.0]))
    t_perp = _unit(np.array([1.0, 0.0, 0.0]) - a[0] * a)
    lateral = np.cross(t_perp, a)  # planners/weave.py: travel x torch axis
    for obj, n in (("plate", np.array([0, 0, 1.0])), ("wall", np.array([0, 1.0, 0]))):
        want = _rim_depth(a, n) + 2e-3 * abs(lateral @ n)
        assert depth[obj] == pytest.approx(want, abs=2e-5), obj
        assert (WIRE_R_MM + 1.0) * 1e-3 < depth[obj] < (WIRE_R_MM + 2.0 + 1.0) * 1e-3


def test_the_weave_reach_is_the_patterns_farthest_offset():
    """Amplitude A for sine, zigzag and circle; sqrt(A^2 + (A/2)^2) for the triangle (A
    across, A/2 behind); 0 without a weave."""
    from planners.weave import Weave
    from sim.simulation.collisions import weave_reach

    for pattern, k in (("sine", 1.0), ("zigzag", 1.0), ("circle", 1.0),
                       ("triangle", np.hypot(1.0, 0.5))):
        assert weave_reach(Weave(pattern, 0.002, 1.5)) == pytest.approx(0.002 * k, rel=1e-9)
    assert weave_reach(None) == 0.0

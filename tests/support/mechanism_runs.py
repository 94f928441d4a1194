"""Small generated runs with external axes, for the tests of what a run reports of its
mechanisms (the typed result, the plots, the report): :func:`axes_cell` writes a cell with a
floor track under the robot and a tilt-rotate positioner carrying a steel plate of a given
size (a mounted workpiece is solid steel, :data:`STEEL_KG_M3`);
:func:`axes_scenario` a short joint phase moving the robot and every axis to given values.
Nothing here is a test; the numbers a test judges by are the ones it gave these writers.
"""

from __future__ import annotations

from pathlib import Path

#: Density of the steel a mounted workpiece is made of, kg/m^3 (docs/cell-format.md).
STEEL_KG_M3 = 7850.0
#: The robot of the generated runs and its joint knots (deg): a short move away from home.
ROBOT = "lrmate200ic5l"
KNOTS_DEG = ([0.0, 0.0, 0.0, 0.0, -90.0, 0.0], [10.0, 5.0, -10.0, 0.0, -80.0, 0.0])

_CELL = """
name = "gen_axes"
tool = "mig_torch"

[robot]
model = "{robot}"
on = "track"

[[mechanisms]]
name = "track"
model = "floor_track_4m"
pos_mm = [0, 0, -240]
home = {{ travel_mm = {track_home_mm!r} }}

[[mechanisms]]
name = "positioner"
model = "motopos_d500"
pos_mm = [0, 1800, -550]

[[objects]]
name = "plate"
shape = "box"
size_mm = [{side_mm!r}, {side_mm!r}, {thick_mm!r}]
pos_mm = [0, 0, {half_mm!r}]
role = "workpiece"
on = "positioner"
"""

_SCENARIO = """
name = "gen_axes_run"
description = "generated: the robot, the track and the positioner move together"
robot = "{robot}"
cell = "cell.toml"
tool = "mig_torch"

[[phases]]
name = "move"
planner = "434"
time_s = [0.0, {duration_s!r}]
joints_deg = [{k0}, {k1}]
axes = {{ {axes} }}
"""


def axes_cell(folder: Path, *, side_mm: float = 300.0, thick_mm: float = 10.0,
              track_home_mm: float = 0.0) -> Path:
    """``folder/cell.toml``: the robot on a 4 m floor track (its carriage at
    ``track_home_mm``) and a MotoPos D500 carrying a square steel plate ``side_mm`` wide and
    ``thick_mm`` thick on its faceplate."""
    path = folder / "cell.toml"
    path.write_text(_CELL.format(robot=ROBOT, track_home_mm=float(track_home_mm),
                                 side_mm=float(side_mm), thick_mm=float(thick_mm),
                                 half_mm=0.5 * float(thick_mm)))
    return path


def plate_kg(side_mm: float, thick_mm: float) -> float:
    """The plate's mass: its volume times the density of steel, kg."""
    return STEEL_KG_M3 * (side_mm * 1e-3) ** 2 * thick_mm * 1e-3


def axes_scenario(folder: Path, *, travel_mm: float, tilt_deg: float, rotate_deg: float,
                  duration_s: float = 1.5) -> Path:
    """``folder/scenario.toml`` (next to :func:`axes_cell`'s cell): one joint phase of
    ``duration_s`` moving the robot by :data:`KNOTS_DEG` and the track, the tilt and the rotate
    axis to the given values at its end."""
    path = folder / "scenario.toml"
    path.write_text(_SCENARIO.format(
        robot=ROBOT, duration_s=float(duration_s), k0=list(KNOTS_DEG[0]), k1=list(KNOTS_DEG[1]),
        axes=f"track_travel_mm = {float(travel_mm)!r}, positioner_tilt_deg = "
             f"{float(tilt_deg)!r}, positioner_rotate_deg = {float(rotate_deg)!r}"))
    return path

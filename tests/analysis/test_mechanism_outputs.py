"""What a run writes of its mechanisms (issue 28): a ``plots/mechanism_<name>.png`` and a
report section per mechanism, whose figures are the summary's and the recorded arrays'; a
linear axis (a track's) is never labelled deg or N m (plots, sizing checks, tables).

One generated run (drawn from a seeded generator: plate size, track home and target, tilt and
rotate targets): the robot on a floor track, a positioner carrying a steel plate. The oracles
are written here from the inputs: the plate's mass is its volume times the density of steel;
each axis's travel runs from its home to the phase's target (a polynomial from rest to rest);
the peak and RMS of a torque are recomputed from the recorded arrays (max |x|, trapezoidal
sqrt(1/T int x^2 dt)).
"""

from __future__ import annotations

import json
import math
import random
import re

import numpy as np
import pytest

import sim
from sim.analysis.mechanism_report import AXIS_HEAD
from sim.analysis.plots import (
    joint_figure,
    mechanism_figure,
    png_size,
    torque_figure,
    tracking_error_figure,
)
from sim.simulation.runfolder import load_run
from tests.support.mechanism_runs import axes_cell, axes_scenario, plate_kg

_RNG = random.Random(2028)
INPUT = {"side_mm": _RNG.uniform(200, 400), "thick_mm": _RNG.uniform(5, 30),
         "track_home_mm": _RNG.uniform(-500, 0), "travel_mm": _RNG.uniform(0, 300),
         "tilt_deg": _RNG.uniform(-40, -10), "rotate_deg": _RNG.uniform(30, 120)}
#: The tables print 4 significant digits.
REL = 6e-4


# one generated run with plots and report (about 20 s): in the slow share (the fast share's
# ten minutes)
pytestmark = pytest.mark.slow

@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("axes")
    axes_cell(folder, side_mm=INPUT["side_mm"], thick_mm=INPUT["thick_mm"],
              track_home_mm=INPUT["track_home_mm"])
    sc = axes_scenario(folder, travel_mm=INPUT["travel_mm"], tilt_deg=INPUT["tilt_deg"],
                       rotate_deg=INPUT["rotate_deg"], duration_s=2.0)
    return sim.run(sim.load_scenario(sc), out_dir=folder / "run", video=False)


def _num(cell: str) -> float:
    return float(cell.split()[0])


def _sections(md: str) -> dict[str, dict]:
    """``sizing.md``'s mechanism sections, parsed: name -> load sentence numbers and rows."""
    out = {}
    for m in re.finditer(r"^## Mechanism (\S+) \((\S+), (\S+)\)\n\n([^\n]*)\n\n(\|.*?)\n\n", md,
                         re.M | re.S):
        lines = m[5].splitlines()
        head = [c.strip() for c in lines[0].strip("|").split("|")]
        assert tuple(head) == AXIS_HEAD
        rows = {}
        for ln in lines[2:]:
            cells = [c.strip() for c in ln.strip("|").split("|")]
            rows[cells[0]] = dict(zip(head, cells, strict=True))
        kg = re.match(r"Carries (.*): (\S+) kg, rated (\S+) kg", m[4])
        assert kg, m[4]
        out[m[1]] = {"kind": m[2], "model": m[3], "carries": kg[1].split(", "),
                     "carried_kg": float(kg[2]), "rated_kg": float(kg[3]), "rows": rows}
    return out


def _close(a: float, b: float, rel: float = REL, abs_: float = 1e-9) -> bool:
    return math.isclose(a, b, rel_tol=rel, abs_tol=abs_)


def _report_mismatches(sections: dict, summary: dict, arrays: dict, joints: list) -> list[str]:
    """The oracle: every figure of the report's mechanism sections against the summary and
    the recorded arrays (recomputed here)."""
    bad = []
    if set(sections) != set(summary["mechanisms"]):
        return ["mechanisms"]
    t = arrays["t"]
    for name, m in summary["mechanisms"].items():
        sec = sections[name]
        if (sec["kind"], sec["model"]) != (m["kind"], m["model"]):
            bad.append(f"{name}.kind")
        if sec["carries"] != list(m["carries"]):
            bad.append(f"{name}.carries")
        if not _close(sec["carried_kg"], m["carried_kg"]):
            bad.append(f"{name}.carried_kg")
        if not _close(sec["rated_kg"], m["rated_payload_kg"]):
            bad.append(f"{name}.rated")
        for axis, a in m["axes"].items():
            row = sec["rows"][axis]
            unit = a["unit"]
            for col, want in (("min", a["min"]), ("max", a["max"]),
                              ("travel", a["max"] - a["min"])):
                if not row[col].endswith(f" {unit}") or not _close(_num(row[col]), want,
                                                                    abs_=1e-6):
                    bad.append(f"{axis}.{col}")
            if not row["max speed"].endswith(f" {unit}/s"):
                bad.append(f"{axis}.speed unit")
            if not _close(_num(row["max speed"]), a["max_speed"]):
                bad.append(f"{axis}.max speed")
            j = joints.index(axis)
            force_unit = "N" if a["kind"] == "prismatic" else "N m"
            for col, key in (("peak torque or force (ID / sim)", "peak"),
                             ("RMS torque or force (ID / sim)", "rms")):
                body = row[col].removesuffix(f" {force_unit}")
                if body == row[col] or not re.fullmatch(r"\S+ / \S+", body):
                    bad.append(f"{axis}.{col} unit")
                    continue
                ident, simu = body.split(" / ")
                for shown, arr in ((ident, arrays["tau_id"][:, j]), (simu, arrays["tau"][:, j])):
                    want = (float(np.abs(arr).max()) if key == "peak" else
                            math.sqrt(np.trapezoid(arr ** 2, t) / (t[-1] - t[0])))
                    # the simulated peak is of the torque sustained over 5 ms: within 2 %
                    tol = 2e-2 if (key == "peak" and arr is arrays["tau"][:, j]) else REL
                    if not _close(float(shown), want, rel=tol, abs_=1e-6):
                        bad.append(f"{axis}.{key}")
    return bad


def test_a_plot_and_a_report_section_per_mechanism(run):
    folder = run.path
    for name in ("track", "positioner"):
        png = folder / "plots" / f"mechanism_{name}.png"
        assert png.is_file()
        w, h = png_size("mechanism")
        assert png.read_bytes()[16:24] == w.to_bytes(4, "big") + h.to_bytes(4, "big")
    md = (folder / "sizing.md").read_text()
    html = (folder / "report.html").read_text()
    summary = run.to_dict()
    for name, m in summary["mechanisms"].items():
        assert f"<h2>Mechanism {name} ({m['kind']}, {m['model']})</h2>" in html
    sections = _sections(md)
    assert set(sections) == {"track", "positioner"}


def test_the_report_figures_are_the_summarys_and_the_inputs(run):
    record = load_run(run.path)
    summary = run.to_dict()
    sections = _sections((run.path / "sizing.md").read_text())
    assert _report_mismatches(sections, summary, record.arrays, list(record.joints)) == []
    # the inputs: the plate is solid steel; each axis ran from its home to its target
    pos, track = summary["mechanisms"]["positioner"], summary["mechanisms"]["track"]
    want_kg = plate_kg(INPUT["side_mm"], INPUT["thick_mm"])
    assert pos["carries"] == ["plate"] and _close(pos["carried_kg"], want_kg, rel=1e-9)
    assert _close(sections["positioner"]["carried_kg"], want_kg)
    ends = {"track_travel": (INPUT["track_home_mm"], INPUT["travel_mm"], 0.05),
            "positioner_tilt": (0.0, INPUT["tilt_deg"], 0.01),
            "positioner_rotate": (0.0, INPUT["rotate_deg"], 0.01)}
    axes = {**track["axes"], **pos["axes"]}
    for axis, (home, target, tol) in ends.items():
        assert axes[axis]["min"] == pytest.approx(min(home, target), abs=tol)
        assert axes[axis]["max"] == pytest.approx(max(home, target), abs=tol)


def test_the_oracle_catches_a_planted_fault(run):
    record = load_run(run.path)
    summary = run.to_dict()
    sections = _sections((run.path / "sizing.md").read_text())
    for path in (("positioner", "carried_kg"), ("track", "rated_payload_kg")):
        bad = json.loads(json.dumps(summary))
        bad["mechanisms"][path[0]][path[1]] *= 1.01
        assert _report_mismatches(sections, bad, record.arrays, list(record.joints)) != []
    bad = json.loads(json.dumps(summary))
    bad["mechanisms"]["track"]["axes"]["track_travel"]["max"] += 1.0
    assert _report_mismatches(sections, bad, record.arrays, list(record.joints)) != []
    arrays = dict(record.arrays)
    arrays["tau_id"] = arrays["tau_id"] * 1.01
    assert _report_mismatches(sections, summary, arrays, list(record.joints)) != []


def _labels(fig) -> list[str]:
    return [ax.get_ylabel() for ax in fig.axes if ax.get_visible()]


def test_a_linear_axis_is_never_labelled_deg_or_n_m(run):
    record = load_run(run.path)
    j = list(record.joints).index("track_travel")
    labels = _labels(joint_figure(record, j))
    assert labels and all("[mm" in lb and "deg" not in lb for lb in labels)
    track_labels = [lb for lb in _labels(tracking_error_figure(record)) if "track" in lb]
    assert track_labels == ["track_travel error [mm]"]
    assert [lb for lb in _labels(torque_figure(record)) if "track" in lb] == \
        ["track_travel force [N]"]
    mech = _labels(mechanism_figure(record, "track"))
    assert mech == ["track_travel position [mm]", "track_travel speed [mm/s]",
                    "track_travel force [N]"]
    # a revolute axis keeps deg and N m
    assert _labels(mechanism_figure(record, "positioner"))[-1] == "positioner_rotate torque [N m]"
    # the sizing: the track's checks in N and m/s, its row's torques as forces
    sizing = json.loads((run.path / "sizing.json").read_text())
    row = next(r for r in sizing["joints"] if r["joint"] == "track_travel")
    assert (row["kind"], row["torque_unit"], row["speed_unit"]) == ("prismatic", "N", "m/s")
    units = {c["key"]: c["unit"] for c in row["checks"]}
    assert units["joint_torque"] == "N" and units["joint_speed"] == "m/s"
    assert run.sizing["track_travel"].torque_unit == "N"
    md = (run.path / "sizing.md").read_text()
    rows_md = [[c.strip() for c in ln.strip("|").split("|")] for ln in md.splitlines()
               if ln.startswith("| track_travel |")]
    assert len(rows_md) >= 3  # the mechanism's table, the per-joint table, the checks
    for cells in rows_md:
        if len(cells) == len(AXIS_HEAD):  # the mechanism's table: travel, speed, force
            joint_side = cells[2:8]
        elif len(cells) == 12:  # the per-joint table: peak and RMS force, peak speed
            joint_side = cells[1:4]
        elif cells[1].startswith("motor"):
            continue  # a motor check: the motor turns, N m and rpm are its units
        else:  # a joint-side check: used and limit
            joint_side = cells[2:4]
        for c in joint_side:
            assert "deg" not in c and "N m" not in c and "rad" not in c, cells
    import csv

    rows = {r["joint"]: r for r in csv.DictReader(open(run.path / "sizing.csv"))}
    tr = rows["track_travel"]
    assert tr["peak_torque_nm"] == "" and float(tr["peak_force_n"]) > 0
    assert tr["speed_limit_rad_s"] == "" and float(tr["speed_limit_m_s"]) > 0
    assert rows["j1"]["peak_force_n"] == "" and float(rows["j1"]["peak_torque_nm"]) > 0

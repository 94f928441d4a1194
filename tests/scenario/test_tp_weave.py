"""FANUC TP weaving (issue 25): ``Weave Sine[n]`` ... ``Weave End`` read and written.

The figures are measured on the planned motion (no dynamics): the tool point is the forward
kinematics of the planned joint path, sampled here, and the weave's amplitude and frequency
come from numpy (half the peak-to-peak of the lateral offset from the programmed line, and an
FFT peak) against the numbers written in the program and its weave table.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from support.limits import run_limited

from sim.errors import ScenarioError
from sim.scenario import load_scenario
from sim.simulation.compile import build
from sim.simulation.motion import build_motion, check_motion_limits

SCENARIO = """name = "{name}"
description = "TP weave test"
robot = "lrmate200ic5l"
tool = "mig_torch"
program = "{program}"
"""


def position(k: int, x: float, y: float, z: float) -> str:
    """A Cartesian /POS entry in UF 0, UT 1, the torch pointing down (W = 180 deg)."""
    return (f"P[{k}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n"
            f"\tX = {x:10.3f}  mm,\tY = {y:10.3f}  mm,\tZ = {z:10.3f}  mm,\n"
            "\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg\n};")


#: The programmed points (frame 0, mm): above the start, the start, and three weld legs.
POINTS = {1: (450, -50, 50), 2: (450, -50, 0), 3: (450, 50, 0), 4: (500, 50, 0),
          5: (500, -30, 0)}

#: A hand-written program: P[2] -> P[3] weaves with schedule 1 of the table, P[3] -> P[4]
#: does not weave, P[4] -> P[5] weaves with the values written in the instruction.
PROGRAM = """/PROG  WEAVE1
/ATTR
COMMENT\t\t= "weave";
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:J P[1] 50% FINE    ;
   4:L P[2] 100mm/sec FINE    ;
   5:  Arc Start[1] ;
   6:  Weave Sine[1] ;
   7:L P[3] 8mm/sec FINE    ;
   8:  Weave End ;
   9:L P[4] 8mm/sec FINE    ;
  10:  Weave Sine[2.5Hz,1.0mm,0.000s,0.000s] ;
  11:L P[5] 8mm/sec FINE    ;
  12:  Weave End[1] ;
  13:  Arc End[1] ;
/POS
""" + "\n".join(position(k, *p) for k, p in POINTS.items()) + "\n/END\n"

#: Its weave table: schedule 1 is the issue's L-bracket weave (2 mm at 1.5 Hz).
TABLE = """[weave_schedules.1]
frequency_hz = 1.5
amplitude_mm = 2.0
dwell_right_s = 0.0
dwell_left_s = 0.0

[weave_schedules.7]
frequency_hz = 3.0
amplitude_mm = 1.0
"""


def write_program(root: Path, program: str = PROGRAM, table: str | None = TABLE) -> Path:
    (root / "w.ls").write_text(program)
    if table is not None:
        (root / "w.weave.toml").write_text(table)
    (root / "s.toml").write_text(SCENARIO.format(name="tp_weave", program="w.ls"))
    return root / "s.toml"


def plan(path: Path):
    scenario = load_scenario(path)
    built = build(scenario)
    motion = build_motion(scenario, built.context)
    check_motion_limits(scenario, motion)
    return scenario, built, motion


def tool_points(built, motion, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tool positions (m) and rotations of the planned joint path at times ``t``, frame 0."""
    kin = built.context.kinematics
    T = np.array([kin.fk(q) for q in motion.at(t).q])
    return T[:, :3, 3], T[:, :3, :3]


def fft_peak_hz(t: np.ndarray, y: np.ndarray) -> float:
    """Dominant frequency of uniform samples ``y(t)``: the peak of the Hann-windowed, 16x
    zero-padded spectrum, refined by a parabola through the log magnitudes around it."""
    dt = t[1] - t[0]
    z = (y - y.mean()) * np.hanning(len(y))
    n = 1 << int(np.ceil(np.log2(16 * len(y))))
    mag = np.abs(np.fft.rfft(z, n))
    k = int(np.argmax(mag[1:])) + 1
    a, b, c = np.log(mag[k - 1:k + 2])
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) / (n * dt)


def lateral_offsets(built, motion, phase: str, a: tuple, b: tuple, dt: float = 0.005,
                    trim: float = 1.5) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples of a phase away from its fades (``trim`` s at each end): times, the tool's
    offset across the line a -> b in the horizontal plane (the plane normal to the vertical
    torch, m), and its height above the line (m)."""
    pm = next(p for p in motion.phases if p.name == phase)
    t = np.arange(pm.t0 + trim, pm.t1 - trim, dt)
    p, _ = tool_points(built, motion, t)
    a, b = np.array(a) * 1e-3, np.array(b) * 1e-3
    u = (b - a) / np.linalg.norm(b - a)
    across = np.cross([0.0, 0.0, 1.0], u)
    return t, (p - a) @ across, p[:, 2] - a[2]


@pytest.fixture(scope="module")
def hand_written(tmp_path_factory):
    root = tmp_path_factory.mktemp("tpweave")
    return plan(write_program(root))


def test_weave_sine_takes_its_schedules_amplitude_and_frequency(hand_written):
    """``Weave Sine[1]`` (2 mm, 1.5 Hz in w.weave.toml) and ``Weave Sine[2.5Hz,1.0mm,..]``:
    measured on the planned tool path, each woven leg's lateral offset has the schedule's
    amplitude (1 %) and frequency (0.5 %), centred on the programmed line (0.02 mm) with no
    offset along the torch axis; the leg after ``Weave End`` does not weave (0.005 mm)."""
    scenario, built, motion = hand_written
    names = [pm.name for pm in motion.phases]
    assert names == ["line007_J", "line008_L", "line011_L", "line013_L", "line015_L"]
    for phase, (a, b), amp, freq in (("line011_L", (2, 3), 2.0e-3, 1.5),
                                     ("line015_L", (4, 5), 1.0e-3, 2.5)):
        t, lat, up = lateral_offsets(built, motion, phase, POINTS[a], POINTS[b])
        assert (lat.max() - lat.min()) / 2 == pytest.approx(amp, rel=0.01), phase
        assert fft_peak_hz(t, lat) == pytest.approx(freq, rel=0.005), phase
        cycles = int((t[-1] - t[0]) * freq)
        whole = t <= t[0] + cycles / freq
        assert abs(lat[whole].mean()) < 0.02e-3, phase
        assert np.abs(up).max() < 0.01e-3, phase
    _, lat, _ = lateral_offsets(built, motion, "line013_L", POINTS[3], POINTS[4], trim=0.0)
    assert np.abs(lat).max() < 0.005e-3
    # every FINE point is reached
    for pm, k in zip(motion.phases[1:], (2, 3, 4, 5), strict=True):
        p, _ = tool_points(built, motion, np.array([pm.t1]))
        assert np.linalg.norm(p[0] - np.array(POINTS[k]) * 1e-3) < 0.01e-3, pm.name
    assert not scenario.program_warnings


def weave_rt_scenario() -> str:
    """A weld with two weaves: a line (sine 2 mm at 1.5 Hz, 0.05 s dwells) and an arc (circle,
    1.5 mm at 2 Hz)."""
    return """name = "weave_rt"
description = "weaving round trip"
robot = "lrmate200ic5l"
tool = "mig_torch"

[[phases]]
name = "approach"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 10, -10, 0, -90, 0]]
to_mm = [450.0, -50.0, 0.0]
euler_zyx_deg = [0.0, 180.0, 0.0]

[[phases]]
name = "weld"
kind = "linear"
to_mm = [450.0, 30.0, 0.0]
speed_mm_s = 8.0
[phases.weave]
pattern = "sine"
amplitude_mm = 2.0
frequency_hz = 1.5
dwell_s = 0.05

[[phases]]
name = "arc"
kind = "circular"
center_mm = [500.0, 30.0, 0.0]
axis = [0.0, 0.0, 1.0]
sweep_deg = -90.0
speed_mm_s = 10.0
orientation = "keep"
[phases.weave]
pattern = "circle"
amplitude_mm = 1.5
frequency_hz = 2.0

[[actions]]
action = "arc_on"
phase = "weld"
[[actions]]
action = "arc_off"
phase = "arc"
at = "end"
"""


def test_an_exported_weaving_scenario_runs_back_to_the_same_motion(tmp_path):
    """``cellsim export`` of a scenario whose line and arc weave writes Weave Sine[1] / Weave
    Circle[2] ... Weave End around them and the two schedules in prog.weave.toml; the program
    run back plans the same tool path: on each weld phase's own clock (the J move before it is
    timed differently), the tool points of the two planned joint paths agree within 0.01 mm
    and the orientations within 0.001 deg, sampled every 5 ms.

    The tolerance: the program holds positions to 0.001 mm and 0.001 deg (the J target's
    joint values), and the rounded lengths change a move's duration by under 1 ms (under
    0.01 mm of travel at these speeds); an amplitude off by 1 % (0.02 mm) or a frequency off
    by 0.1 % (0.1 mm after 15 cycles) is outside it."""
    (tmp_path / "s.toml").write_text(weave_rt_scenario())
    r = run_limited([sys.executable, "-m", "sim", "export", str(tmp_path / "s.toml"),
                        "--out", str(tmp_path / "prog.ls")], capture_output=True, text=True,
                       cpu_s=300)
    assert r.returncode == 0, r.stderr
    assert "prog.weave.toml" in r.stdout and "note" not in r.stdout, r.stdout
    text = (tmp_path / "prog.ls").read_text()
    assert "Weave Sine[1]" in text and "Weave Circle[2]" in text and "Weave End[2]" in text
    (tmp_path / "back.toml").write_text(SCENARIO.format(name="back", program="prog.ls"))
    _, built_o, orig = plan(tmp_path / "s.toml")
    _, built_b, back = plan(tmp_path / "back.toml")
    assert [pm.kind for pm in back.phases] == ["joint", "linear", "circular"]
    for po, pb in zip(orig.phases[1:], back.phases[1:], strict=True):
        assert pb.t1 - pb.t0 == pytest.approx(po.t1 - po.t0, abs=1e-3), po.name
        tau = np.arange(0.0, min(po.t1 - po.t0, pb.t1 - pb.t0), 0.005)
        p_o, R_o = tool_points(built_o, orig, po.t0 + tau)
        p_b, R_b = tool_points(built_b, back, pb.t0 + tau)
        assert np.linalg.norm(p_o - p_b, axis=1).max() < 0.01e-3, po.name
        cos = (np.einsum("nij,nij->n", R_o, R_b) - 1.0) / 2.0
        assert np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max() < 1e-3, po.name
    # the comparison is not between two straight paths: the run-back line weaves 2 mm
    _, lat, _ = lateral_offsets(built_b, back, back.phases[1].name, (450, -50, 0), (450, 30, 0))
    assert (lat.max() - lat.min()) / 2 == pytest.approx(2e-3, rel=0.01)
    acts = [a for _, a in back.actions]
    assert acts == ["arc_on", "arc_off"]


def test_export_refuses_to_replace_a_weave_table(tmp_path):
    (tmp_path / "s.toml").write_text(weave_rt_scenario())
    (tmp_path / "prog.weave.toml").write_text("mine")
    from sim.pipeline.export import write_program as export

    with pytest.raises(ScenarioError, match="prog.weave.toml: exists"):
        export(load_scenario(tmp_path / "s.toml"), tmp_path / "prog.ls")
    assert (tmp_path / "prog.weave.toml").read_text() == "mine"
    assert not (tmp_path / "prog.ls").exists()


BAD = {
    "unknown schedule": (lambda p, t: (p.replace("Weave Sine[1]", "Weave Sine[3]"), t),
                         r"w\.ls: line 10: Weave Sine\[3\]: no weave schedule 3 in "
                         r"w\.weave\.toml \(it has 1, 7\)"),
    "no table": (lambda p, t: (p, None),
                 r"w\.ls: line 10: Weave Sine\[1\]: no weave table w\.weave\.toml"),
    "unequal dwells": (lambda p, t: (p.replace("0.000s,0.000s", "0.100s,0.050s"), t),
                       r"w\.ls: line 14: Weave Sine: right dwell 0\.1 s and left dwell 0\.05 s"),
    "register schedule": (lambda p, t: (p.replace("Weave Sine[1]", "Weave Sine[R[1]]"), t),
                          r"w\.ls: line 10: Weave Sine\[R\[1\]\]: a register schedule"),
    "three values": (lambda p, t: (p.replace("2.5Hz,1.0mm,0.000s,0.000s", "2.5,1.0,0"), t),
                     r"w\.ls: line 14: .*4 values .* got 3"),
    "a unit out of place": (lambda p, t: (p.replace("2.5Hz,1.0mm", "2.5mm,1.0Hz"), t),
                            r"w\.ls: line 14: .*the frequency is a number in Hz"),
    "dwell too long": (lambda p, t: (p, t.replace("dwell_left_s = 0.0", "dwell_left_s = 0.3")
                                     .replace("dwell_right_s = 0.0", "dwell_right_s = 0.3")),
                       r"w\.ls: line 10: Weave Sine\[1\]: weave\.dwell"),
    "a bad table key": (lambda p, t: (p, t.replace("amplitude_mm = 2.0", "amplitude_mm = -2.0")),
                        r"w\.weave\.toml: weave_schedules\.1\.amplitude_mm: .*greater than 0"),
    "a misspelt table key": (lambda p, t: (p, t.replace("frequency_hz = 3.0", "freq_hz = 3.0")),
                             r"w\.weave\.toml: weave_schedules\.7\.freq_hz: unknown key"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_weave_is_one_line_naming_the_file_and_line(case, tmp_path):
    edit, needle = BAD[case]
    program, table = edit(PROGRAM, TABLE)
    path = write_program(tmp_path, program, table)
    with pytest.raises(ScenarioError, match=needle) as exc:
        plan(path)
    assert "\n" not in str(exc.value)


def test_an_unknown_schedule_exits_2_with_one_line(tmp_path):
    path = write_program(tmp_path, PROGRAM.replace("Weave Sine[1]", "Weave Sine[3]"))
    r = run_limited([sys.executable, "-m", "sim", "check", str(path)], capture_output=True,
                       text=True, cpu_s=300)
    assert r.returncode == 2, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "w.ls: line 10" in lines[0] and "schedule 3" in lines[0], lines


def test_weave_patterns_cellsim_does_not_run_and_j_moves_are_warnings(tmp_path):
    """A J move between ``Weave Sine[1]`` and its end: a warning with its line, and it runs as
    a J move; ``Weave Figure 8[1]``: a warning with its line, and the next leg does not
    weave."""
    program = PROGRAM.replace("   8:  Weave End ;\n", "").replace(
        "   9:L P[4] 8mm/sec FINE", "   9:J P[4] 20% FINE").replace(
        "Weave Sine[2.5Hz,1.0mm,0.000s,0.000s]", "Weave Figure 8[1]")
    scenario = load_scenario(write_program(tmp_path, program))
    assert scenario.program_warnings == (
        "w.ls: line 12: a J move between Weave and Weave End does not weave",
        "w.ls: line 13: Weave Figure 8[1]: pattern not simulated (cellsim runs Sine, Circle); "
        "the moves until Weave End do not weave")
    weaves = {ph.name: getattr(ph, "weave", None) for ph in scenario.phases}
    assert weaves["line011_L"].amplitude == pytest.approx(2e-3)
    assert weaves["line014_L"] is None and weaves["line012_J"] is None

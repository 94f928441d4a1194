"""Scenario loading and validation (issue 2 section 3): shipped files, and every kind of bad
input giving one line that names the file and the key."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sim.core.resources import shipped_scenarios
from sim.errors import CellsimError, ScenarioError, UnknownNameError
from sim.scenario import (
    ActionSpec,
    CircularPhaseSpec,
    DriveOverrideSpec,
    ExpectSpec,
    HoldPhaseSpec,
    JointPhaseSpec,
    LinearPhaseSpec,
    ScenarioSpec,
    SimulationSpec,
    SizingSpec,
    VideoSpec,
    WeaveSpec,
    load_scenario,
    parse_scenario,
)

SHIPPED = shipped_scenarios()
DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario-format.md"

GOOD = """
name = "t"
description = "test"
robot = "robot_5r"
[[phases]]
name = "a"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [[0,0,0,0,0],[1,2,3,4,5],[2,4,6,8,10]]
"""


def test_required_scenarios_ship():
    assert {"bugnar_5r_phase1", "kacso_lrmate100ib_sequence1"} <= set(SHIPPED)


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_scenario_loads_with_consistent_phases(name):
    from sim.scenario import JointPhase

    sc = load_scenario(name)
    assert sc.name == name, "a shipped scenario's name must equal its file name"
    for prev, phase in zip(sc.phases, sc.phases[1:]):
        if (isinstance(prev, JointPhase) and isinstance(phase, JointPhase)
                and prev.times is not None and phase.times is not None and prev.target is None):
            assert phase.t0 == pytest.approx(prev.t1)
            np.testing.assert_allclose(phase.q[0], prev.q[-1], atol=1e-12)
    for phase in sc.phases:
        if isinstance(phase, JointPhase):
            assert phase.q.shape == (phase.durations.size + 1, sc.robot.n_joints)


def test_bugnar_phase1_is_seed001_table1_in_radians():
    """Seed 001 Table 1 (the values chosen where eq. 3-4 disagree: q4 = -14.06, +1.40)."""
    ph = load_scenario("bugnar_5r_phase1").phases[0]
    np.testing.assert_allclose(ph.times, [0, 3.33, 6.67, 10])
    np.testing.assert_allclose(np.rad2deg(ph.q[:, 3]), [0, -7.03, -14.06, 1.40])
    np.testing.assert_allclose(np.rad2deg(ph.q[3]), [-15.2, 116.82, -1.3, 1.4, -0.206])


def test_kacso_sequence1_is_seed000_table3():
    """Seed 000 Table 3 at 0.208 s segments; joints 1 and 5 at zero."""
    ph = load_scenario("kacso_lrmate100ib_sequence1").phases[0]
    np.testing.assert_allclose(ph.times, [0, 0.208, 0.416, 0.624])
    np.testing.assert_allclose(np.rad2deg(ph.q[:, 1]), [0, 28.79, 57.59, 86.38])
    assert np.all(ph.q[:, [0, 4]] == 0)


def _err(text: str) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="x.toml")
    msg = str(info.value)
    assert "\n" not in msg, "errors are one line"
    assert msg.startswith("x.toml: ")
    return msg


@pytest.mark.parametrize("mutation, key, fragment", [
    (("time_s = [0.0, 1.0, 2.0]", "time_s = [2.0]"), "phases[0].time_s", "at least 2"),
    (("time_s = [0.0, 1.0, 2.0]", "time_s = [0.0, 1.0, 1.0]"), "phases[0].time_s", "must increase"),
    (("time_s = [0.0, 1.0, 2.0]", "time_s = [0.0, 3.0, 2.0]"), "phases[0].time_s", "index 2"),
    (("[1,2,3,4,5]", "[1,2,3,4]"), "phases[0].joints_deg[1]", "5 joints"),
    (("[1,2,3,4,5]", "[1,2,nan,4,5]"), "phases[0].joints_deg[1][2]", "finite"),
    (("[1,2,3,4,5]", "[1,2,inf,4,5]"), "phases[0].joints_deg[1][2]", "finite"),
    (("[1,2,3,4,5]", '[1,2,"3",4,5]'), "phases[0].joints_deg[1][2]", "must be a number"),
    (('planner = "434"', 'planner = "4343"'), "phases[0].planner", "'434' or '546'"),
    (('robot = "robot_5r"', 'robot = "robot5r"'), "robot", "did you mean 'robot_5r'"),
    (('time_s =', 'tim_s ='), "phases[0].tim_s", "did you mean 'time_s'"),
    (('description = "test"', ''), "description", "missing"),
    (("joints_deg = [[0,0,0,0,0],[1,2,3,4,5],[2,4,6,8,10]]",
      "joints_deg = [[0,0,0,0,0],[1,2,3,4,5]]"), "phases[0].joints_deg", "one row per time"),
    (('planner = "434"', 'planner = "434"\nstart_jerk_deg_s3 = [0,0,0,0,0]'),
     "phases[0].start_jerk_deg_s3", "no jerk"),
    (('planner = "434"', 'planner = "434"\nstart_velocity_deg_s = [0,0]'),
     "phases[0].start_velocity_deg_s", "5 joints"),
    (('joints_deg', 'joints_rad = [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]\njoints_deg'),
     "phases[0]", "exactly one of joints_deg, joints_rad or joints_maker_deg"),
])
def test_bad_input_names_the_key(mutation, key, fragment):
    old, new = mutation
    assert old in GOOD
    msg = _err(GOOD.replace(old, new, 1))
    assert f" {key}" in msg or f"{key}:" in msg, msg
    assert fragment in msg, msg


def test_malformed_toml_is_one_line():
    msg = _err(GOOD.replace('name = "a"', 'name = "a'))
    assert "invalid TOML" in msg


def test_phases_must_meet():
    second = """
[[phases]]
name = "b"
planner = "546"
time_s = [2.5, 3.0, 4.0]
joints_deg = [[2,4,6,8,10],[2,4,6,8,10],[0,0,0,0,0]]
"""
    msg = _err(GOOD + second)
    assert "phases[1].time_s" in msg and "ends at 2 s" in msg
    msg = _err(GOOD + second.replace("2.5", "2.0").replace("[2,4,6,8,10],[2", "[2,4,6,9,10],[2", 1))
    assert "joint j4" in msg and "phases[1]" in msg


def test_duplicate_phase_names():
    dup = GOOD + GOOD[GOOD.index("[[phases]]"):].replace("time_s = [0.0, 1.0, 2.0]",
                                                          "time_s = [2.0, 3.0, 4.0]")
    dup = dup.replace("joints_deg = [[0,0,0,0,0],[1,2,3,4,5],[2,4,6,8,10]]",
                      "joints_deg = [[2,4,6,8,10],[1,2,3,4,5],[0,0,0,0,0]]")
    dup = dup.replace("[[0,0,0,0,0],[1,2,3,4,5],[2,4,6,8,10]]", "[[0,0,0,0,0],[1,2,3,4,5],[2,4,6,8,10]]")
    msg = _err(dup)
    assert "phases[1].name" in msg and "already" in msg


def test_unknown_scenario_lists_shipped():
    with pytest.raises(UnknownNameError) as info:
        load_scenario("bugnar_5r_phase")
    assert "did you mean 'bugnar_5r_phase1'" in str(info.value)
    assert "kacso_lrmate100ib_sequence1" in str(info.value)


def test_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match="no such scenario file"):
        load_scenario(tmp_path / "nope.toml")


def _mutations():
    """Random edits of a shipped scenario's parsed TOML: delete, retype or rename a key."""
    values = st.one_of(st.none(), st.booleans(), st.integers(-5, 5), st.floats(allow_nan=True),
                       st.text(max_size=5), st.lists(st.floats(allow_nan=True), max_size=6),
                       st.lists(st.lists(st.integers(-200, 200), max_size=6), max_size=5))
    return st.tuples(st.sampled_from(sorted(SHIPPED)), st.integers(0, 10_000),
                     st.sampled_from(["delete", "set", "rename"]), values, st.text(max_size=8))


def _dump_toml(obj, prefix=""):
    """A tiny TOML writer for the mutation test (tables, arrays of tables, scalars, arrays)."""
    import json
    lines, tables = [], []
    for k, v in obj.items():
        if isinstance(v, dict):
            tables.append((k, v, False))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            tables.append((k, v, True))
        else:
            lines.append(f"{json.dumps(k)} = {_toml_value(v)}")
    out = "\n".join(lines) + "\n"
    for k, v, is_array in tables:
        name = f"{prefix}{json.dumps(k)}"
        for item in (v if is_array else [v]):
            out += f"\n[{'[' if is_array else ''}{name}{']' if is_array else ''}]\n"
            out += _dump_toml(item, prefix=name + ".")
    return out


def _toml_value(v):
    import json
    import math
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v == math.inf else "-inf" if v == -math.inf
                                            else repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    return '""'


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_mutations())
def test_random_mutations_never_traceback(mutation):
    """Property test: a mutated shipped scenario loads, or fails with a one-line CellsimError."""
    name, pick, action, value, new_key = mutation
    raw = tomllib.loads(SHIPPED[name].read_text())
    # collect every (container, key) pair of the document
    slots = []

    def walk(node):
        if isinstance(node, dict):
            for k in list(node):
                slots.append((node, k))
                walk(node[k])
        elif isinstance(node, list):
            for i in range(len(node)):
                slots.append((node, i))
                walk(node[i])

    walk(raw)
    container, key = slots[pick % len(slots)]
    if action == "delete":
        del container[key]
    elif action == "set" or not isinstance(container, dict):
        if value is None:
            value = ""
        container[key] = value
    else:
        container[new_key or "x"] = container.pop(key)
    text = _dump_toml(raw)
    try:
        parse_scenario(text, source="m.toml")
    except CellsimError as exc:
        assert "\n" not in str(exc)
        assert str(exc).startswith("m.toml")


def test_format_reference_documents_every_key():
    """docs/scenario-format.md and the declared schema name the same keys."""
    doc = DOC.read_text()
    documented = set(re.findall(r"`([a-z][a-z0-9_]*)`", doc))
    models = (ScenarioSpec, JointPhaseSpec, LinearPhaseSpec, CircularPhaseSpec, HoldPhaseSpec,
              ActionSpec, SimulationSpec, VideoSpec, DriveOverrideSpec, SizingSpec, WeaveSpec,
              ExpectSpec)
    declared = set()
    for model in models:
        for key in model.model_fields:
            assert key in documented, f"{model.__name__}.{key} is not in {DOC.name}"
            declared.add(key)
    table_keys = set(re.findall(r"^\| `([a-z][a-z0-9_]*)`", doc, flags=re.M))
    table_keys |= set(re.findall(r"^\| `[a-z0-9_]+` / `([a-z][a-z0-9_]*)`", doc, flags=re.M))
    assert table_keys <= declared, f"documented but not accepted: {table_keys - declared}"


CYCLE = GOOD + """
[[phases]]
name = "line"
kind = "linear"
to_mm = [600.0, 0.0, 100.0]
speed_mm_s = 10.0

[[phases]]
name = "arc"
kind = "circular"
via_mm = [650.0, 50.0, 100.0]
to_mm = [700.0, 0.0, 100.0]
speed_mm_s = 10.0

[[phases]]
name = "wait"
kind = "hold"
duration_s = 0.5

[[phases]]
name = "back"
planner = "546"
durations_s = [1.0, 1.0]
joints_deg = [[1,1,1,1,1],[0,0,0,0,0]]

[drives.j2]
gear_ratio = 120.0
"""


def test_full_cycle_parses_in_si_units():
    sc = parse_scenario(CYCLE, source="c.toml")
    kinds = [p.kind for p in sc.phases]
    assert kinds == ["joint", "linear", "circular", "hold", "joint"]
    line, arc, hold, back = sc.phases[1:]
    np.testing.assert_allclose(line.to, [0.6, 0.0, 0.1])
    assert line.speed == pytest.approx(0.01) and line.orientation == "keep"
    assert arc.orientation == "follow" and arc.via is not None
    assert hold.duration == 0.5
    assert back.times is None and back.starts_from_previous
    placed = back.with_start(12.0, np.zeros(5))
    np.testing.assert_allclose(placed.times, [12.0, 13.0, 14.0])
    assert sc.drives == {"j2": {"gear_ratio": 120.0}}


@pytest.mark.parametrize("old, new, key, fragment", [
    ('kind = "hold"\nduration_s = 0.5', 'kind = "hold"\nduration_s = -1', "phases[3].duration_s",
     "greater than 0"),
    ('kind = "hold"', 'kind = "hodl"', "phases[3].kind", "'hold'"),
    ("speed_mm_s = 10.0\n\n[[phases]]\nname = \"arc\"", "speed_mm_s = 0\n\n[[phases]]\nname = \"arc\"",
     "phases[1].speed_mm_s", "greater than 0"),
    ("to_mm = [600.0, 0.0, 100.0]", "to_mm = [600.0, 0.0]", "phases[1].to_mm", "at least 3"),
    ("to_mm = [600.0, 0.0, 100.0]", 'seam = "s1"\nto_mm = [600.0, 0.0, 100.0]', "phases[1]",
     "exactly one of seam, to_mm or to_seam"),
    ('via_mm = [650.0, 50.0, 100.0]\n', '', "phases[2]", "give seam, or via_mm"),
    ("durations_s = [1.0, 1.0]", "durations_s = [1.0, 0.0]", "phases[4].durations_s[1]",
     "positive"),
    ("joints_deg = [[1,1,1,1,1],[0,0,0,0,0]]", "joints_deg = [[0,0,0,0,0]]", "phases[4].joints_deg",
     "one row per segment end"),
    ("durations_s = [1.0, 1.0]", "time_s = [9.0, 10.0, 11.0]", "phases[4].time_s",
     "give durations_s"),
    ("[drives.j2]", "[drives.j9]", "drives.j9", "unknown joint"),
    ("gear_ratio = 120.0", "gear_ration = 120.0", "drives.j2.gear_ration",
     "did you mean 'gear_ratio'"),
])
def test_cycle_bad_input_names_the_key(old, new, key, fragment):
    assert old in CYCLE
    msg = _err(CYCLE.replace(old, new, 1))
    assert key in msg and fragment in msg, msg


@pytest.mark.parametrize("extra, fragment", [
    ('\n[[actions]]\naction = "arc_on"\nphase = "line"\n', "needs a torch tool"),
    ('\n[[actions]]\naction = "suction_on"\ntime_s = 1.0\n', "needs a gripper tool"),
    ('\n[[actions]]\naction = "arc_on"\n', "exactly one of time_s or phase"),
    ('\n[[actions]]\naction = "weld"\ntime_s = 1.0\n', "actions[0].action"),
])
def test_action_errors(extra, fragment):
    # actions come after the tables in TOML; put them before [drives.j2]
    text = CYCLE.replace("[drives.j2]", extra + "\n[drives.j2]")
    msg = _err(text)
    assert fragment in msg, msg


@pytest.mark.parametrize("table, key, fragment", [
    ('verdict = "fail"\nfailed_checks = ["speed j2"]', "expect.reason", "say why"),
    ('verdict = "fail"\nreason = "r"', "expect.failed_checks", "name the checks"),
    ('failed_checks = ["speed j2"]\nreason = "r"', "expect.verdict", 'verdict = "fail"'),
    ('check_findings = ["limit"]', "expect.reason", "say why"),
    ('check_findings = ["limits"]\nreason = "r"', "expect.check_findings[0]", "'limit'"),
    ('failed_checks = ["speed"]\nverdict = "fail"\nreason = "r"', "expect.failed_checks[0]",
     "pattern"),
    ('verdict = "failed"', "expect.verdict", "'pass' or 'fail'"),
    ('verdikt = "fail"', "expect.verdikt", "did you mean 'verdict'"),
])
def test_expect_errors_name_the_key(table, key, fragment):
    """[expect] is consistent: a failure names its checks and its reason (one line, the key)."""
    msg = _err(GOOD.replace("[[phases]]", f"[expect]\n{table}\n\n[[phases]]", 1))
    assert f" {key}:" in msg, msg
    assert fragment in msg, msg


def test_expect_defaults_to_a_passing_run_and_is_carried_on_the_scenario():
    assert parse_scenario(GOOD).expect == ExpectSpec(verdict="pass")
    sc = parse_scenario(GOOD.replace("[[phases]]", '[expect]\nverdict = "fail"\nfailed_checks = '
                                     '["speed j2"]\nreason = "as published"\n\n[[phases]]', 1))
    assert (sc.expect.verdict, sc.expect.failed_checks, sc.expect.reason) == (
        "fail", ["speed j2"], "as published")


def test_action_unknown_phase_suggests():
    text = CYCLE.replace("[drives.j2]", '[[actions]]\naction = "arc_on"\nphase = "lin"\n\n[drives.j2]')
    text = text.replace('robot = "robot_5r"', 'robot = "robot_5r"')
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="c.toml")
    # no tool: the tool check or the phase check fires, both one line naming actions[0]
    assert "actions[0]" in str(info.value)


def test_single_segment_gets_the_joint_space_midpoint():
    """durations_s = [T] with one row: the midpoint becomes the via point (4-4)."""
    text = GOOD + """
[[phases]]
name = "b"
planner = "434"
durations_s = [2.0]
joints_deg = [[0,0,0,0,0]]
"""
    sc = parse_scenario(text, source="s.toml")
    placed = sc.phases[1].with_start(2.0, np.deg2rad([2, 4, 6, 8, 10]))
    np.testing.assert_allclose(placed.times, [2.0, 3.0, 4.0])
    np.testing.assert_allclose(np.rad2deg(placed.q[1]), [1, 2, 3, 4, 5])


def test_pose_target_rows():
    """With to_mm the end knot comes from IK: joints_deg lists the via points only."""
    text = GOOD + """
[[phases]]
name = "b"
planner = "434"
durations_s = [1.0, 1.0]
joints_deg = [[1,1,1,1,1]]
to_mm = [600.0, 0.0, 0.0]
"""
    sc = parse_scenario(text, source="s.toml")
    ph = sc.phases[1]
    assert ph.target is not None and ph.q.shape == (3, 5)
    assert np.isnan(ph.q[0]).all() and np.isnan(ph.q[2]).all()
    bad = text.replace("joints_deg = [[1,1,1,1,1]]", "joints_deg = [[1,1,1,1,1],[2,2,2,2,2]]")
    msg = _err(bad)
    assert "phases[1].joints_deg" in msg and "pose target" in msg


@settings(max_examples=40, deadline=None, derandomize=True)
@given(times=st.lists(st.one_of(st.floats(-1e308, 1e308), st.sampled_from([1e300, -1e300,
                                                                            1e6, 1e-300])),
                      min_size=3, max_size=3).map(sorted))
def test_knot_times_at_any_scale_plan_or_are_one_line_without_numpy_warnings(times):
    """Issue 31: a knot time of 1e300 s printed numpy's overflow warnings before its error.
    Whatever the times, the scenario plans or is refused in one line naming the key (the
    bounds, checked here on the file's numbers: segments of MIN_SEGMENT_S to MAX_TIME_S,
    knot times within MAX_TIME_S of 0), and numpy warns of nothing (warnings are errors)."""
    import warnings

    from sim.scenario.phases import MAX_TIME_S, MIN_SEGMENT_S
    from sim.simulation.motion import build_motion

    text = GOOD.replace("time_s = [0.0, 1.0, 2.0]", f"time_s = {times!r}")
    steps = np.diff(times)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if np.any(steps <= 0):
            assert "must increase" in _err(text)
        elif not (np.all(steps >= MIN_SEGMENT_S) and np.all(steps <= MAX_TIME_S)
                  and np.all(np.abs(times) <= MAX_TIME_S)):
            assert "phases[0].time_s[" in _err(text)
        else:
            build_motion(parse_scenario(text, source="x.toml"), None)


@pytest.mark.parametrize("line, key, needle", [
    ("width = 100000", "video.width", "less than or equal to 8192"),
    ("height = 8", "video.height", "greater than or equal to 16"),
    ("width = 641", "video.width", "must be even for H.264 yuv420p, got 641"),
    ("cameras = []", "video.cameras", "at least 1 item"),
])
def test_a_bad_video_table_is_refused_when_the_scenario_is_read(tmp_path, line, key, needle):
    """The scenario's [video] is held to the command line's rules when it is read, so the
    error names the file and key and `cellsim check` sees it (a trial's width = 100000 said
    only "video width must be ..." at run time, and check passed it; cameras = [] filmed the
    overview camera)."""
    from sim.errors import ScenarioError
    from sim.render.frames import MAX_SIDE
    from sim.scenario import load_scenario

    assert MAX_SIDE == 8192  # the schema's bound (sim/scenario/schema.py VideoSide)
    from sim.core.resources import scenarios_dir

    text = (scenarios_dir() / "bugnar_5r_phase1.toml").read_text()
    assert "[video]" not in text
    path = tmp_path / "v.toml"
    path.write_text(text + f"\n[video]\n{line}\n")
    with pytest.raises(ScenarioError, match=rf"v\.toml: {key}: .*{needle}"):
        load_scenario(path)


@pytest.mark.parametrize("value", ["1e308", "10000.5"])
def test_a_tool_point_speed_past_10_m_s_is_refused_in_one_line(tmp_path, value):
    """speed_mm_s = 1e308 overflowed the planner (a stray numpy warning, then "knot times must
    be strictly increasing"): at most MAX_TCP_SPEED_MM_S, named with its key."""
    from sim.core.resources import scenarios_dir
    from sim.errors import ScenarioError
    from sim.scenario import load_scenario

    text = (scenarios_dir() / "lrmate200ic_weld_plate.toml").read_text()
    head, _, rest = text.partition("speed_mm_s = 8.0")
    path = tmp_path / "fast.toml"
    path.write_text(head + f"speed_mm_s = {value}" + rest)
    phase = head.count("[[phases]]") - 1
    with pytest.raises(ScenarioError, match=rf"fast\.toml: phases\[{phase}\]\.speed_mm_s: must "
                       "be less than or equal to 10000"):
        load_scenario(path)

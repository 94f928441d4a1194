"""A scenario's ``[drives.<joint>]`` override takes a robot file's ranges (docs/robot-format.md):
a gear ratio of 1e308 made an OverflowError traceback in the model's armature (exit 3) and a
peak torque of 1e308 an internal error in the check model, where the same value in a robot or
mechanism file is one line and exit 2 (found by a new-user trial). Specification, on generated
values of every key: a value outside its range is refused at load with one line naming
``drives.j2.<key>``, its range and its value; the range's own ends are taken; the Python API's
:func:`sim.robots.drives.apply_overrides` refuses the same values."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cli import main
from sim.core.tomlschema import EFFICIENCY, GEAR_RATIO, ROTOR_INERTIA_KG_M2, SPEED_RPM, TORQUE_NM
from sim.errors import ScenarioError
from sim.robots.drives import apply_overrides
from sim.scenario import parse_scenario

ROOT = Path(__file__).resolve().parents[2]
BASE = (ROOT / "scenarios" / "kacso_lrmate100ib_sequence1.toml").read_text()
RANGES = {"gear_ratio": GEAR_RATIO, "efficiency": EFFICIENCY,
          "rotor_inertia_kg_m2": ROTOR_INERTIA_KG_M2, "rated_torque_nm": TORQUE_NM,
          "peak_torque_nm": TORQUE_NM, "max_speed_rpm": SPEED_RPM}


def _text(key: str, value: float) -> str:
    extra = f"\n[drives.j2]\n{key} = {value!r}\n"
    if key == "rated_torque_nm" and value > 0:  # keep peak >= rated: the range is the subject
        extra += f"peak_torque_nm = {min(max(value, 1e-6), 1e6)!r}\n"
    return BASE + extra


@st.composite
def outside(draw: st.DrawFn) -> tuple[str, float]:
    key = draw(st.sampled_from(sorted(RANGES)))
    q = RANGES[key]
    above = draw(st.floats(q.hi * (1 + 1e-9), 1e308, allow_infinity=False))
    below = draw(st.floats(-1e308, q.lo * (1 - 1e-9) if q.lo > 0 else -1e-300))
    return key, draw(st.sampled_from([above, below]))


@settings(max_examples=40, deadline=None)
@given(case=outside())
def test_a_value_outside_the_robot_files_range_is_refused_naming_its_key(
        case: tuple[str, float]) -> None:
    key, value = case
    with pytest.raises(ScenarioError) as err:
        parse_scenario(_text(key, value), source="h.toml")
    msg = str(err.value)
    q = RANGES[key]
    assert f"drives.j2.{key}: must be between {q.lo:g} and {q.hi:g}" in msg, msg
    assert "\n" not in msg


@pytest.mark.parametrize("key", sorted(RANGES))
@pytest.mark.parametrize("end", ["lo", "hi"])
def test_the_ranges_own_ends_are_taken(key: str, end: str) -> None:
    q = RANGES[key]
    value = getattr(q, end)
    if key == "efficiency" or value > 0 or key == "rotor_inertia_kg_m2":
        sc = parse_scenario(_text(key, value), source="ok.toml")
        assert sc.drives["j2"][key] == value


@settings(max_examples=20, deadline=None)
@given(case=outside())
def test_the_api_refuses_the_same_values(case: tuple[str, float]) -> None:
    key, value = case
    sc = parse_scenario(BASE, source="base.toml")
    with pytest.raises(ScenarioError, match=rf"drives\.j2\.{key}: must be between"):
        apply_overrides(sc.robot.drives, {"j2": {key: value, **(
            {"peak_torque_nm": 1e6} if key == "rated_torque_nm" else {})}}, sc.robot.joints)


def test_the_trials_overflow_is_one_line_and_exit_2(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "h.toml"
    path.write_text(_text("gear_ratio", 1e308))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["cellsim: error: h.toml: drives.j2.gear_ratio: must be between 0.01 and "
                   "10000 (a gear ratio), got 1e+308"], err


def test_planted_in_range_value_is_not_refused() -> None:
    sc = parse_scenario(_text("gear_ratio", 9999.0), source="ok.toml")
    assert sc.drives["j2"]["gear_ratio"] == 9999.0

"""A failed check in words (:func:`sim.analysis.verdict.check_line`, the console's verdict
lines): its name, what it is about (its subject, else its joint), and its value against its
limit; a saturation as how far the drive's demand went over its limit (printed before as
"3.2 N m against the limit 0 N m"), a collision as its depth. Specification, on generated
checks: the value and limit appear with the check's unit, formatted as the line says; the
saturation and collision lines never name a zero limit."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis.verdict import check_line

_names = st.sampled_from(["speed", "tracking", "payload", "clearance", "joint_torque",
                          "selection_inertia_ratio", "cartesian_speed"])
_values = st.floats(0.0, 1e6, allow_nan=False)


def _check(name: str, value: float, limit: float, unit: str, joint: str = "j2",
           subject: str = "") -> dict:
    return {"name": name, "joint": joint, "subject": subject, "value": value, "limit": limit,
            "unit": unit, "pass": False, "severity": "error"}


@settings(max_examples=60, deadline=None)
@given(name=_names, value=_values, limit=_values, unit=st.sampled_from(["N m", "rad/s", "kg"]),
       subject=st.sampled_from(["", "weld_1", "tool 1 kg + payload 2 kg"]))
def test_a_check_reads_value_against_limit(name: str, value: float, limit: float, unit: str,
                                           subject: str) -> None:
    line = check_line(_check(name, value, limit, unit, subject=subject))
    who = subject or "j2"
    assert line == (f"{name} {who}: {value:.4g} {unit} against the limit {limit:.4g} {unit}")


@settings(max_examples=30, deadline=None)
@given(value=st.floats(1e-6, 1e5), unit=st.sampled_from(["N m", "N"]))
def test_a_saturation_reads_how_far_over_the_drive_limit(value: float, unit: str) -> None:
    line = check_line(_check("saturation", value, 0.0, unit, joint="j3"))
    assert line == f"saturation j3: demand up to {value:.4g} {unit} over the drive's limit"
    assert "limit 0" not in line


@settings(max_examples=20, deadline=None)
@given(value=st.floats(-1e4, -1e-3))
def test_a_failed_selection_reads_its_closest_pairs_margin(value: float) -> None:
    # it read "-83.43 % margin against the limit 0 % margin" (a new-user trial)
    subject = "j2: no pair passes; the closest, M + R, fails inertia_ratio (18.34 against 10)"
    line = check_line(_check("selection", value, 0.0, "% margin", joint="j2", subject=subject))
    assert line == f"selection {subject}; {value:.4g} % margin at its worst"
    assert "limit 0" not in line


def test_a_collision_reads_its_depth() -> None:
    line = check_line(_check("collision", 2.345, 0.0, "mm", joint="",
                             subject="robot/link_3 / fixture (weld_1)"))
    assert line == "collision robot/link_3 / fixture (weld_1): 2.3 mm deep"


def test_planted_generic_wording_for_saturation_is_caught() -> None:
    c = _check("saturation", 3.2, 0.0, "N m")
    generic = f"saturation j2: {3.2:.4g} N m against the limit {0.0:.4g} N m"
    assert check_line(c) != generic


def test_a_sweep_row_names_the_joint_of_a_check_without_subject() -> None:
    """sweep.csv's ``failed_checks``: a saturation names its joint (it read ``saturation``
    alone), a check with a subject keeps it."""
    from sim.pipeline.sweep.variants import failed_checks_text

    summary = {"checks": [_check("saturation", 3.2, 0.0, "N m", joint="j2"),
                          _check("tool_payload", 2.75, 2.04, "kg", joint="",
                                 subject="the vacuum_gripper holds 2.75 kg, rated 2.04 kg")]}
    assert failed_checks_text(summary) == (
        "saturation: j2; tool_payload: the vacuum_gripper holds 2.75 kg, rated 2.04 kg")

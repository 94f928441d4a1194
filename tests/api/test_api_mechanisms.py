"""``RunResult.mechanisms`` (issue 28): the typed form of ``summary.json``'s
``"mechanisms"``, judged against generated summaries (every field as the dict gives it, the
travel and the payload ratio recomputed here, the summary handed back unchanged) and a wrong
entry refused with one line."""

from __future__ import annotations

import copy
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sim
from sim.errors import RunFolderError

_F = st.floats(-1e4, 1e4, allow_nan=False)


@st.composite
def mechanism_entries(draw: st.DrawFn) -> dict:
    kind = draw(st.sampled_from(["turntable", "positioner", "track"]))
    axis_kind = "prismatic" if kind == "track" else "revolute"
    n = draw(st.integers(1, 3)) if kind == "positioner" else 1
    axes = {}
    for k in range(n):
        lo, hi = sorted((draw(_F), draw(_F)))
        axes[f"ax{k}"] = {"kind": axis_kind, "unit": "mm" if axis_kind == "prismatic" else "deg",
                          "min": lo, "max": hi, "max_speed": draw(st.floats(0, 1e4))}
    return {"kind": kind, "model": draw(st.from_regex(r"[a-z][a-z0-9_]{0,8}", fullmatch=True)),
            "carries": draw(st.lists(st.from_regex(r"[a-z]{1,6}", fullmatch=True), max_size=3)),
            "carried_kg": draw(st.floats(0, 2000)), "rated_payload_kg": draw(st.floats(0, 2000)),
            "axes": axes}


def _summary(mechanisms: dict) -> dict:
    return {"scenario": "s", "robot": "r", "verdict": "pass", "checks": [], "joints": ["j1"],
            "duration_s": 1.0, "mechanisms": mechanisms}


def _mismatches(result: sim.RunResult, mechanisms: dict) -> list[str]:
    """The oracle: every typed field against the dict; travel and ratio recomputed."""
    bad = [] if list(result.mechanisms) == list(mechanisms) else ["names"]
    for name, m in mechanisms.items():
        r = result.mechanisms.get(name)
        if r is None:
            bad.append(name)
            continue
        for key in ("kind", "model", "carried_kg", "rated_payload_kg"):
            if getattr(r, key) != m[key]:
                bad.append(f"{name}.{key}")
        if r.name != name or list(r.carries) != m["carries"]:
            bad.append(f"{name}.carries")
        ratio = m["carried_kg"] / m["rated_payload_kg"] if m["rated_payload_kg"] > 0 else math.inf
        if r.payload_ratio != ratio:
            bad.append(f"{name}.ratio")
        if list(r.axes) != list(m["axes"]):
            bad.append(f"{name}.axes")
            continue
        for axis, a in m["axes"].items():
            ra = r.axes[axis]
            for key in ("kind", "unit", "min", "max", "max_speed"):
                if getattr(ra, key) != a[key]:
                    bad.append(f"{axis}.{key}")
            if ra.name != axis or ra.travel != a["max"] - a["min"]:
                bad.append(f"{axis}.travel")
    return bad


@settings(max_examples=60, deadline=None)
@given(entries=st.dictionaries(st.from_regex(r"[a-z][a-z_]{0,8}", fullmatch=True),
                               mechanism_entries(), max_size=3))
def test_mechanisms_typed_from_the_summary(entries):
    summary = _summary(entries)
    before = copy.deepcopy(summary)
    result = sim.RunResult.from_summary(summary)
    assert _mismatches(result, entries) == []
    assert result.to_dict() == before  # the summary handed back unchanged


@given(entry=mechanism_entries())
@settings(max_examples=20, deadline=None)
def test_the_oracle_catches_a_planted_fault(entry):
    result = sim.RunResult.from_summary(_summary({"m": entry}))
    bad = copy.deepcopy(entry)
    bad["carried_kg"] += 1.0
    assert _mismatches(result, {"m": bad}) != []
    bad = copy.deepcopy(entry)
    first = next(iter(bad["axes"].values()))
    first["max"] += 1.0
    assert _mismatches(result, {"m": bad}) != []


def test_a_run_without_mechanisms_has_none():
    summary = _summary({})
    del summary["mechanisms"]
    assert sim.RunResult.from_summary(summary).mechanisms == {}


def test_a_wrong_axis_unit_is_one_line_naming_the_summary():
    entry = {"kind": "track", "model": "t", "carries": ["robot"], "carried_kg": 1.0,
             "rated_payload_kg": 2.0,
             "axes": {"t_travel": {"kind": "prismatic", "unit": "deg", "min": 0.0, "max": 1.0,
                                   "max_speed": 1.0}}}
    with pytest.raises(RunFolderError) as exc:
        sim.RunResult.from_summary(_summary({"t": entry}))
    assert "\n" not in str(exc.value) and "summary" in str(exc.value)
    assert "t_travel" in str(exc.value)

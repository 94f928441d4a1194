"""A speed scale ``s`` (``Scenario.scaled``, ``cellsim size --speed-scale``): the same joint
paths traversed ``s`` times faster, as the docs say ("knot times are divided by each").

The oracle is the unscaled plan itself: every phase of the scaled plan lasts ``1/s`` as long,
and the joints are where the unscaled plan has them ``s`` times later, on Cartesian moves with
their default ramps (their least duration once stayed 0.3 s: the weld plate at x1.25 took
66.373 s instead of 82.592 / 1.25 = 66.074 s, found by a new-user trial), a weave (its
frequency) and a TP program's ``sec`` move (its time). Scales are generated.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import DATA
from support.scenarios import TP_SCENARIO

from sim.scenario import load_scenario
from sim.simulation.compile import build
from sim.simulation.motion import build_motion

WEAVE_BRACKET = Path(__file__).with_name("test_weld_paths.py")


def _bracket(tmp: Path) -> Path:
    """The L-bracket seam of test_weld_paths.py with its sine weave (a polyline, blended)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("weld_paths", WEAVE_BRACKET)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.write(tmp, mod.WEAVE)


def _tp_with_a_sec_move(tmp: Path) -> Path:
    """weld1.ls with its first L move given as a time (``2sec``)."""
    (tmp / "weld1.ls").write_text((DATA / "weld1.ls").read_text().replace(
        "L P[2] 100mm/sec FINE", "L P[2] 2sec FINE", 1))
    (tmp / "s.toml").write_text(TP_SCENARIO)
    return tmp / "s.toml"


CASES = {
    "weld plate (default ramps)": lambda tmp: "lrmate200ic_weld_plate",
    "bracket with a weave": _bracket,
    "TP program with a sec move": _tp_with_a_sec_move,
}
#: The fastest scale drawn per case. The bracket's blended corner already uses most of the
#: joints' share at x1 (the planner slows a corner that would need more than
#: ``CORNER_LIMIT_SHARE`` of a joint's limit, as a controller does): faster, it is passed more
#: slowly than 1/s (the documented exception), so its scales stop at 1.
FASTEST = {"weld plate (default ramps)": 2.0, "bracket with a weave": 1.0,
           "TP program with a sec move": 2.0}


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    """Per case: the scenario, its built cell and its unscaled plan (once per module)."""
    out = {}
    for name, make in CASES.items():
        sc = load_scenario(make(tmp_path_factory.mktemp("scale")))
        built = build(sc)
        out[name] = (sc, built, build_motion(sc, built.context))
    return out


@pytest.mark.parametrize("case", sorted(CASES))
@settings(max_examples=3, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(u=st.floats(0.0, 1.0))
def test_a_scaled_plan_is_the_same_joint_path_s_times_faster(planned, case, u):
    s = 0.5 + u * (FASTEST[case] - 0.5)
    sc, built, ref = planned[case]
    fast = build_motion(sc.scaled(s), built.context)
    assert [pm.name for pm in fast.phases] == [pm.name for pm in ref.phases]
    for a, b in zip(ref.phases, fast.phases, strict=True):
        assert b.t1 - b.t0 == pytest.approx((a.t1 - a.t0) / s, rel=1e-9, abs=1e-9), a.name
    t = np.linspace(ref.phases[0].t0, ref.phases[-1].t1, 2001)
    np.testing.assert_allclose(fast.at(t / s).q, ref.at(t).q, atol=1e-7)


def test_a_corner_slowed_for_the_joints_only_lengthens_the_scaled_plan(planned):
    """The bracket at x2: its corner is passed more slowly than 1/s (the joints' share), so
    its weld lasts longer than 1/2 of x1's; every other phase is exactly 1/2."""
    sc, built, ref = planned["bracket with a weave"]
    fast = build_motion(sc.scaled(2.0), built.context)
    for a, b in zip(ref.phases, fast.phases, strict=True):
        if a.name == "weld":
            assert b.t1 - b.t0 > (a.t1 - a.t0) / 2.0 + 0.05
        else:
            assert b.t1 - b.t0 == pytest.approx((a.t1 - a.t0) / 2.0, rel=1e-9, abs=1e-9)


def test_the_weld_plate_cycle_at_x1_25_is_its_cycle_over_1_25(planned):
    """The trial's own figures: 82.592 s at x1, so 66.074 s at x1.25 (was 66.373 s)."""
    sc, built, ref = planned["weld plate (default ramps)"]
    fast = build_motion(sc.scaled(1.25), built.context)
    assert ref.phases[-1].t1 == pytest.approx(82.592, abs=1e-3)
    assert fast.phases[-1].t1 - fast.phases[0].t0 == pytest.approx(
        (ref.phases[-1].t1 - ref.phases[0].t0) / 1.25, rel=1e-12)

"""``cellsim run`` prints the first saturation intervals and collisions one per line and counts
the rest, naming the worst of all: a run printed 10 of its 69 intervals, none of them the one
its verdict quoted (661.5 N m over the limit at 79 s), with no word of the other 59 (found by a
new-user trial). Specification, on generated lists: at most ``SHOWN`` lines of each kind, then
one line with the count of the others and the worst interval (largest excess) or collision
(deepest) of the whole list, which is therefore always on screen."""

from __future__ import annotations

import contextlib
import io

from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cli.run import SHOWN, print_findings

_interval = st.fixed_dictionaries({
    "joint": st.sampled_from(["j1", "j2", "j7"]), "t0": st.floats(0, 100),
    "t1": st.floats(0, 100), "phase": st.just("weld"),
    "worst_excess_nm": st.floats(0.001, 1e4)})
_collision = st.fixed_dictionaries({
    "bodies": st.just(["robot/link2", "table"]), "geoms": st.just(["robot/link2#0", "table"]),
    "t0": st.floats(0, 100), "t1": st.floats(0, 100), "depth_mm": st.floats(0.0, 500.0),
    "phase": st.just("weld")})


@settings(max_examples=40, deadline=None)
@given(sat=st.lists(_interval, max_size=40), col=st.lists(_collision, max_size=25))
def test_the_worst_is_always_on_screen(sat, col):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        print_findings({"saturation": sat, "collisions": col}, {"j7": "mm"})
    lines = buf.getvalue().splitlines()
    shown_sat = [ln for ln in lines if ln.startswith("  saturation ")]
    shown_col = [ln for ln in lines if ln.startswith("  collision ")]
    more = [ln for ln in lines if ln.startswith("  ... and ")]
    assert len(shown_sat) == min(len(sat), SHOWN) and len(shown_col) == min(len(col), SHOWN)
    assert len(more) == (len(sat) > SHOWN) + (len(col) > SHOWN)
    if sat:
        worst = max(s["worst_excess_nm"] for s in sat)
        assert any(f"{worst:.4g} " in ln for ln in shown_sat + more)
    if len(sat) > SHOWN:
        assert f"and {len(sat) - SHOWN} more saturation intervals" in more[0]
    if col:
        deepest = max(c["depth_mm"] for c in col)
        assert any(f"{deepest:.1f} mm" in ln for ln in shown_col + more)

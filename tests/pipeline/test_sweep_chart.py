"""``sweep.png`` (:func:`sim.pipeline.sweep.report.sweep_figure`): per joint, peak and RMS
torque against payload and against speed scale, each only where the sweep varies it (against
one value every line would be a single point; issue 29: the chart is drawn after the variants,
half of it was such a column). Specification, on generated grids and joints: one row of axes
per joint, a column per varied quantity (the payload's alone for one variant), and every
line's points are the table's values (peak solid, RMS dashed), one line per value of the
other quantity; a joint's columns share their torque axis. A planted fault (the two quantities swapped in the right-hand column) is
caught."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.pipeline.sweep import report
from sim.pipeline.sweep.report import sweep_figure
from sim.pipeline.sweep.variants import Outcome, SweepResult, Variant

VALUES = st.lists(st.floats(0.1, 20.0).map(lambda v: round(v, 3)), min_size=1, max_size=4,
                  unique=True)


def _result(payloads: list[float], speeds: list[float], joints: list[str],
            seed: int) -> SweepResult:
    rng = np.random.default_rng(seed)
    outcomes = []
    for i, (p, s) in enumerate(itertools.product(payloads, speeds)):
        rows = tuple({"payload_kg": p, "speed_scale": s, "joint": j,
                      "peak_torque_nm": float(rng.uniform(1, 50)),
                      "rms_torque_nm": float(rng.uniform(0.1, 1))} for j in joints)
        outcomes.append(Outcome(Variant(p, s, "x", index=i), None, rows))
    return SweepResult(outcomes=outcomes, workers=1, wall_s=0.0)


def _mismatches(result: SweepResult, draw: Any = sweep_figure) -> list[str]:
    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    payloads = sorted({r["payload_kg"] for r in rows})
    speeds = sorted({r["speed_scale"] for r in rows})
    want_cols = [c for c, v in (("payload", payloads), ("speed", speeds)) if len(v) > 1]
    want_cols = want_cols or ["payload"]
    fig = draw(result)
    axes = np.array(fig.axes).reshape(len(joints), -1)
    bad = []
    if axes.shape[1] != len(want_cols):
        return [f"{axes.shape[1]} columns, want {want_cols}"]
    value = {(r["payload_kg"], r["speed_scale"], r["joint"]): r for r in rows}
    for (k, j), (c, col) in itertools.product(enumerate(joints), enumerate(want_cols)):
        xs, others = (payloads, speeds) if col == "payload" else (speeds, payloads)
        want = set()
        for o in others:
            for key, style in (("peak_torque_nm", "-"), ("rms_torque_nm", "--")):
                pts = tuple((x, value[(x, o, j) if col == "payload" else (o, x, j)][key])
                            for x in xs)
                want.add((style, pts))
        got = {(ln.get_linestyle(), tuple(zip(ln.get_xdata(), ln.get_ydata(), strict=True)))
               for ln in axes[k, c].get_lines()}
        if got != want:
            bad.append(f"joint {j}, column {col}")
        if axes[k, c].get_ylim() != axes[k, 0].get_ylim():
            bad.append(f"joint {j}: its columns' torque axes differ")
    return bad


@settings(max_examples=15, deadline=None)
@given(payloads=VALUES, speeds=VALUES, n_joints=st.integers(1, 3), seed=st.integers(0, 99))
def test_columns_and_lines_are_the_tables(payloads: list[float], speeds: list[float],
                                           n_joints: int, seed: int) -> None:
    result = _result(payloads, speeds, [f"j{i + 1}" for i in range(n_joints)], seed)
    assert _mismatches(result) == []


def test_the_png_is_written() -> None:
    png = report.sweep_chart(_result([1.0, 2.0], [0.5, 1.0], ["j1"], 0))
    assert png.startswith(b"\x89PNG")


def test_planted_swapped_column_is_caught() -> None:
    def swapped(result: SweepResult) -> Any:  # the two quantities exchanged
        return sweep_figure(SweepResult(outcomes=[Outcome(o.variant, None, tuple(
            {**r, "payload_kg": r["speed_scale"], "speed_scale": r["payload_kg"]}
            for r in o.rows)) for o in result.outcomes], workers=1, wall_s=0.0))

    assert _mismatches(_result([1.0, 2.0, 3.0], [0.5, 1.0], ["j1", "j2"], 1), swapped) != []

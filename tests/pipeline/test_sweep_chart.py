"""``sweep.svg`` (:func:`sim.pipeline.sweep.report.sweep_svg`): per joint, peak and RMS torque
against payload and against speed scale, each only where the sweep varies it (against one value
every line would be a single point). Specification, on generated grids and joints, read back the
way a person reads the chart, through its own tick labels: one row of panels per joint, a column
per varied quantity (the payload's alone for one variant); every line's points, read through the
ticks, are the table's values (peak solid, RMS dashed), one line per value of the other quantity,
in the colour of its legend entry; a joint's columns share their torque axis and a column its x
axis. Planted faults (the two quantities swapped; tick labels one step off; legend colours in
the wrong order) are caught."""

from __future__ import annotations

import itertools
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import Any
from unittest import mock

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis import svg_chart
from sim.analysis.svg_chart import axis, nice_ticks
from sim.pipeline.sweep.report import sweep_markdown, sweep_svg
from sim.pipeline.sweep.variants import Outcome, SweepResult, Variant

NS = "{http://www.w3.org/2000/svg}"
VALUES = st.lists(st.floats(0.1, 20.0).map(lambda v: round(v, 3)), min_size=1, max_size=4,
                  unique=True)


def _result(payloads: list[float], speeds: list[float], joints: list[str], seed: int,
            scale: float = 50.0) -> SweepResult:
    rng = np.random.default_rng(seed)
    outcomes = []
    for i, (p, s) in enumerate(itertools.product(payloads, speeds)):
        rows = tuple({"payload_kg": p, "speed_scale": s, "joint": j,
                      "peak_torque_nm": float(rng.uniform(1, scale)),
                      "rms_torque_nm": float(rng.uniform(0.1, 1)), "margin_pct": math.nan}
                     for j in joints)
        outcomes.append(Outcome(Variant(p, s, "x", index=i), None, rows))
    return SweepResult(outcomes=outcomes, workers=1, wall_s=0.0)


def _fit(ticks: list[tuple[float, float]]) -> Callable[[float], float]:
    """Position -> value through a panel's tick labels (least squares over every tick; their
    positions must lie on one straight line)."""
    pos = np.array([p for p, _ in ticks])
    val = np.array([v for _, v in ticks])
    a, b = np.polyfit(pos, val, 1)
    # positions are written to 0.01 px
    assert np.allclose(a * pos + b, val, rtol=0, atol=0.01 * abs(a)), "ticks not linear"
    return lambda p: float(a * p + b)


def read_chart(svg: str) -> dict[tuple[int, int], dict[str, Any]]:
    """Each panel's lines, read back through the tick labels: {(row, col): {"lines": [(dashed,
    colour, ((x, y), ...)), ...], "ygrid": (...), "xgrid": (...), "span": (x, y)}}; and the
    legends {(0, col)}["legend"]: {label: colour}."""
    root = ET.fromstring(svg)
    panels = {(int(g.get("data-row")), int(g.get("data-col"))): g
              for g in root.iter(f"{NS}g") if g.get("class") == "panel"}
    n_rows = 1 + max(r for r, _ in panels)
    out: dict[tuple[int, int], dict[str, Any]] = {}
    for (r, c), g in panels.items():
        # y ticks are labelled left of a row's first panel, x ticks under a column's last
        ylab = [(float(t.get("y")), float(t.text)) for t in panels[(r, 0)].iter(f"{NS}text")
                if t.get("class") == "ytick"]
        xlab = [(float(t.get("x")), float(t.text))
                for t in panels[(n_rows - 1, c)].iter(f"{NS}text") if t.get("class") == "xtick"]
        fx, fy = _fit(xlab), _fit(ylab)
        lines = []
        for pl in g.iter(f"{NS}polyline"):
            pts = [tuple(map(float, p.split(","))) for p in pl.get("points").split()]
            lines.append((pl.get("stroke-dasharray") is not None, pl.get("stroke"),
                          tuple((fx(x), fy(y)) for x, y in pts)))
        grid = [(float(ln.get("x1")), float(ln.get("y1")), float(ln.get("x2")), float(ln.get("y2")))
                for ln in g.findall(f"{NS}line")]  # the grid, not the legend's lines
        out[(r, c)] = {"lines": lines,
                       "ygrid": tuple(round(y1, 2) for x1, y1, x2, y2 in grid if y1 == y2),
                       "xgrid": tuple(round(x1, 2) for x1, y1, x2, y2 in grid if x1 == x2),
                       "span": (abs(fx(1.0) - fx(0.0)), abs(fy(1.0) - fy(0.0))),
                       "legend": {e.get("data-label"): e.find(f"{NS}line").get("stroke")
                                  for e in g.iter(f"{NS}g") if e.get("class") == "legend"}}
    return out


def _mismatches(result: SweepResult, draw: Any = sweep_svg) -> list[str]:
    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    payloads = sorted({r["payload_kg"] for r in rows})
    speeds = sorted({r["speed_scale"] for r in rows})
    want_cols = [c for c, v in (("payload", payloads), ("speed", speeds)) if len(v) > 1]
    want_cols = want_cols or ["payload"]
    chart = read_chart(draw(result))
    shape = (1 + max(r for r, _ in chart), 1 + max(c for _, c in chart))
    if shape != (len(joints), len(want_cols)):
        return [f"{shape} panels, want {len(joints)} joints x {want_cols}"]
    value = {(r["payload_kg"], r["speed_scale"], r["joint"]): r for r in rows}
    bad = []
    for (k, j), (c, col) in itertools.product(enumerate(joints), enumerate(want_cols)):
        panel = chart[(k, c)]
        xs, others = (payloads, speeds) if col == "payload" else (speeds, payloads)
        legend = chart[(0, c)]["legend"]
        label = (lambda o: f"speed x{o:g}") if col == "payload" else (lambda o: f"{o:g} kg")
        if set(legend) != {label(o) for o in others}:
            bad.append(f"column {col}: legend {sorted(legend)}")
            continue
        # a reading is right to a hundredth of a pixel (coordinates are written to 0.01 px)
        tol_x, tol_y = 0.02 * panel["span"][0], 0.02 * panel["span"][1]
        got = list(panel["lines"])
        for o in others:
            for key, dashed in (("peak_torque_nm", False), ("rms_torque_nm", True)):
                want = [(x, value[(x, o, j) if col == "payload" else (o, x, j)][key])
                        for x in xs]
                hit = [g for g in got if g[0] == dashed and g[1] == legend[label(o)]
                       and len(g[2]) == len(want)
                       and all(abs(a - x) <= tol_x and abs(b - y) <= tol_y
                               for (a, b), (x, y) in zip(g[2], want, strict=True))]
                if not hit:
                    bad.append(f"joint {j}, column {col}, {label(o)}, {key}: no such line")
                else:
                    got.remove(hit[0])
        if got:
            bad.append(f"joint {j}, column {col}: {len(got)} lines the table does not have")
        if panel["ygrid"] != chart[(k, 0)]["ygrid"]:
            bad.append(f"joint {j}: its columns' torque axes differ")
        if panel["xgrid"] != chart[(len(joints) - 1, c)]["xgrid"]:
            bad.append(f"column {col}: its panels' x axes differ")
    return bad


@settings(max_examples=25, deadline=None)
@given(payloads=VALUES, speeds=VALUES, n_joints=st.integers(1, 3), seed=st.integers(0, 99),
       scale=st.sampled_from([2.0, 50.0, 4000.0]))
def test_lines_read_through_the_ticks_are_the_tables(payloads: list[float], speeds: list[float],
                                                      n_joints: int, seed: int,
                                                      scale: float) -> None:
    result = _result(payloads, speeds, [f"j{i + 1}" for i in range(n_joints)], seed, scale)
    assert _mismatches(result) == []


def test_the_svg_is_a_document_the_report_links() -> None:
    result = _result([1.0, 2.0], [0.5, 1.0], ["j1"], 0)
    root = ET.fromstring(sweep_svg(result))
    assert root.tag == f"{NS}svg" and float(root.get("width")) > 0
    assert "![peak and RMS torque](sweep.svg)" in sweep_markdown(result)


def test_a_non_finite_value_breaks_its_line() -> None:
    result = _result([1.0, 2.0, 3.0, 4.0], [1.0], ["j1"], 3)
    rows = result.outcomes[1].rows
    result.outcomes[1] = Outcome(result.outcomes[1].variant, None,
                                 ({**rows[0], "peak_torque_nm": math.nan},))
    peak = [pts for dashed, _, pts in read_chart(sweep_svg(result))[(0, 0)]["lines"]
            if not dashed]
    want = [r["peak_torque_nm"] for r in result.rows]
    assert [len(p) for p in peak] == [1, 2]
    assert np.allclose([y for p in peak for _, y in p], [want[0], want[2], want[3]], rtol=1e-3)


@settings(max_examples=200, deadline=None)
@given(lo=st.floats(-1e6, 1e6), width=st.floats(0.0, 1e6))
def test_an_axis_holds_its_values_between_round_ticks(lo: float, width: float) -> None:
    hi = lo + width
    a, b, ticks = axis([lo, hi])
    assert a <= lo and hi <= b and a < b
    assert 2 <= len(ticks) <= 12
    assert all(a - 1e-9 * (b - a) <= t <= b + 1e-9 * (b - a) for t in ticks)
    step = ticks[1] - ticks[0]
    # what float arithmetic leaves of ticks far from zero (k x step with k up to 1e10)
    ulp = 8 * np.finfo(float).eps * max(abs(a), abs(b))
    mantissa = step / 10 ** math.floor(math.log10(step))
    assert any(math.isclose(mantissa, m, rel_tol=1e-6 + ulp / step) for m in (1, 2, 5, 10))
    assert np.allclose(np.diff(ticks), step, rtol=1e-6, atol=ulp)
    # a tick's label reads as its value to the step's precision
    labels = [svg_chart.tick_text(t, ticks) for t in ticks]
    for t, text in zip(ticks, labels, strict=True):
        assert abs(float(text) - t) <= 1e-6 * step + ulp
    # short labels beside the torque axis: fixed point up to 7 characters, else 1.5e-8
    assert all(len(x) <= 7 for x in labels) or all("e" in x or x == "0" for x in labels)
    cover = nice_ticks(lo, hi)
    assert cover[0] <= lo and hi <= cover[-1]


def test_planted_swapped_quantities_are_caught() -> None:
    def swapped(result: SweepResult) -> str:  # the two quantities exchanged
        return sweep_svg(SweepResult(outcomes=[Outcome(o.variant, None, tuple(
            {**r, "payload_kg": r["speed_scale"], "speed_scale": r["payload_kg"]}
            for r in o.rows)) for o in result.outcomes], workers=1, wall_s=0.0))

    assert _mismatches(_result([1.0, 2.0, 3.0], [0.5, 1.0], ["j1", "j2"], 1), swapped) != []


def test_planted_tick_labels_one_step_off_are_caught() -> None:
    real = svg_chart.tick_text

    def off(v: float, ticks: list[float]) -> str:
        return real(v + (ticks[1] - ticks[0]), ticks)

    result = _result([1.0, 2.0, 3.0], [0.5, 1.0], ["j1"], 2)
    with mock.patch.object(svg_chart, "tick_text", off):
        assert _mismatches(result) != []
    assert _mismatches(result) == []


def test_planted_legend_colours_in_the_wrong_order_are_caught() -> None:
    def reversed_legend(result: SweepResult) -> str:
        svg = sweep_svg(result)
        entries = re.findall(r'<g class="legend" data-label="[^"]*"><line [^>]*stroke="(#\w+)"',
                             svg)
        it = iter(reversed(entries))
        return re.sub(r'(<g class="legend" data-label="[^"]*"><line [^>]*stroke=")(#\w+)',
                      lambda m: m.group(1) + next(it), svg)

    result = _result([1.0, 2.0, 3.0], [0.5, 1.0], ["j1"], 4)
    assert _mismatches(result, reversed_legend) != []

"""A sweep's report: ``sweep.csv`` (one row per variant and joint), ``sweep.md`` (pivot tables of
peak and RMS torque, sizing margins, failures), ``sweep.svg`` (torque against payload and
against speed scale, each where the sweep varies it) and ``sweep.json``."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.analysis.report import csv_text, write_atomic
from sim.analysis.svg_chart import Panel, Series, grid_svg, viridis
from sim.pipeline.sweep.selection_report import selection_markdown, write_selection
from sim.pipeline.sweep.variants import SweepResult

#: Columns of sweep.csv, in order.
SWEEP_COLUMNS = ("payload_kg", "speed_scale", "joint", "peak_torque_nm", "rms_torque_nm",
                 "peak_torque_id_nm", "peak_torque_sim_nm", "rms_torque_id_nm", "rms_torque_sim_nm",
                 "peak_speed_rad_s", "peak_power_w", "duration_s", "margin_pct", "pass",
                 "limiting", "verdict", "failed_checks", "run_dir")


def _pivot(rows: Sequence[dict[str, Any]], key: str, joints: Sequence[str]) -> list[list[str]]:
    table: dict[tuple[float, float], dict[str, float]] = {}
    verdict: dict[tuple[float, float], str] = {}
    for r in rows:
        table.setdefault((r["payload_kg"], r["speed_scale"]), {})[r["joint"]] = r[key]
        verdict[(r["payload_kg"], r["speed_scale"])] = str(r.get("verdict", ""))
    out = []
    for (p, s), vals in table.items():
        cells = [f"{vals[j]:.4g}" if j in vals and np.isfinite(vals[j]) else "n/a" for j in joints]
        # 12 digits: values that differ only past the 6th (1.0000001 and 1.0000002 kg) stay
        # two rows that read apart
        out.append([f"{p:.12g}", f"{s:.12g}", verdict[(p, s)] or "-", *cells])
    return out


def sweep_markdown(result: SweepResult, chart: str | None = "sweep.svg") -> str:
    """Text of ``sweep.md``: pivot tables (variant rows, joint columns), failures, chart."""
    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    ok = len(result.outcomes) - len(result.failures)
    failing = len(_verdicts(result))
    passed = f", {failing} of them with a failed verdict" if failing else ""
    parts = ["# Sweep", "",
             f"{len(result.outcomes)} variants ({ok} succeeded{passed}), {result.workers} "
             "worker(s), "
             f"{result.wall_s:.1f} s wall-clock. Speed scale s divides the knot times "
             "(s = 2: twice as fast). Torques are the larger of inverse dynamics and simulation "
             "(a linear axis's, a track's, are forces in N).",
             ""]
    head = ["payload kg", "speed scale", "verdict", *joints]

    def table(title: str, key: str) -> None:
        parts.extend([f"## {title}", "",
                      "| " + " | ".join(head) + " |", "|" + "---|" * len(head)])
        parts.extend("| " + " | ".join(r) + " |" for r in _pivot(rows, key, joints))
        parts.append("")

    if rows:
        table("Peak |torque| (N m)", "peak_torque_nm")
        table("RMS torque (N m)", "rms_torque_nm")
        if any(np.isfinite(r["margin_pct"]) for r in rows):
            table("Sizing margin (%)", "margin_pct")
    verdicts = _verdicts(result)
    if verdicts:
        parts += ["## Variants whose verdict failed", "",
                  "Simulated and sized (their rows are in the tables above), but physically "
                  "impossible or out of the robot's or tool's rating: why, per variant.", ""]
        parts += [f"- {label}: {why or 'fail'}" for label, why in verdicts]
        parts.append("")
    parts += selection_markdown(result)
    if result.failures:
        parts += ["## Failed variants", ""]
        parts += [f"- {o.variant.label}: {o.error}" for o in result.failures]
        parts.append("")
    if chart and rows:
        parts += ["## Chart", "", f"![peak and RMS torque]({chart})", ""]
    return "\n".join(parts)


def _verdicts(result: SweepResult) -> list[tuple[str, str]]:
    """The variants whose verdict failed, in variant order: their label and why."""
    return [(o.variant.label, str(o.rows[0].get("failed_checks", "")))
            for o in result.outcomes if o.rows and o.rows[0].get("verdict") == "fail"]


def chart_columns(result: SweepResult) -> tuple[str, ...]:
    """The columns :func:`sweep_svg` draws: ``"payload"`` (torque against payload) and
    ``"speed"`` (against speed scale), each only where the sweep has more than one value of
    it (against a single value every line would be one point); the payload column alone for
    a sweep of one variant."""
    rows = result.rows
    cols = tuple(name for name, key in (("payload", "payload_kg"), ("speed", "speed_scale"))
                 if len({r[key] for r in rows}) > 1)
    return cols or ("payload",)


def sweep_svg(result: SweepResult) -> str:
    """The chart, SVG text: per joint (rows), peak (solid, circles) and RMS (dashed, squares)
    torque against payload (one line per speed scale) and against speed scale (one line per
    payload), the columns of :func:`chart_columns`; a joint's columns share their torque axis
    (the same values, seen two ways). Written directly (:mod:`sim.analysis.svg_chart`), in
    milliseconds: the sweep's parent draws it after its workers."""
    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    payloads = sorted({r["payload_kg"] for r in rows})
    scales = sorted({r["speed_scale"] for r in rows})
    idx = {(r["payload_kg"], r["speed_scale"], r["joint"]): r for r in rows}
    against = {
        "payload": (payloads, scales, lambda s: f"speed x{s:g}",
                    lambda j, x, s: (x, s, j), "against payload", "payload (kg)"),
        "speed": (scales, payloads, lambda p: f"{p:g} kg",
                  lambda j, x, p: (p, x, j), "against speed scale", "speed scale"),
    }
    grid = []
    for k, j in enumerate(joints):
        row = []
        for c, col in enumerate(chart_columns(result)):
            xs, others, label, key_of, title, xlabel = against[col]
            series = []
            for i, other in enumerate(others):
                color = viridis(i / max(len(others) - 1, 1))
                for key, dashed, marker in (("peak_torque_nm", False, "circle"),
                                            ("rms_torque_nm", True, "square")):
                    pts = [(x, idx[key_of(j, x, other)][key]) for x in xs
                           if key_of(j, x, other) in idx]
                    if pts:
                        series.append(Series(
                            x=[p[0] for p in pts], y=[p[1] for p in pts], color=color,
                            dashed=dashed, marker=marker,
                            label=label(other) if not dashed else None))
            row.append(Panel(series=series,
                             title=f"{title} (solid: peak, dashed: RMS)" if k == 0 else None,
                             xlabel=xlabel, legend=k == 0,
                             ylabel=f"{j} torque (N m)\n(N on a linear axis)" if c == 0
                             else None))
        grid.append(row)
    return grid_svg(grid)


def write_sweep(out_dir: str | Path, result: SweepResult) -> dict[str, Path]:
    """Write ``sweep.csv``, ``sweep.json``, ``sweep.svg`` (when any variant succeeded),
    ``selection.csv`` and ``selection.json`` (when the variants made an actuator selection) and
    ``sweep.md`` into ``out_dir`` (atomically). Returns the paths by name."""
    out = Path(out_dir)
    files: dict[str, Path] = {}
    rows = result.rows
    files["csv"] = write_atomic(out / "sweep.csv", csv_text(SWEEP_COLUMNS, rows))
    payload = {
        "workers": result.workers, "wall_s": result.wall_s,
        "variants": [{"payload_kg": o.variant.payload_kg, "speed_scale": o.variant.speed_scale,
                      "run_dir": o.run_dir, "error": o.error, "wall_s": o.wall_s}
                     for o in result.outcomes],
        "rows": [{k: (v if not isinstance(v, float) or math.isfinite(v) else None)
                  for k, v in r.items()} for r in rows],
    }
    files["json"] = write_atomic(out / "sweep.json", json.dumps(payload, indent=2) + "\n")
    chart = None
    if rows:
        files["svg"] = write_atomic(out / "sweep.svg", sweep_svg(result))
        chart = "sweep.svg"
    files.update(write_selection(out, result))
    files["md"] = write_atomic(out / "sweep.md", sweep_markdown(result, chart))
    return files


__all__ = ["SWEEP_COLUMNS", "chart_columns", "sweep_markdown", "sweep_svg", "write_sweep"]

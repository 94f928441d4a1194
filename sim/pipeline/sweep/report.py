"""A sweep's report: ``sweep.csv`` (one row per variant and joint), ``sweep.md`` (pivot tables of
peak and RMS torque, sizing margins, failures), ``sweep.png`` (torque against payload and
against speed scale, each where the sweep varies it) and ``sweep.json``."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.analysis.report import csv_text, figure_png, write_atomic
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


def sweep_markdown(result: SweepResult, chart: str | None = "sweep.png") -> str:
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
    """The columns :func:`sweep_figure` draws: ``"payload"`` (torque against payload) and
    ``"speed"`` (against speed scale), each only where the sweep has more than one value of
    it (against a single value every line would be one point); the payload column alone for
    a sweep of one variant."""
    rows = result.rows
    cols = tuple(name for name, key in (("payload", "payload_kg"), ("speed", "speed_scale"))
                 if len({r[key] for r in rows}) > 1)
    return cols or ("payload",)


def sweep_figure(result: SweepResult) -> Any:
    """The chart as a matplotlib ``Figure``: per joint (rows), peak (solid) and RMS (dashed)
    torque against payload (one line per speed scale) and against speed scale (one line per
    payload), the columns of :func:`chart_columns`; a joint's columns share their torque axis
    (the same values, seen two ways)."""
    import matplotlib
    from matplotlib.figure import Figure

    rows = result.rows
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    payloads = sorted({r["payload_kg"] for r in rows})
    scales = sorted({r["speed_scale"] for r in rows})
    idx = {(r["payload_kg"], r["speed_scale"], r["joint"]): r for r in rows}
    cols = chart_columns(result)
    height = 2.3 * len(joints) + 0.8
    width = 5.0 * len(cols)
    fig = Figure(figsize=(width, height))
    # fixed margins, in inches (a constrained layout costs as much as the drawing itself)
    fig.subplots_adjust(left=0.85 / width, right=1.0 - 0.15 / width, wspace=0.2,
                        top=1.0 - 0.4 / height, bottom=0.5 / height, hspace=0.45 / 2.3)
    axes = fig.subplots(len(joints), len(cols), squeeze=False, sharex="col", sharey="row")
    cmap = matplotlib.colormaps["viridis"]

    def lines(ax, xs, series_keys, label_fmt, make_key):
        for i, other in enumerate(series_keys):
            color = cmap(i / max(len(series_keys) - 1, 1))
            for key, style in (("peak_torque_nm", "-o"), ("rms_torque_nm", "--s")):
                pts = [(x, idx[make_key(x, other)][key]) for x in xs if make_key(x, other) in idx]
                if pts:
                    x, y = zip(*pts, strict=True)
                    ax.plot(x, y, style, color=color, ms=3.5, lw=1.2,
                            label=label_fmt(other) if key == "peak_torque_nm" else None)

    against = {
        "payload": (payloads, scales, lambda s: f"speed x{s:g}",
                    lambda j: lambda x, s: (x, s, j), "against payload", "payload (kg)"),
        "speed": (scales, payloads, lambda p: f"{p:g} kg",
                  lambda j: lambda x, p: (p, x, j), "against speed scale", "speed scale"),
    }
    for k, j in enumerate(joints):
        for c, col in enumerate(cols):
            ax = axes[k][c]
            xs, series, label, key_of, title, xlabel = against[col]
            lines(ax, xs, series, label, key_of(j))
            ax.grid(alpha=0.3)
            if k == 0:
                ax.set_title(f"{title} (solid: peak, dashed: RMS)", fontsize=9)
                ax.legend(fontsize=7)
            if k == len(joints) - 1:
                ax.set_xlabel(xlabel)
        axes[k][0].set_ylabel(f"{j} torque (N m)\n(N on a linear axis)", fontsize=9)
    return fig


def sweep_chart(result: SweepResult) -> bytes:
    """PNG bytes of :func:`sweep_figure`."""
    return figure_png(sweep_figure(result))


def warm_chart() -> None:
    """Draw a two-variant chart and throw it away: what :func:`sweep_chart` pays the first
    time in a process (matplotlib's import, fonts, glyphs, tick machinery), paid while the
    workers run (a sweep calls it in a thread), so the report's own chart costs its drawing
    only."""
    import types

    rows = [{"joint": "J1", "payload_kg": p, "speed_scale": 1.0, "peak_torque_nm": 1.0 + p,
             "rms_torque_nm": 0.5 + p} for p in (0.0, 1.0)]
    sweep_chart(types.SimpleNamespace(rows=rows))  # type: ignore[arg-type]


def write_sweep(out_dir: str | Path, result: SweepResult) -> dict[str, Path]:
    """Write ``sweep.csv``, ``sweep.json``, ``sweep.png`` (when any variant succeeded),
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
        files["png"] = write_atomic(out / "sweep.png", sweep_chart(result))
        chart = "sweep.png"
    files.update(write_selection(out, result))
    files["md"] = write_atomic(out / "sweep.md", sweep_markdown(result, chart))
    return files


__all__ = ["SWEEP_COLUMNS", "chart_columns", "sweep_chart", "sweep_figure", "sweep_markdown",
           "warm_chart", "write_sweep"]

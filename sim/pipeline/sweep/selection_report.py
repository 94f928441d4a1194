"""A sweep's actuator selection (``cellsim size --select``, or ``[sizing] select = true``):
``selection.csv`` (one row per variant and joint: the chosen motor and reducer, the hardest
check and its margin, how many pairs pass), ``selection.json`` (each variant's whole selection,
``selection.json``'s content of a run) and a section of ``sweep.md``."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from sim.analysis.report import csv_text, write_atomic
from sim.pipeline.sweep.variants import SweepResult

#: Columns of selection.csv, in order.
SELECTION_COLUMNS = ("payload_kg", "speed_scale", "joint", "motor", "reducer", "ratio",
                     "hardest_check", "margin_pct", "pairs_passing", "pairs_checked", "reason")


def _hardest(joint: dict[str, Any]) -> dict[str, Any] | None:
    """The chosen pair's error check with the least margin (None without a pair)."""
    checks = [c for c in joint.get("checks", ()) if c.get("severity") == "error"]
    return min(checks, key=lambda c: math.inf if c["margin_pct"] is None else c["margin_pct"],
               default=None)


def selection_rows(result: SweepResult) -> list[dict[str, Any]]:
    """One row per variant that made a selection and per joint (variant order)."""
    rows = []
    for o in result.outcomes:
        doc = o.selection
        if not doc:
            continue
        for name, j in doc["joints"].items():
            hard = _hardest(j)
            rows.append({
                "payload_kg": o.variant.payload_kg, "speed_scale": o.variant.speed_scale,
                "joint": name, "motor": j["motor"] or "", "reducer": j["reducer"] or "",
                "ratio": math.nan if j.get("ratio") is None else j["ratio"],
                "hardest_check": hard["name"] if hard else "",
                "margin_pct": (math.inf if hard and hard["margin_pct"] is None else
                               hard["margin_pct"] if hard else math.nan),
                "pairs_passing": j["pairs_passing"], "pairs_checked": j["pairs_checked"],
                "reason": j.get("reason", "")})
    return rows


def selection_markdown(result: SweepResult) -> list[str]:
    """The ``sweep.md`` section: per variant, the pair chosen for each joint (or why none)."""
    rows = selection_rows(result)
    if not rows:
        return []
    joints = list(dict.fromkeys(r["joint"] for r in rows))
    head = ["payload kg", "speed scale", *joints]
    by_variant: dict[tuple[float, float], dict[str, str]] = {}
    for r in rows:
        cell = (f"{r['motor']} + {r['reducer']} ({r['hardest_check']}, "
                f"{_pct(r['margin_pct'])})" if r["motor"] else "NO PAIR")
        by_variant.setdefault((r["payload_kg"], r["speed_scale"]), {})[r["joint"]] = cell
    parts = ["## Actuator selection", "",
             "The motor and reducer chosen per joint for each variant (its hardest check and "
             "margin); every pair checked is in selection.json, one row per joint in "
             "selection.csv.", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for (p, s), cells in by_variant.items():
        parts.append("| " + " | ".join([f"{p:.12g}", f"{s:.12g}",
                                        *(cells.get(j, "-") for j in joints)]) + " |")
    none = [r for r in rows if not r["motor"]]
    if none:
        parts += ["", *(f"- payload {r['payload_kg']:g} kg, speed x{r['speed_scale']:g}, "
                        f"{r['joint']}: {r['reason']}" for r in none)]
    parts.append("")
    return parts


def _pct(margin: float) -> str:
    return "inf" if math.isinf(margin) else "n/a" if math.isnan(margin) else f"{margin:.0f} %"


def write_selection(out_dir: str | Path, result: SweepResult) -> dict[str, Path]:
    """Write ``selection.csv`` and ``selection.json`` into ``out_dir`` when any variant made a
    selection; returns their paths by name (empty otherwise)."""
    rows = selection_rows(result)
    if not rows:
        return {}
    out = Path(out_dir)
    doc = {"variants": [{"payload_kg": o.variant.payload_kg,
                         "speed_scale": o.variant.speed_scale, "selection": o.selection}
                        for o in result.outcomes if o.selection]}
    return {"selection_csv": write_atomic(out / "selection.csv",
                                          csv_text(SELECTION_COLUMNS, rows)),
            "selection_json": write_atomic(out / "selection.json",
                                           json.dumps(doc, indent=2) + "\n")}


__all__ = ["SELECTION_COLUMNS", "selection_markdown", "selection_rows", "write_selection"]

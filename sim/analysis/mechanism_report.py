"""The reports' section on a run's mechanisms (turntables, positioners, tracks): per mechanism
its kind and model, what it carries and that mass against its rating, and per axis the
recorded travel and largest speed (``summary["mechanisms"]``, deg or mm) with the peak and RMS
torque of its drive from the sizing (a linear axis's force, N).

Owns the section's text (a title, a sentence and table rows per mechanism);
:mod:`sim.analysis.report` renders it into ``sizing.md`` and ``report.html``.
May import: the sizing result types.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from sim.analysis.sizing_result import JointSizing, SizingResult

#: Columns of a mechanism's axis table.
AXIS_HEAD = ("axis", "kind", "min", "max", "travel", "max speed",
             "peak torque or force (ID / sim)", "RMS torque or force (ID / sim)",
             "limiting check", "margin %")


@dataclass(frozen=True)
class MechanismSection:
    """One mechanism's part of the reports.

    Attributes:
        title: ``<name> (<kind>, <model>)``.
        load: One sentence: what it carries, that mass against its rating.
        rows: The axis table's rows (:data:`AXIS_HEAD`), every figure with its unit.
    """

    title: str
    load: str
    rows: tuple[tuple[str, ...], ...]


def _g(x: float) -> str:
    return f"{x:.4g}" if math.isfinite(x) else "n/a"


def _pair(j: JointSizing | None, attr: str) -> str:
    if j is None or not j.stats:
        return "n/a"
    return (f"{_g(getattr(j.stats['id'], attr))} / {_g(getattr(j.stats['sim'], attr))} "
            f"{j.torque_unit}")


def _margin(j: JointSizing | None) -> tuple[str, str]:
    if j is None or j.limiting is None:
        return "n/a", "n/a"
    m = j.margin_pct
    return j.limiting.title, (f"{m:.1f}" if abs(m) >= 1 else f"{m:.2g}")


def load_sentence(m: Mapping[str, Any]) -> str:
    """``Carries pipe, plate: 24.82 kg, rated 500 kg (4.964 % of its rating).``"""
    carried, rated = float(m["carried_kg"]), float(m["rated_payload_kg"])
    what = ", ".join(m.get("carries", ())) or "nothing"
    share = f" ({_g(100.0 * carried / rated)} % of its rating)" if rated > 0 else ""
    return f"Carries {what}: {_g(carried)} kg, rated {_g(rated)} kg{share}."


def mechanism_sections(summary: Mapping[str, Any], result: SizingResult | None = None
                       ) -> list[MechanismSection]:
    """The sections of ``summary["mechanisms"]`` in the cell's order (none without any); the
    torque columns from ``result`` (``n/a`` where it does not size that axis)."""
    sized = {j.joint: j for j in result.joints} if result is not None else {}
    out = []
    for name, m in summary.get("mechanisms", {}).items():
        rows = []
        for axis, a in m.get("axes", {}).items():
            unit = str(a["unit"])
            lo, hi = float(a["min"]), float(a["max"])
            j = sized.get(axis)
            rows.append((str(axis), str(a["kind"]), f"{_g(lo)} {unit}", f"{_g(hi)} {unit}",
                         f"{_g(hi - lo)} {unit}", f"{_g(float(a['max_speed']))} {unit}/s",
                         _pair(j, "peak_torque"), _pair(j, "rms_torque"), *_margin(j)))
        out.append(MechanismSection(title=f"{name} ({m['kind']}, {m['model']})",
                                    load=load_sentence(m), rows=tuple(rows)))
    return out


__all__ = ["AXIS_HEAD", "MechanismSection", "load_sentence", "mechanism_sections"]

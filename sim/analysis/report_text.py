"""How the reports write numbers: :func:`num_text`, :func:`pct_text` (margins) and
:func:`pair_text` (a figure from inverse dynamics and from the simulation, ``ID / sim``).
May import: the sizing result types."""

from __future__ import annotations

import numpy as np

from sim.analysis.sizing_result import JointSizing


def pct_text(m: float) -> str:
    """A margin in percent: one decimal, more when it is small (so a fail never reads -0.0)."""
    if m is None or not np.isfinite(m):
        return "n/a"
    return f"{m:.1f}" if abs(m) >= 1 else f"{m:.2g}"


def num_text(x: float, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits, without an exponent from 10**digits up to
    1e12 (a motor's 6000 rpm reads "6000", not "6e+03"); "n/a" for none or not finite."""
    if x is None or not np.isfinite(x):
        return "n/a"
    text = f"{x:.{digits}g}"
    rounded = float(text)
    return f"{rounded:.0f}" if "e+" in text and abs(rounded) < 1e12 else text


def pair_text(j: JointSizing, attr: str, motor: bool = False, digits: int = 4,
          unit: str = "") -> str:
    src = j.motor if motor else j.stats
    if not src:
        return "n/a"
    return (f"{num_text(getattr(src['id'], attr), digits)} / {num_text(getattr(src['sim'], attr), digits)}"
            f" {unit}").rstrip()


__all__ = ["num_text", "pair_text", "pct_text"]

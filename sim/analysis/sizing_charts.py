"""Sizing charts of a run, PNG bytes (matplotlib, Agg; no display needed): joint torques
against time (``torques.png``) and each joint's motor operating points against its drive's
torque-speed envelopes (``torque_speed_<joint>.png``).

Owns how a :class:`~sim.analysis.sizing_result.SizingResult` is drawn; the report embeds and
writes the charts (:mod:`sim.analysis.report`).
May import: the sizing modules and :mod:`sim.analysis.plots` (phase shading).
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from sim.analysis.plots import shade_phases
from sim.analysis.sizing import PEAK_KNEE_FRACTION, continuous_envelope, peak_envelope
from sim.analysis.sizing_result import JointSizing, SizingResult


def figure_png(fig: Any) -> bytes:
    """PNG bytes of a matplotlib ``Figure`` (no pyplot, no display needed)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


_COLORS = {"id": "#1f77b4", "sim": "#d62728"}


def chart_torques(result: SizingResult) -> bytes:
    """PNG: joint torque against time (a prismatic joint's force, N), inverse dynamics and
    simulation, phases shaded; each
    axis scaled to its data, the force range drawn as lines where it is in view and named at
    the edge where it is not."""
    from matplotlib.figure import Figure

    s = result.series
    n = len(result.joints)
    fig = Figure(figsize=(9, 1.9 * n + 0.8), layout="constrained")
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    phases = [p for p in result.phases if "t0" in p and "t1" in p]
    for k, (ax, j) in enumerate(zip(axes, result.joints)):
        ax.plot(s["t"], s["tau_id"][:, k], color=_COLORS["id"], lw=1.2, label="inverse dynamics")
        ax.plot(s["t"], s["tau"][:, k], color=_COLORS["sim"], lw=0.8, alpha=0.8, label="simulated")
        data = np.concatenate([s["tau_id"][:, k], s["tau"][:, k]])
        lo_d, hi_d = float(np.min(data)), float(np.max(data))
        pad = 0.12 * max(hi_d - lo_d, 1e-3 * max(abs(lo_d), abs(hi_d), 1.0))
        ax.set_ylim(lo_d - pad, hi_d + pad)
        y0, y1 = ax.get_ylim()
        off = []
        for v in j.torque_range:
            if not np.isfinite(v):
                continue
            if y0 <= v <= y1:
                ax.axhline(v, color="k", ls="--", lw=0.8)
            else:
                off.append(f"{v:+.4g}")
        shade_phases(ax, phases, label=k == 0)
        ax.set_ylabel(f"{j.joint} ({j.torque_unit})" + (f"\nlimits {' / '.join(off)}\n(off scale)"
                                            if off else ""), fontsize=9)
        ax.grid(alpha=0.3)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=2,
               fontsize=8)
    axes[-1].set_xlabel("time (s)")
    linear = any(j.kind == "prismatic" for j in result.joints)
    fig.suptitle(f"Joint torques{' and forces' if linear else ''} (dashed: force range, where "
                 "in view)", fontsize=10)
    return figure_png(fig)


def chart_torque_speed(j: JointSizing, knee_fraction: float = PEAK_KNEE_FRACTION) -> bytes:
    """PNG: motor operating points against the continuous and peak envelopes (first quadrant,
    ``|speed|`` and ``|torque|``); joint side against the force range and speed limit when the
    joint has no drive data."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.6), layout="constrained")
    ax = fig.subplots()
    if j.drive is not None and j.points:
        d = j.drive
        n = np.linspace(0, d.max_speed_rpm, 400)
        ax.plot(n, peak_envelope(d, n, knee_fraction), "k-", lw=1.6, label="peak (intermittent)")
        ax.plot(n, continuous_envelope(d, n), "k--", lw=1.4, label="rated (continuous, S1)")
        ax.axvline(d.max_speed_rpm, color="0.4", lw=0.8, ls=":")
        for s in sorted(j.points, key=lambda k: k != "sim"):  # simulation below, ID on top
            speed, torque = j.points[s]
            ax.plot(np.abs(speed), np.abs(torque), ".", ms=2, color=_COLORS[s], alpha=0.35,
                    label=f"operating points ({s})")
            m = j.motor[s]
            ax.plot([m.mean_speed_rpm], [m.rms_torque], "D", color=_COLORS[s], mec="k", ms=7,
                    label=f"RMS torque at mean speed ({s})")
        ax.set_xlabel("motor speed |n| (rpm)")
        ax.set_ylabel("motor torque |tau_m| (N m)")
        ax.set_title(f"{j.joint}: motor torque-speed, ratio {d.gear_ratio:g}, "
                     f"eta {d.efficiency:g}", fontsize=10)
    else:
        s_ = j.stats
        lo, hi = j.torque_range
        tl = min(abs(lo), abs(hi))
        if np.isfinite(tl):
            ax.axhline(tl, color="k", lw=1.4, label="force range")
        if np.isfinite(j.speed_limit):
            ax.axvline(j.speed_limit, color="k", ls="--", lw=1.2, label="speed limit")
        for s in ("id", "sim"):
            ax.plot([s_[s].peak_speed], [s_[s].peak_torque], "o", color=_COLORS[s],
                    label=f"peaks ({s})")
            ax.plot([0], [s_[s].rms_torque], "D", color=_COLORS[s], mec="k", label=f"RMS ({s})")
        force = j.kind == "prismatic"
        ax.set_xlabel(f"joint speed |qd| ({j.speed_unit})")
        ax.set_ylabel(f"joint {'force |f|' if force else 'torque |tau|'} ({j.torque_unit})")
        ax.set_title(f"{j.joint}: joint side (no drive data)", fontsize=10)
    if j.drive is not None and j.points:  # the operating cloud in view, envelopes clipped
        speeds = np.concatenate([np.abs(v[0]) for v in j.points.values()])
        torques = np.concatenate([np.abs(v[1]) for v in j.points.values()]
                                 + [[j.motor[s].rms_torque for s in j.points]])
        n_top = 1.15 * max(float(np.max(speeds)), 1.0)
        t_top = 1.25 * max(float(np.max(torques)), 1e-6)
        # the envelope's levels come into view when they are near the cloud; farther ones
        # are named at the edge instead of squashing the cloud into a corner
        off = []
        for level, name in ((d.rated_torque, "rated"), (d.peak_torque, "peak")):
            if level <= 3.0 * t_top / 1.25:
                t_top = max(t_top, 1.08 * level)
            else:
                off.append(f"{name} {level:.3g} N m")
        if d.max_speed_rpm <= 3.0 * n_top / 1.15:
            n_top = max(n_top, 1.05 * d.max_speed_rpm)
        else:
            off.append(f"max speed {d.max_speed_rpm:.4g} rpm")
        ax.set_xlim(0, n_top)
        ax.set_ylim(0, t_top)
        if off:
            ax.annotate("off scale: " + ", ".join(off), (0.99, 0.98), xycoords="axes fraction",
                        ha="right", va="top", fontsize=7, color="0.3")
    else:
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="outside lower center", ncol=2)
    return figure_png(fig)


def sizing_charts(result: SizingResult) -> dict[str, bytes]:
    """All charts of a run by file name (relative to the ``sizing/`` folder)."""
    charts = {"torques.png": chart_torques(result)}
    for j in result.joints:
        charts[f"torque_speed_{j.joint}.png"] = chart_torque_speed(j)
    return charts

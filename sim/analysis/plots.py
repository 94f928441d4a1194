"""PNG plots of a recorded run (matplotlib, Agg; no display needed).

:func:`write_plots` writes into ``DIR/plots/``:

* ``joint_<name>.png`` for every joint: position, velocity, acceleration and jerk against
  time (reference solid; simulated position and velocity dashed), knots marked (dotted
  verticals and dots on the reference), phases shaded and named; the layout of seed 001,
  figures 5-9, with the jerk added;
* ``tool_path.png``: the tool point's path in 3D, reference vs actual, with the seam
  (samples where ``arc_on``) drawn thick and the knots as dots, and the tool point's position
  error ``|tcp_pos - tcp_pos_ref|`` (mm) against time;
* ``tracking_error.png``: ``q - q_ref`` per joint (mrad) against time;
* ``torques.png``: simulated actuator torque ``tau`` vs inverse dynamics of the reference
  ``tau_id`` per joint (N m) against time.

Units: SI, except where the axis label says otherwise (mrad, mm). Every figure has a fixed
pixel size (:data:`FIGURE_SIZES` x :data:`DPI`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.intervals import true_runs
from sim.errors import UsageError
from sim.simulation.runfolder import PLOTS_DIR, REQUIRED_FOR_PLOTS, RunRecord, as_record

#: Resolution of the PNG files, dots per inch.
DPI = 100
#: Figure size (width, height) in inches for each kind of plot.
FIGURE_SIZES: dict[str, tuple[float, float]] = {
    "joint": (10.0, 10.0),
    "tool_path": (14.0, 6.0),
    "tracking_error": (12.0, 8.0),
    "torques": (12.0, 8.0),
}

_REF = "#1a9e3f"
_ACT = "#d62728"
_BEAD = "#ff8c00"
_ID = "#1f4e9e"


def png_size(kind: str) -> tuple[int, int]:
    """Pixel size (width, height) of the PNG of plot kind ``kind``."""
    w, h = FIGURE_SIZES[kind]
    return int(round(w * DPI)), int(round(h * DPI))


def _figure(kind: str) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=FIGURE_SIZES[kind], dpi=DPI, layout="constrained")


def _shade_phases(ax: Any, record: RunRecord, label: bool) -> None:
    for k, phase in enumerate(record.phases):
        if k % 2:
            ax.axvspan(phase.t0, phase.t1, color="0.92", zorder=0, lw=0)
        if label:
            ax.text(
                0.5 * (phase.t0 + phase.t1), 1.0, phase.name, transform=ax.get_xaxis_transform(),
                ha="center", va="bottom", fontsize=8, color="0.3",
            )


#: Above this many knots (dense Cartesian via points) knots are dots only, no vertical lines.
MAX_KNOT_LINES = 60


def _knots(record: RunRecord) -> np.ndarray:
    if not record.has("knot_t"):
        return np.zeros(0)
    knots = np.asarray(record.get("knot_t"), dtype=float).ravel()
    return knots[(knots >= record.t[0] - 1e-9) & (knots <= record.t[-1] + 1e-9)]


def _grid(fig: Any, n: int) -> list[Any]:
    cols = 1 if n <= 3 else 2
    rows = math.ceil(n / cols)
    axes = fig.subplots(rows, cols, sharex=True, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return list(axes[:n])


def joint_figure(record: RunRecord, joint: int) -> Any:
    """Position, velocity, acceleration and jerk of one joint against time.

    Args:
        record: The run (needs ``q_ref``, ``qd_ref``, ``qdd_ref``, ``qddd_ref``; ``q``, ``qd``
            and ``knot_t`` are drawn when present).
        joint: Column index of the joint.

    Returns:
        A matplotlib ``Figure`` with 4 axes (top to bottom: q, qd, qdd, qddd); in each, the
        first line is the reference.
    """
    t = record.t
    name = record.joints[joint]
    fig = _figure("joint")
    axes = fig.subplots(4, 1, sharex=True)
    rows = (
        ("q_ref", "q", "position [rad]"),
        ("qd_ref", "qd", "velocity [rad/s]"),
        ("qdd_ref", None, "acceleration [rad/s²]"),
        ("qddd_ref", None, "jerk [rad/s³]"),
    )
    knots = _knots(record)
    for k, (ax, (ref_key, act_key, label)) in enumerate(zip(axes, rows)):
        _shade_phases(ax, record, label=k == 0)
        ref = record.get(ref_key)[:, joint]
        ax.plot(t, ref, color=_REF, lw=1.6, label="reference")
        if act_key and record.has(act_key):
            ax.plot(t, record.get(act_key)[:, joint], color=_ACT, lw=1.0, ls="--",
                    label="simulated")
        if 0 < knots.size <= MAX_KNOT_LINES:
            ax.vlines(knots, 0, 1, transform=ax.get_xaxis_transform(), colors="0.45", lw=0.7,
                      linestyles=":", zorder=1)
        if knots.size:
            ms = 4 if knots.size <= MAX_KNOT_LINES else 1.5
            ax.plot(knots, np.interp(knots, t, ref), "o", color="k", ms=ms, label="knots")
        ax.set_ylabel(label)
        ax.grid(True, lw=0.3)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    title = record.summary.get("scenario", "")
    fig.suptitle(f"joint {name}" + (f" ({title})" if title else ""))
    return fig


def tool_path_figure(record: RunRecord) -> Any:
    """The tool point's path in 3D (reference vs actual, seam thick) and its position error.

    Args:
        record: The run (needs ``tcp_pos``, ``tcp_pos_ref``; ``arc_on``, ``knot_t`` optional).

    Returns:
        A ``Figure`` with a 3D axes (lines: reference, actual, then seam segments) and a 2D
        axes of the error in mm.
    """
    t = record.t
    ref = record.get("tcp_pos_ref")
    act = record.get("tcp_pos")
    fig = _figure("tool_path")
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot(*ref.T, color=_REF, lw=1.6, label="reference")
    ax.plot(*act.T, color=_ACT, lw=1.0, ls="--", label="actual")
    if record.has("arc_on"):
        arc = record.get("arc_on").astype(bool)
        first = True
        for a, b in true_runs(arc):
            ax.plot(*act[a:b].T, color=_BEAD, lw=4.0, alpha=0.8,
                    label="seam (arc on)" if first else None)
            first = False
    knots = _knots(record)
    if knots.size:
        kp = np.stack([np.interp(knots, t, ref[:, i]) for i in range(3)], axis=1)
        ax.scatter(*kp.T, color="k", s=12, label="knots", depthshade=False)
    lo, hi = np.minimum(ref.min(0), act.min(0)), np.maximum(ref.max(0), act.max(0))
    centre, half = 0.5 * (lo + hi), max(0.5 * float(np.max(hi - lo)), 1e-3)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("tool point path (world frame)")
    ax2 = fig.add_subplot(1, 2, 2)
    _shade_phases(ax2, record, label=True)
    ax2.plot(t, 1000.0 * np.linalg.norm(act - ref, axis=1), color=_ACT, lw=1.2)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("|tcp - tcp_ref| [mm]")
    ax2.grid(True, lw=0.3)
    ax2.set_title("tool point position error", pad=14)
    return fig


def tracking_error_figure(record: RunRecord) -> Any:
    """Joint tracking error ``q - q_ref`` (mrad) against time, one axes per joint."""
    t = record.t
    err = 1000.0 * (record.get("q") - record.get("q_ref"))
    fig = _figure("tracking_error")
    for j, ax in enumerate(_grid(fig, len(record.joints))):
        _shade_phases(ax, record, label=j == 0)
        ax.plot(t, err[:, j], color=_ACT, lw=1.0)
        ax.axhline(0.0, color="0.5", lw=0.5)
        ax.set_ylabel(f"{record.joints[j]} error [mrad]")
        ax.grid(True, lw=0.3)
        if ax.get_subplotspec().is_last_row():
            ax.set_xlabel("time [s]")
    fig.suptitle("joint tracking error q - q_ref")
    return fig


def torque_figure(record: RunRecord) -> Any:
    """Simulated torque vs inverse dynamics of the reference (N m), one axes per joint."""
    t = record.t
    tau, tau_id = record.get("tau"), record.get("tau_id")
    fig = _figure("torques")
    for j, ax in enumerate(_grid(fig, len(record.joints))):
        _shade_phases(ax, record, label=j == 0)
        ax.plot(t, tau_id[:, j], color=_ID, lw=1.6, label="inverse dynamics (reference)")
        ax.plot(t, tau[:, j], color=_ACT, lw=0.9, ls="--", label="simulated")
        ax.set_ylabel(f"{record.joints[j]} torque [N m]")
        ax.grid(True, lw=0.3)
        if ax.get_subplotspec().is_last_row():
            ax.set_xlabel("time [s]")
        if j == 0:
            ax.legend(loc="upper right", fontsize=8)
    fig.suptitle("joint torques")
    return fig


def write_plots(run: str | Path | RunRecord, out_dir: str | Path | None = None) -> list[Path]:
    """Writes every plot of a run as PNG.

    Args:
        run: A run folder or a :class:`~sim.simulation.runfolder.RunRecord`.
        out_dir: Destination folder; default ``<run folder>/plots``.

    Returns:
        Paths written: ``joint_<name>.png`` per joint, then ``tool_path.png``,
        ``tracking_error.png``, ``torques.png``.

    Raises:
        RunFolderError: The run is missing or lacks arrays the plots need.
        ValueError: ``out_dir`` is None for an in-memory record without a source folder.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    record = as_record(run)
    record.require(REQUIRED_FOR_PLOTS)
    if out_dir is None:
        if record.source is None:
            raise UsageError("out_dir is required for a run that was not read from a folder")
        out_dir = record.source / PLOTS_DIR
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jobs: list[tuple[str, Any]] = [
        (f"joint_{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}.png", lambda j=j: joint_figure(record, j))
        for j, name in enumerate(record.joints)
    ]
    jobs += [
        ("tool_path.png", lambda: tool_path_figure(record)),
        ("tracking_error.png", lambda: tracking_error_figure(record)),
        ("torques.png", lambda: torque_figure(record)),
    ]
    written = []
    for filename, build in jobs:
        fig = build()
        FigureCanvasAgg(fig)
        path = out / filename
        fig.savefig(path, dpi=DPI, format="png")
        written.append(path)
    return written

"""PNG plots of a recorded run (matplotlib, Agg; no display needed).

:func:`write_plots` writes into ``DIR/plots/``:

* ``joint_<name>.png`` for every joint: position, velocity, acceleration and jerk against
  time in degrees (reference solid; simulated position and velocity dashed), knots as ticks on
  the time axis, phases shaded and named without overlap (:func:`shade_phases`); the layout
  of seed 001, figures 5-9, with the jerk added;
* ``tool_path.png``: the tool point's path in 3D in mm with equal axes, reference vs actual,
  with the seam (samples where ``arc_on``) drawn thick, and the tool point's position error
  ``|tcp_pos - tcp_pos_ref|`` (mm) against time; ``tool_path_<name>.png`` the same of each
  of a cell's other robots (``summary["robots"]``: its ``<name>_tcp_pos``..., its phases),
  whose joints' figures shade their own robot's phases;
* ``tracking_error.png``: ``q - q_ref`` per joint (deg) against time;
* ``torques.png``: simulated actuator torque ``tau`` vs inverse dynamics of the reference
  ``tau_id`` per joint (N m) against time;
* ``mechanism_<name>.png`` for every mechanism of the cell (``summary["mechanisms"]``: a
  positioner, turntable or track): per axis its position, speed and torque (a linear axis's
  force) against time, reference and simulated.

Units: the scenario's (deg, mm), as every axis label says; torques in N m. A linear external
axis (a track's: a prismatic joint, ``summary["mechanisms"][...]["axes"][...]["kind"]``) is in
mm, mm/s, ... and its "torque" is a force in N, in every figure. Every figure has a fixed pixel
size (:data:`FIGURE_SIZES` x :data:`DPI`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.intervals import true_runs
from sim.errors import RunFolderError, UsageError
from sim.simulation.runfolder import PLOTS_DIR, REQUIRED_FOR_PLOTS, RunRecord, as_record

#: Resolution of the PNG files, dots per inch.
DPI = 100
#: Figure size (width, height) in inches for each kind of plot.
FIGURE_SIZES: dict[str, tuple[float, float]] = {
    "joint": (10.0, 10.0),
    "tool_path": (14.0, 6.0),
    "tracking_error": (12.0, 8.0),
    "torques": (12.0, 8.0),
    "mechanism": (12.0, 9.0),
}

#: Display scale and unit of a joint's position by its kind (rad -> deg, m -> mm).
POSITION_UNITS: dict[str, tuple[float, str]] = {"revolute": (math.degrees(1.0), "deg"),
                                                 "prismatic": (1e3, "mm")}
#: Unit of a joint's "torque" by its kind (a prismatic joint's is a force).
TORQUE_UNITS = {"revolute": "N m", "prismatic": "N"}


def joint_kinds(record: RunRecord) -> list[str]:
    """Each joint's kind, ``"revolute"`` or ``"prismatic"``, in :attr:`RunRecord.joints`
    order: a mechanism's axis as its summary entry says (``summary["mechanisms"]``), the
    robot's joints revolute."""
    kinds = {axis: str(v.get("kind", "revolute"))
             for m in record.summary.get("mechanisms", {}).values()
             for axis, v in m.get("axes", {}).items()}
    return [kinds.get(name, "revolute") for name in record.joints]

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


#: Font size of the phase labels, pt, and how many rows they may stack in.
PHASE_LABEL_PT = 7.5
PHASE_LABEL_ROWS = 3


def shade_phases(ax: Any, phases: Any, label: bool) -> list[Any]:
    """Shade every other phase of ``phases`` (objects or dicts with ``name``, ``t0``, ``t1``)
    and, when ``label``, name them at the top of the axes without overlap.

    A label goes on the first of :data:`PHASE_LABEL_ROWS` rows where it clears the labels
    already there (text widths estimated from the font size and the axes' width in pixels);
    a phase too short for its name on any row gets its number (its position in the cycle,
    from 1) where that fits, else no label. Returns the label texts.
    """
    spans = []
    for k, p in enumerate(phases):
        name, t0, t1 = ((p["name"], p["t0"], p["t1"]) if isinstance(p, dict)
                        else (p.name, p.t0, p.t1))
        spans.append((k, str(name), float(t0), float(t1)))
        if k % 2:
            ax.axvspan(float(t0), float(t1), color="0.92", zorder=0, lw=0)
    if not label or not spans:
        return []
    lo, hi = spans[0][2], spans[-1][3]
    ax.set_xlim(lo, hi)
    fig = ax.get_figure()
    spec = ax.get_subplotspec()
    ncols = spec.get_gridspec().ncols if spec is not None else 1
    width_px = fig.get_size_inches()[0] * fig.dpi * 0.86 / ncols
    px_per_s = width_px / max(hi - lo, 1e-12)
    char_px = 0.58 * PHASE_LABEL_PT * fig.dpi / 72.0
    rows_end = [-np.inf] * PHASE_LABEL_ROWS
    texts = []
    for k, name, t0, t1 in spans:
        centre = 0.5 * (t0 + t1) * px_per_s
        for text in (name, str(k + 1)):
            half = 0.5 * len(text) * char_px + 3.0
            row = next((r for r in range(PHASE_LABEL_ROWS)
                        if centre - half >= rows_end[r]
                        and lo * px_per_s <= centre - half + 3 and
                        centre + half - 3 <= hi * px_per_s), None)
            if row is None:
                continue
            rows_end[row] = centre + half
            texts.append(ax.text(0.5 * (t0 + t1), 0.985 - 0.075 * row, text,
                                 transform=ax.get_xaxis_transform(), ha="center", va="top",
                                 fontsize=PHASE_LABEL_PT, color="0.25", gid="phase-label",
                                 zorder=5, bbox={"boxstyle": "round,pad=0.15", "fc": "white",
                                                 "ec": "none", "alpha": 0.75}))
            break
    return texts


#: Knot ticks closer than this fraction of the time axis to the previous tick are left out
#: (Cartesian phases have a via point every sampling period: a band, not ticks).
KNOT_MIN_SPACING = 1.0 / 80.0


def mark_knots(ax: Any, knots: Any) -> None:
    """Knot times as short ticks on the time axis (not markers on the curves), thinned to at
    most one per :data:`KNOT_MIN_SPACING` of the axis."""
    knots = np.sort(np.asarray(knots, dtype=float))
    if not knots.size:
        return
    lo, hi = ax.get_xlim()
    gap = KNOT_MIN_SPACING * (hi - lo)
    kept = [knots[0]]
    for k in knots[1:]:
        if k - kept[-1] >= gap:
            kept.append(k)
    ax.vlines(kept, 0.0, 0.035, transform=ax.get_xaxis_transform(), colors="0.2", lw=0.8,
              zorder=4)


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
        A matplotlib ``Figure`` with 4 axes (top to bottom: q, qd, qdd, qddd), in deg (a
        prismatic joint's in mm, :func:`joint_kinds`); in each, the first line is the
        reference.
    """
    t = record.t
    name = record.joints[joint]
    scale, u = POSITION_UNITS[joint_kinds(record)[joint]]
    fig = _figure("joint")
    axes = fig.subplots(4, 1, sharex=True)
    rows = (
        ("q_ref", "q", f"position [{u}]"),
        ("qd_ref", "qd", f"velocity [{u}/s]"),
        ("qdd_ref", None, f"acceleration [{u}/s²]"),
        ("qddd_ref", None, f"jerk [{u}/s³]"),
    )
    knots = _knots(record)
    for k, (ax, (ref_key, act_key, label)) in enumerate(zip(axes, rows, strict=True)):
        ref = scale * record.get(ref_key)[:, joint]
        ax.plot(t, ref, color=_REF, lw=1.6, label="reference")
        if act_key and record.has(act_key):
            ax.plot(t, scale * record.get(act_key)[:, joint], color=_ACT, lw=1.0, ls="--",
                    label="simulated")
        shade_phases(ax, _joint_phases(record, name), label=k == 0)
        mark_knots(ax, knots)
        ax.set_ylabel(label)
        ax.grid(True, lw=0.3)
    axes[1].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s] (ticks at the bottom: knots)")
    title = record.summary.get("scenario", "")
    fig.suptitle(f"joint {name}" + (f" ({title})" if title else ""))
    return fig


def other_robots(record: RunRecord) -> list[str]:
    """A cell's other robots (``summary["robots"]`` after the first) with a recorded tool
    point; empty for a cell with one robot."""
    robots = list((record.summary or {}).get("robots", {}))[1:]
    return [name for name in robots if record.has(f"{name}_tcp_pos")]


def _joint_phases(record: RunRecord, joint: str) -> Any:
    """The phases a joint's figures shade: its own robot's (``summary["robots"]``)."""
    for r in list((record.summary or {}).get("robots", {}).values())[1:]:
        if joint in r.get("joints", ()):
            return r["phases"]
    return record.phases


def tool_path_figure(record: RunRecord, robot: str | None = None) -> Any:
    """The tool point's path in 3D (reference vs actual, seam thick) and its position error.

    Args:
        record: The run (needs ``tcp_pos``, ``tcp_pos_ref``; ``arc_on``, ``knot_t`` optional).
        robot: One of a cell's other robots (its ``<robot>_tcp_pos``, ``_tcp_pos_ref``,
            ``_arc_on`` and its phases); None: the first robot.

    Returns:
        A ``Figure`` with a 3D axes (lines: reference, actual, then seam segments) and a 2D
        axes of the error in mm.
    """
    t = record.t
    pre = f"{robot}_" if robot else ""
    phases = record.summary["robots"][robot]["phases"] if robot else record.phases
    ref = 1000.0 * record.get(f"{pre}tcp_pos_ref")
    act = 1000.0 * record.get(f"{pre}tcp_pos")
    fig = _figure("tool_path")
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot(*ref.T, color=_REF, lw=1.6, label="reference")
    ax.plot(*act.T, color=_ACT, lw=1.0, ls="--", label="actual")
    if record.has(f"{pre}arc_on"):
        arc = record.get(f"{pre}arc_on").astype(bool)
        first = True
        for a, b in true_runs(arc):
            ax.plot(*act[a:b].T, color=_BEAD, lw=4.0, alpha=0.8,
                    label="seam (arc on)" if first else None)
            first = False
    lo, hi = np.minimum(ref.min(0), act.min(0)), np.maximum(ref.max(0), act.max(0))
    centre, half = 0.5 * (lo + hi), max(0.5 * float(np.max(hi - lo)), 1.0)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"{robot}: tool point path (world frame)" if robot
                 else "tool point path (world frame)")
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(t, np.linalg.norm(act - ref, axis=1), color=_ACT, lw=1.2)
    shade_phases(ax2, phases, label=True)
    mark_knots(ax2, _knots(record))
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("|tcp - tcp_ref| [mm]")
    ax2.grid(True, lw=0.3)
    ax2.set_title("tool point position error", pad=14)
    return fig


def tracking_error_figure(record: RunRecord) -> Any:
    """Joint tracking error ``q - q_ref`` (deg; a prismatic joint's in mm) against time, one
    axes per joint."""
    t = record.t
    units = [POSITION_UNITS[k] for k in joint_kinds(record)]
    err = (record.get("q") - record.get("q_ref")) * np.array([sc for sc, _ in units])
    fig = _figure("tracking_error")
    for j, ax in enumerate(_grid(fig, len(record.joints))):
        ax.plot(t, err[:, j], color=_ACT, lw=1.0)
        shade_phases(ax, record.phases, label=j == 0)
        ax.axhline(0.0, color="0.5", lw=0.5)
        ax.set_ylabel(f"{record.joints[j]} error [{units[j][1]}]")
        ax.grid(True, lw=0.3)
        if ax.get_subplotspec().is_last_row():
            ax.set_xlabel("time [s]")
    fig.suptitle("joint tracking error q - q_ref")
    return fig


def torque_figure(record: RunRecord) -> Any:
    """Simulated torque vs inverse dynamics of the reference (N m; a prismatic joint's force,
    N), one axes per joint."""
    t = record.t
    tau, tau_id = record.get("tau"), record.get("tau_id")
    kinds = joint_kinds(record)
    fig = _figure("torques")
    for j, ax in enumerate(_grid(fig, len(record.joints))):
        ax.plot(t, tau_id[:, j], color=_ID, lw=1.6, label="inverse dynamics (reference)")
        ax.plot(t, tau[:, j], color=_ACT, lw=0.9, ls="--", label="simulated")
        shade_phases(ax, record.phases, label=j == 0)
        what = "force" if kinds[j] == "prismatic" else "torque"
        ax.set_ylabel(f"{record.joints[j]} {what} [{TORQUE_UNITS[kinds[j]]}]")
        ax.grid(True, lw=0.3)
        if ax.get_subplotspec().is_last_row():
            ax.set_xlabel("time [s]")
        if j == 0:
            ax.legend(loc="upper right", fontsize=8)
    fig.suptitle("joint torques")
    return fig


def mechanism_figure(record: RunRecord, name: str) -> Any:
    """One mechanism's axes against time (``mechanism_<name>.png``): a column per axis, rows
    position and speed (reference solid, simulated dashed) and torque (a linear axis's force:
    inverse dynamics of the reference solid, simulated dashed), each in its axis's unit (deg or
    mm, N m or N); the title names its kind, model, what it carries and that mass against its
    rating (``summary["mechanisms"][name]``)."""
    m = record.summary["mechanisms"][name]
    axes_names = list(m["axes"])
    kinds = joint_kinds(record)
    t = record.t
    fig = _figure("mechanism")
    grid = fig.subplots(3, len(axes_names), sharex=True, squeeze=False)
    knots = _knots(record)
    for c, axis in enumerate(axes_names):
        j = record.joints.index(axis)
        scale, u = POSITION_UNITS[kinds[j]]
        what = "force" if kinds[j] == "prismatic" else "torque"
        rows = (("q_ref", "q", scale, f"position [{u}]"),
                ("qd_ref", "qd", scale, f"speed [{u}/s]"),
                ("tau_id", "tau", 1.0, f"{what} [{TORQUE_UNITS[kinds[j]]}]"))
        for r, (ref_key, act_key, sc, label) in enumerate(rows):
            ax = grid[r, c]
            first = "inverse dynamics" if ref_key == "tau_id" else "reference"
            ax.plot(t, sc * record.get(ref_key)[:, j], color=_ID if r == 2 else _REF, lw=1.6,
                    label=first)
            if record.has(act_key):
                ax.plot(t, sc * record.get(act_key)[:, j], color=_ACT, lw=1.0, ls="--",
                        label="simulated")
            shade_phases(ax, record.phases, label=r == 0)
            mark_knots(ax, knots)
            ax.set_ylabel(f"{axis} {label}")
            ax.grid(True, lw=0.3)
            if r == 2:
                ax.set_xlabel("time [s]")
                ax.legend(loc="upper right", fontsize=8)
    carries = ", ".join(m.get("carries", ())) or "nothing"
    fig.suptitle(f"{name}: {m['kind']} {m['model']}, carries {carries} "
                 f"({float(m['carried_kg']):.4g} kg, rated {float(m['rated_payload_kg']):g} kg)")
    return fig


def check_plots_dir(out: Path) -> None:
    """Refuses a plots folder that is a symbolic link (cellsim never writes through one).

    Raises:
        RunFolderError: One line naming it.
    """
    if Path(out).is_symlink():
        raise RunFolderError(f"{out}: is a symbolic link; cellsim writes plots only into a real "
                             "folder (remove the link)")


def write_plots(run: str | Path | RunRecord, out_dir: str | Path | None = None) -> list[Path]:
    """Writes every plot of a run as PNG.

    Args:
        run: A run folder or a :class:`~sim.simulation.runfolder.RunRecord`.
        out_dir: Destination folder; default ``<run folder>/plots``.

    Returns:
        Paths written: ``joint_<name>.png`` per joint, then ``tool_path.png`` (and
        ``tool_path_<robot>.png`` per other robot of the cell),
        ``tracking_error.png``, ``torques.png``, then ``mechanism_<name>.png`` per mechanism.

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
    check_plots_dir(out)
    out.mkdir(parents=True, exist_ok=True)
    jobs: list[tuple[str, Any]] = [
        (f"joint_{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}.png", lambda j=j: joint_figure(record, j))
        for j, name in enumerate(record.joints)
    ]
    jobs += [
        ("tool_path.png", lambda: tool_path_figure(record)),
        *((f"tool_path_{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}.png",
           lambda name=name: tool_path_figure(record, name)) for name in other_robots(record)),
        ("tracking_error.png", lambda: tracking_error_figure(record)),
        ("torques.png", lambda: torque_figure(record)),
    ]
    jobs += [(f"mechanism_{re.sub(r'[^A-Za-z0-9_.-]', '_', name)}.png",
              lambda name=name: mechanism_figure(record, name))
             for name in record.summary.get("mechanisms", {})]
    written = []
    for filename, build in jobs:
        fig = build()
        FigureCanvasAgg(fig)
        path = out / filename
        fig.savefig(path, dpi=DPI, format="png")
        written.append(path)
    return written

"""``cellsim run SCENARIO``: simulate a scenario and write its run folder.

The folder (default ``runs/<scenario name>/``) holds ``summary.json``, ``trajectory.npz`` (at
``simulation.record_hz``, default every step; ``trajectory.csv`` too with ``--csv``),
``model.xml`` (the compiled cell exactly as simulated), ``scenario.toml``,
``manifest.json``, the actuator-sizing report (``sizing.csv``/``.json``/``.md``,
``report.html``), ``plots/`` and ``video.mp4``. It is written atomically: a failed run leaves
no ``summary.json``; a run that fails mid-simulation keeps what it recorded in
``<folder>.failed/``.

The run's verdict (``summary.json`` ``"verdict"``, :mod:`sim.analysis.verdict`) fails when the
run tracks worse than its tolerance, saturates a drive, exceeds a speed or acceleration limit
or a sizing limit, or collides (the robot with itself, the tool or the arm with the cell, a held
part with the cell: :mod:`sim.simulation.collisions`); the failed checks and the collisions are
printed, and a phase closer to the cell than ``simulation.clearance_mm`` is a warning. Exit codes: 0 when the run was simulated
(whatever its verdict), 1 with ``--strict`` when the verdict is fail, 2 for a mistake in the
input. A scenario whose ``[expect]`` table declares a failure (a published motion past the robot's
limits, say) gets one line after the verdict saying so and why; its verdict and exit code are
those of any failed run.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from sim.cli.render import fps_arg

if TYPE_CHECKING:
    from sim.scenario.schema import ExpectSpec

#: Saturation intervals and collisions printed one per line; the rest are counted, with the
#: worst of all named (a run printed 10 of 69 intervals while its verdict quoted the worst,
#: not among them: found by a new-user trial).
SHOWN = 10


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help="simulate a scenario: results, sizing report, plots and video",
        description="Build the scenario's cell, plan every phase, drive the robot with position "
                    "actuators in MuJoCo, and write the run folder (summary.json, "
                    "trajectory.npz/.csv, model.xml, sizing report, plots, video.mp4).")
    p.add_argument("scenario", metavar="SCENARIO",
                   help="a scenario file, or a shipped scenario's name (see `cellsim list`)")
    p.add_argument("--out", type=Path, metavar="DIR",
                   help="run folder (default: runs/<scenario name>)")
    p.add_argument("--no-video", action="store_true", help="do not render video.mp4")
    p.add_argument("--no-plots", action="store_true", help="do not write plots/*.png")
    p.add_argument("--csv", action="store_true",
                   help="also write trajectory.csv (large: about 0.5 MB per second of cycle)")
    p.add_argument("--no-feedforward", action="store_true",
                   help="position actuators alone (no inverse-dynamics torque feed-forward)")
    p.add_argument("--gl", choices=("egl", "osmesa"),
                   help="OpenGL backend for the video (default: the first that works)")
    p.add_argument("--width", type=int, help="video width per camera, pixels")
    p.add_argument("--height", type=int, help="video height, pixels")
    p.add_argument("--fps", type=fps_arg, help="video frames per second (1-1000)")
    p.add_argument("--video-speed", type=float, metavar="X",
                   help="video playback speed, simulated seconds per second of video (4: a "
                        "time-lapse four times faster than real time)")
    p.add_argument("--camera", action="append", metavar="NAME",
                   help="cell camera to film (repeat to tile several side by side)")
    p.add_argument("--video-jobs", type=_jobs, metavar="N",
                   help="processes rendering the video's frames, each with its own OpenGL "
                        "context (default: one per core; 1: in the cellsim process)")
    p.add_argument("--backend", choices=("mujoco", "warp"), default="mujoco",
                   help="physics: MuJoCo in C (default) or MuJoCo Warp (float32, on a GPU "
                        "where there is one; pip install 'cellsim[warp]')")
    p.add_argument("--quiet", action="store_true", help="no progress bars (the result lines only)")
    p.add_argument("--strict", action="store_true",
                   help="exit with 1 when the run's verdict is fail (a collision, a saturated "
                        "drive, a joint over its speed or acceleration limit, tracking worse "
                        "than the tolerance, a sizing limit exceeded)")
    from sim.cli.size import add_selection_args

    add_selection_args(p)
    p.set_defaults(func=run)


def _jobs(text: str) -> int:
    """A positive whole number of processes (``--video-jobs``)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of processes, got {text!r}"
                                         ) from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected at least 1 process, got {value}")
    return value


def run(args: argparse.Namespace) -> int:
    if not args.no_video:
        from sim.render.gl import configure_gl

        configure_gl(args.gl)
    from sim.analysis.verdict import check_line
    from sim.cli.size import selection_overrides
    from sim.pipeline.run import RunOptions, default_out_dir, run_scenario
    from sim.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    select = selection_overrides(args, scenario.sizing.select)
    selection = None
    if select is not None:
        from sim.pipeline.run import selection_options

        selection = selection_options(scenario, **select)
    options = RunOptions(
        out_dir=args.out,
        video=not args.no_video,
        plots=not args.no_plots,
        feedforward=False if args.no_feedforward else None,
        video_args={"width": args.width, "height": args.height, "fps": args.fps,
                    "speed": args.video_speed,
                    "cameras": tuple(args.camera) if args.camera else None, "gl": args.gl,
                    "jobs": args.video_jobs},
        progress=not args.quiet,
        selection=selection,
        csv=args.csv,
        backend=args.backend,
    )
    summary = run_scenario(scenario, options)
    out = (args.out or default_out_dir(scenario))
    units = summary.get("joint_units") or ["deg"] * len(summary["max_tracking_error_deg"])
    track, worst = max((e, j) for j, e, u in zip(summary["joints"],
                                                 summary["max_tracking_error_deg"], units,
                                                 strict=True) if u == "deg")
    robots = list(summary.get("robots", {}))
    # in a cell with other robots: whose joint, and that the headline's tcp is the first's
    whose = f" ({worst})" if len(robots) > 1 else ""
    first = f" ({robots[0]})" if len(robots) > 1 else ""
    linear = "".join(f", {j} {e:.4f} mm" for j, e, u in zip(
        summary["joints"], summary["max_tracking_error_deg"], units, strict=True) if u == "mm")
    # the MuJoCo steps' own time (the simulate stage's line adds the reference and feed-forward)
    line = (f"{scenario.name}: {summary['duration_s']:.3f} s simulated in "
            f"{summary['wall_s']:.3g} s of MuJoCo steps (x{summary['realtime_factor']:.1f} real time); max tracking error "
            f"{track:.4f} deg{whose}"
            f"{linear}; max tcp deviation {summary['max_tcp_deviation_mm']:.3f} mm{first}")
    print(line)
    for line in summary.get("program_warnings", []):
        print(f"  program: {line}")
    for name, r in list(summary.get("robots", {}).items())[1:]:
        phases = r.get("phases", [])
        idle = len(phases) == 1 and phases[0].get("kind") == "hold"  # no work: stays home
        print(f"  {name} ({r['model']}): "
              + ("holds its home all cycle" if idle else f"cycle end {r['t_end_s']:.3f} s")
              + f", max tcp deviation {r['max_tcp_deviation_mm']:.3f} mm")
        for line in r.get("program_warnings", []):
            print(f"  {name}: program: {line}")
    for w in summary.get("weave", []):
        print(f"  {_who(w)}weave {w['phase']} ({w['pattern']}): {w['amplitude_mm']:.3f} mm at "
              f"{w['frequency_hz']:.3f} Hz (set {w['set_amplitude_mm']:.3f} mm at "
              f"{w['set_frequency_hz']:.3f} Hz), centre line {w['centre_line_mm']:+.4f} mm")
    for weld in summary.get("weld", []):
        print(weld_line(weld))
    sing = summary.get("singularity")
    if sing:
        extra = (f", |sin theta5| >= {sing['min_abs_wrist']:.3f}" if "min_abs_wrist" in sing
                 else "")
        print(f"  closest to a singularity: sigma_min {sing['min_sigma']:.4g} at "
              f"{sing['t']:.2f} s ({sing['phase']}){extra}")
    if "placed" in summary:
        print(f"  parts placed: {sum(summary['placed'])}/{len(summary['placed'])}, errors "
              + ", ".join(f"{e:.2f}" for e in summary["place_error_mm"]) + " mm")
    if "sizing" in summary:
        s = summary["sizing"]
        print(f"  sizing: hardest joint {s['hardest_joint']} (margin {s['hardest_margin_pct']:.1f} %),"
              f" {'all pass' if s['pass'] else 'FAIL'}")
    if "selection" in summary:
        for joint, j in summary["selection"]["joints"].items():
            print(f"  selection {joint}: " + (f"{j['motor']} + {j['reducer']}" if j["motor"]
                                               else "NO PAIR passes (see selection.json)"))
    checks = summary.get("checks", [])
    failed = [c for c in checks if not c["pass"] and c.get("severity", "error") == "error"]
    warned = [c for c in checks if not c["pass"] and c.get("severity") == "warning"]
    unit_of = dict(zip(summary["joints"], summary.get("joint_units") or (), strict=False))
    print_findings(summary, unit_of)
    for c in warned:
        print(f"  warning: {check_line(c)}")
    if failed:
        print(f"  verdict: FAIL ({len(failed)} check(s) failed, {len(warned)} warning(s))")
        for c in failed:
            print(f"    {check_line(c)}")
    else:
        print(f"  verdict: pass ({len(checks)} checks, {len(warned)} warning(s))")
    expected = _expectation(scenario.expect, summary.get("verdict"))
    if expected:
        print(f"  {expected}")
    timings = summary.get("timings_s", {})
    if timings:
        from sim.pipeline.stages import timings_line

        print("  " + timings_line(timings, summary.get("total_wall_s", sum(timings.values()))))
    print(f"  results in {out}/")
    return 1 if args.strict and summary.get("verdict") == "fail" else 0



def print_findings(summary: dict, unit_of: dict[str, str]) -> None:
    """The run's saturation intervals and collisions, one per line, the first :data:`SHOWN`
    of each; the rest counted, with the worst of all named (``unit_of``: joint -> its unit,
    ``mm`` for a linear axis)."""
    from sim.simulation.collisions import collision_phase

    saturation = summary.get("saturation", [])
    for s in saturation[:SHOWN]:
        force = "N" if unit_of.get(s["joint"]) == "mm" else "N m"
        print(f"  saturation {s['joint']}: {s['t0']:.3f}-{s['t1']:.3f} s ({s['phase']}), "
              f"demand over the drive's limit by up to {s['worst_excess_nm']:.4g} {force}")
    if len(saturation) > SHOWN:  # the worst may be among those not shown: named
        w = max(saturation, key=lambda s: s["worst_excess_nm"])
        force = "N" if unit_of.get(w["joint"]) == "mm" else "N m"
        print(f"  ... and {len(saturation) - SHOWN} more saturation intervals (the worst: "
              f"{w['joint']} {w['t0']:.3f}-{w['t1']:.3f} s, by up to "
              f"{w['worst_excess_nm']:.4g} {force}); all in summary.json")
    collisions = summary.get("collisions", [])
    for c in collisions[:SHOWN]:
        print(f"  collision {c['bodies'][0]} / {c['bodies'][1]}: {c['t0']:.3f}-{c['t1']:.3f} s "
              f"({collision_phase(c)}), {c['depth_mm']:.1f} mm deep ({c['geoms'][0]}, "
              f"{c['geoms'][1]})")
    if len(collisions) > SHOWN:
        w = max(collisions, key=lambda c: c["depth_mm"])
        print(f"  ... and {len(collisions) - SHOWN} more collisions (the deepest: "
              f"{w['bodies'][0]} / {w['bodies'][1]} at {w['t0']:.3f}-{w['t1']:.3f} s, "
              f"{w['depth_mm']:.1f} mm); all in summary.json")

def weld_line(weld: dict) -> str:
    """The console's line for a weld phase (a ``summary["weld"]`` entry): its length, travel
    speed, path deviation and torch angle error, and with corner zones what happens in them
    (left out of the first two figures, so said)."""
    corners = weld.get("corner_path_deviation_mm")
    swing = weld.get("corner_torch_excess_deg")
    return (f"  {_who(weld)}weld {weld['phase']}: {weld['seam_length_mm']:.1f} mm at "
            f"{weld['travel_speed_mm_s']:.2f} mm/s (cv {weld['travel_speed_cv']:.4f}), path "
            f"deviation {weld['max_path_deviation_mm']:.3f} mm, torch angle error "
            f"{weld['torch_angle_error_deg']:.3f} deg"
            + ("" if corners is None else " outside the corner zones; in them the tool point is "
               f"up to {corners:.3f} mm off the seam"
               + ("" if swing is None else f" and the torch swings {swing:.3f} deg out of its "
                  "turn from one leg's posture to the next")))


def _who(entry: dict) -> str:
    """``"<robot>: "`` for an entry of a cell with other robots (its ``"robot"``), else ``""``."""
    return f"{entry['robot']}: " if entry.get("robot") else ""


def _expectation(expect: ExpectSpec, verdict: str | None) -> str | None:
    """One line on the scenario's declared ``[expect]`` verdict when it expects a failure or
    the run does not give the declared verdict (None otherwise); it changes nothing."""
    reason = " ".join((expect.reason or "").split())
    if expect.verdict == "fail" and verdict == "fail":
        return f"expected: the scenario declares this failure ([expect]): {reason}"
    if expect.verdict != verdict and not expect.model_fields_set:  # no [expect] table
        return (f"unexpected: verdict {verdict!r}; the scenario expects {expect.verdict!r} (it "
                "has no [expect] table declaring a failure)")
    if expect.verdict != verdict:
        return (f"unexpected: the scenario declares verdict {expect.verdict!r} ([expect])"
                + (f": {reason}" if reason else ""))
    return None

"""The scenario runner: build the cell, plan, simulate with the drives, record, judge.

``run_scenario`` is what ``cellsim run`` does:

1. compose the cell (robot, tool, fixtures, cameras) with ``dm_control.mjcf`` and compile it
   (:mod:`sim.simulation.compile`);
2. plan every phase into one reference motion (:mod:`sim.simulation.motion`) and check it
   against the joint ranges, speed and acceleration limits;
3. simulate: each joint's drive (a position actuator limited to the drive's peak torque)
   tracks the reference with the inverse-dynamics feed-forward through the same actuator
   (:mod:`sim.simulation.simulate`);
4. record the tool-point path and the continuous-time joint torques, compute the summary
   metrics, the drives' saturation intervals, collisions and clearance
   (:mod:`sim.simulation.collisions`);
5. size the drives (and choose actuators from a catalogue when asked), judge the run
   (:mod:`sim.analysis.verdict`: ``"checks"`` and ``"verdict"`` in ``summary.json``), draw the
   plots and the video, and write the run folder atomically through
   :mod:`sim.simulation.runfolder`.

Each stage is timed and reported (:mod:`sim.pipeline.stages`): a status line on a terminal, one
line per stage on standard error otherwise; ``summary.json`` holds ``"timings_s"`` per stage and
``"total_wall_s"``.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim import __version__
from sim.analysis.sizing import SizingResult
from sim.analysis.verdict import run_checks, verdict, warnings_count
from sim.errors import InternalError, RenderError, RunFolderError
from sim.pipeline.loads import heaviest_part_kg, tool_load
from sim.pipeline.options import check_run_options
from sim.pipeline.stages import Stages
from sim.scenario import Scenario
from sim.simulation import runfolder
from sim.simulation.build_cache import build_reusing
from sim.simulation.compile import BuiltCell, build
from sim.simulation.metrics import make_summary
from sim.simulation.motion import build_motion, check_motion_limits, check_size
from sim.simulation.motion.axes import world_from_frame0 as frame0_in_world
from sim.simulation.robot_metrics import add_robots
from sim.simulation.simulate import simulate


@dataclass
class RunOptions:
    """Options of one run.

    Attributes:
        out_dir: Run folder (default ``runs/<scenario name>``).
        video: Write ``video.mp4``.
        feedforward: Override the scenario's ``simulation.feedforward``.
        video_args: Keyword arguments for :func:`sim.render.video.write_video` (cameras, width,
            height, fps, gl, jobs).
        plots: Write ``plots/*.png``.
        sizing: Write the actuator-sizing report.
        progress: Show progress bars (they are silent anyway when stderr is not a terminal).
        csv: Also write ``trajectory.csv`` (the main arrays as columns; large: about 0.5 MB
            per second of cycle at 1 kHz).
        selection: Choose a motor and a reducer per joint from a catalogue
            (:mod:`sim.analysis.selection`; ``selection.json``/``.csv``, a report section and a
            ``selection`` check per joint): the loaded settings (:func:`selection_options`);
            for :func:`sim.evaluate` and :func:`sim.run` also True (the scenario's
            catalogue, or the starter), a catalogue file's path, or False; None: the
            scenario's ``[sizing] select`` decides there, no selection here.
        backend: ``"mujoco"`` (MuJoCo in C) or ``"warp"`` (MuJoCo Warp, float32, on a GPU
            where there is one: :mod:`sim.simulation.warp_batch`).
    """

    out_dir: Path | None = None
    video: bool = True
    feedforward: bool | None = None
    video_args: dict[str, Any] = field(default_factory=dict)
    plots: bool = True
    sizing: bool = True
    progress: bool = True
    selection: Any = None
    csv: bool = False
    backend: str = "mujoco"

    def __post_init__(self) -> None:
        check_run_options(self)  # each option of its kind, or one line naming it


# --------------------------------------------------------------------------------------------
# Run folder
# --------------------------------------------------------------------------------------------


def _git_commit() -> str | None:
    try:
        res = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                             cwd=Path(__file__).resolve().parent, timeout=5)
        return res.stdout.strip() or None if res.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return None


def manifest(scenario: Scenario) -> dict[str, Any]:
    import mujoco

    return {
        "cellsim": __version__,
        "mujoco": mujoco.__version__,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "git_commit": _git_commit(),
        "scenario": scenario.name,
        "scenario_sha256": scenario.sha256,
    }


def default_out_dir(scenario: Scenario) -> Path:
    return Path("runs") / scenario.name


@dataclass
class Evaluation:
    """A run evaluated in memory: what a run folder would hold, before anything is written.

    Attributes:
        summary: The summary (metrics, checks, verdict; ``summary.json``'s content).
        record: Every recorded sample (:class:`~sim.simulation.runfolder.RunRecord`).
        sizing: The sizing result, or None when sizing was off.
        selection: The actuator selection, or None when none was asked for.
        built: The compiled cell.
    """

    summary: dict[str, Any]
    record: runfolder.RunRecord
    sizing: SizingResult | None
    selection: Any
    built: BuiltCell


#: Plans kept for reuse by metrics-only evaluations in this process (a sweep's variants that
#: differ only in payload share their motion: planning does not depend on the payload).
_PLANS: dict[str, Any] = {}
_PLANS_KEPT = 4


def _plan_key(scenario: Scenario) -> str | None:
    """What a plan depends on: the scenario without its payload (None when it cannot be
    fingerprinted; then nothing is reused)."""
    import dataclasses
    import hashlib
    import pickle

    try:
        blob = pickle.dumps(dataclasses.replace(scenario, payload_kg=0.0))
    except Exception:  # noqa: BLE001 - an unpicklable scenario is planned every time
        return None
    return hashlib.sha256(blob).hexdigest()


def _prepare(scenario: Scenario, options: RunOptions, stages: Stages, *, reuse_plan: bool = False
             ) -> tuple[BuiltCell, Any, dict[str, Any]]:
    """Build the cell and plan the motion; refuse bad video settings before simulating. With
    ``reuse_plan`` a motion planned for the same scenario in this process (another payload)
    is reused."""
    with stages.stage("build"):  # another payload's cell is reused with the plan
        built = (build_reusing if reuse_plan else build)(scenario)
        _check_tcp_consistency(built, scenario)
        video_args = _video_args(scenario, options)
        if options.video:  # refuse bad video settings before simulating, not after
            from sim.render.video import check_video_args

            check_video_args(built.model, video_args)
    with stages.stage("plan"):
        key = _plan_key(scenario) if reuse_plan else None
        motion = _PLANS.get(key) if key is not None else None
        if motion is None:
            motion = build_motion(scenario, built.context)
            check_motion_limits(scenario, motion)
            if key is not None:
                _PLANS[key] = motion
                while len(_PLANS) > _PLANS_KEPT:
                    _PLANS.pop(next(iter(_PLANS)))
        check_size(scenario, motion, float(built.model.opt.timestep))
    return built, motion, video_args


def _feedforward(scenario: Scenario, options: RunOptions) -> bool:
    return (scenario.simulation.feedforward if options.feedforward is None
            else options.feedforward)


def _drives(scenario: Scenario) -> Any:
    """The drives whose torque-speed curves limit the simulation, or None."""
    drives = scenario.drive_train
    return drives if scenario.simulation.motor_speed_limits and drives else None


def simulate_batch(scenarios: list[Scenario], prepared: list[tuple[BuiltCell, Any]],
                   options: RunOptions, labels: list[str] | None = None) -> list[Any]:
    """Simulate prepared variants on MuJoCo Warp, one batch per model structure (every
    payload, 0 kg included, has the same: a payload body, massless at 0 kg); records in
    order."""
    from sim.simulation.warp_batch import simulate_batch as warp_batch

    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, (built, _) in enumerate(prepared):
        m = built.model
        key = (m.nq, m.nv, m.nu, m.nbody, m.njnt, m.ngeom, m.nsite, m.nsensordata, m.neq,
               float(m.opt.timestep), _feedforward(scenarios[i], options),
               float(scenarios[i].simulation.settle_s))
        groups.setdefault(key, []).append(i)
    records: list[Any] = [None] * len(prepared)
    names = labels or [s.name for s in scenarios]
    for key, members in groups.items():
        got = warp_batch([prepared[i][0] for i in members], [prepared[i][1] for i in members],
                         feedforward=key[-2], settle_s=key[-1],
                         drives=[_drives(scenarios[i]) for i in members],
                         labels=[names[i] for i in members])
        for i, rec in zip(members, got, strict=True):
            records[i] = rec
    return records


def _judge(scenario: Scenario, built: BuiltCell, motion: Any, options: RunOptions,
           stages: Stages, *, on_failure: Any = None, model_path: Path | None = None,
           rec: Any = None, collide: Any = None) -> Evaluation:
    """Simulate (unless ``rec``, a record simulated already, is given), check (collisions,
    clearance, limits; ``collide``: instead of :func:`add_collisions`, same arguments), size,
    select, judge; writes nothing."""
    feedforward = _feedforward(scenario, options)
    if options.backend not in ("mujoco", "warp"):
        from sim.errors import SimulationError

        raise SimulationError(f"unknown backend {options.backend!r}; valid: mujoco, warp")
    with stages.stage("simulate"):
        if rec is None and options.backend == "warp":
            rec = simulate_batch([scenario], [(built, motion)], options)[0]
        elif rec is None:
            rec = simulate(built, motion, feedforward=feedforward,
                           settle_s=scenario.simulation.settle_s, progress=options.progress,
                           on_failure=on_failure, drives=_drives(scenario))
    arrays = rec.arrays
    with stages.stage("checks"):
        summary = make_summary(scenario, built, motion, rec, feedforward)
        if motion.lanes:  # a cell's other robots measured as the first is
            add_robots(summary, scenario, built, motion, rec)
        (collide or add_collisions)(summary, built, motion, arrays)
    # post-processing reads the record in memory, never the files a run writes
    record = runfolder.RunRecord.from_arrays(
        arrays, joints=list(summary["joints"]), phases=summary["phases"],
        model_path=model_path, model_xml=None if model_path is not None else lambda: built.xml,
        summary=summary)
    with stages.stage("sizing"):
        sizing = _size(scenario, built, record, summary) if options.sizing else None
        selected = None
        if options.selection is not None:
            from sim.analysis.selection import select_actuators
            from sim.analysis.sizing import joint_armature

            selected = select_actuators(record, built.joint_ids,
                                        joint_armature(built.model, built.joint_ids),
                                        options.selection)
            summary["selection"] = {
                "catalog": list(options.selection.catalog.sources),
                "all_joints_served": selected.all_served,
                "joints": {j.joint: {"motor": j.chosen.motor.id if j.chosen else None,
                                     "reducer": j.chosen.reducer.id if j.chosen else None}
                           for j in selected.joints}}
        checks = run_checks(arrays, summary, scenario.system,
                            scenario.simulation.tracking_tolerance_deg, sizing,
                            tracking_tolerance_mm=scenario.simulation.tracking_tolerance_mm,
                            clearance_mm=scenario.simulation.clearance_mm,
                            selection=selected,
                            torch_angle_tolerance_deg=(
                                scenario.simulation.torch_angle_tolerance_deg),
                            flange_load_kg=(built.cell.tool.mass_kg if built.cell.tool else 0.0,
                                            scenario.payload_kg),
                            tool_load=tool_load(built, scenario.payload_kg),
                            held_part_kg=heaviest_part_kg(built),
                            partner_loads=[(cr.name, cr.robot,
                                            cr.tool.mass_kg if cr.tool is not None else 0.0)
                                           for cr in built.cell.partners])
        summary["checks"] = [c.to_dict() for c in checks]
        summary["verdict"] = verdict(checks)
        summary["warnings"] = warnings_count(checks)
    return Evaluation(summary, record, sizing, selected, built)


def evaluate_scenario(scenario: Scenario, options: RunOptions | None = None) -> Evaluation:
    """Everything a run computes (summary, checks, verdict, sizing, selection), in memory:
    no run folder, no plots, no video. What a metrics-only sweep variant does.

    Raises:
        CellsimError: A user mistake or an unstable simulation (one-line message).
    """
    return evaluate_scenarios([scenario], options)[0]


def evaluate_scenarios(scenarios: list[Scenario], options: RunOptions | None = None,
                       labels: list[str] | None = None, collide: Any = None
                       ) -> list[Evaluation]:
    """:func:`evaluate_scenario` for several scenarios; with ``options.backend == "warp"``
    their simulations run as MuJoCo Warp batches (one per model structure), the rest (plans,
    checks, sizing) one by one on the host. ``labels`` name the scenarios in errors;
    ``collide`` replaces :func:`add_collisions` (a sweep's reuse of its plan's scan).

    Raises:
        CellsimError: A user mistake or an unstable simulation (one-line message).
    """
    options = options or RunOptions(video=False, plots=False)
    quiet = RunOptions(**{**options.__dict__, "video": False})
    staged = [Stages(enabled=False) for _ in scenarios]
    prepared = [_prepare(s, quiet, st, reuse_plan=True)[:2]
                for s, st in zip(scenarios, staged, strict=True)]
    records: list[Any] = [None] * len(scenarios)
    if options.backend == "warp":
        import time

        start = time.perf_counter()
        records = simulate_batch(scenarios, prepared, options, labels)
        share = (time.perf_counter() - start) / len(scenarios)
        for st in staged:
            st.timings["simulate_batch"] = share
    out = []
    for s, (built, motion), st, rec in zip(scenarios, prepared, staged, records, strict=True):
        evaluation = _judge(s, built, motion, options, st, rec=rec, collide=collide)
        evaluation.summary["timings_s"] = dict(st.timings)
        evaluation.summary["total_wall_s"] = st.total_s
        evaluation.summary["backend"] = options.backend
        out.append(evaluation)
    return out


def run_scenario(scenario: Scenario, options: RunOptions | None = None) -> dict[str, Any]:
    """Run a scenario and write its run folder; returns the summary.

    The folder is built in a temporary sibling and moved into place at the end, so a failed
    run never leaves a ``summary.json``. A run that fails mid-simulation keeps what it recorded
    in ``<out_dir>.failed/`` with ``error.txt``.

    Raises:
        CellsimError: A user mistake or an unstable simulation (one-line message).
    """
    return run_and_write(scenario, options).summary


def run_and_write(scenario: Scenario, options: RunOptions | None = None) -> Evaluation:
    """:func:`run_scenario`, returning the whole evaluation in memory (every sample, not only
    what ``trajectory.npz`` keeps at ``record_hz``) besides writing the run folder."""
    options = options or RunOptions()
    out_dir = runfolder.check_out_dir(options.out_dir if options.out_dir
                                      else default_out_dir(scenario))
    stages = Stages(enabled=options.progress)
    built, motion, video_args = _prepare(scenario, options, stages)

    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunFolderError(f"{out_dir.parent}: cannot create the run folder's parent: "
                             f"{exc.strerror or exc}") from None
    # one writer per place: a second run into it refuses; what a killed run left goes
    with runfolder.RunLock(out_dir):
        runfolder.remove_stale(out_dir)
        tmp = runfolder.make_folder(f".{out_dir.name}.", out_dir.parent)
        try:
            runfolder.write_marker(tmp, state="writing")
            runfolder.write_text(tmp, runfolder.MODEL_XML, built.xml)
            runfolder.write_text(tmp, runfolder.SCENARIO_TOML, scenario.text)
            runfolder.write_text(tmp, runfolder.MANIFEST_JSON,
                                 json.dumps(manifest(scenario), indent=1) + "\n")

            def keep_failed(partial: dict[str, NDArray[Any]], message: str) -> None:
                runfolder.write_marker(tmp, state="failed")
                runfolder.write_trajectory(tmp, partial)
                runfolder.write_text(tmp, runfolder.ERROR_TXT, message + "\n")
                failed = runfolder.failed_folder(out_dir)
                if runfolder.is_run_folder(failed):
                    shutil.rmtree(failed)
                elif failed.exists() or failed.is_symlink():  # not ours: never replaced
                    failed = runfolder.make_folder(failed.name + "-", out_dir.parent)
                    failed.rmdir()
                os.replace(tmp, failed)

            evaluation = _judge(scenario, built, motion, options, stages,
                                on_failure=keep_failed, model_path=tmp / runfolder.MODEL_XML)
            summary, record = evaluation.summary, evaluation.record
            sizing, selected = evaluation.sizing, evaluation.selection
            arrays = record.arrays
            if selected is not None:
                from sim.analysis.selection import write_selection

                write_selection(tmp, selected)
            # the folder only becomes visible (moved into place) once everything succeeded
            if options.plots:
                with stages.stage("plots"):
                    from sim.analysis.plots import write_plots

                    write_plots(record, tmp / runfolder.PLOTS_DIR)
            if options.video:
                with stages.stage("video"):
                    from sim.render.video import write_video

                    write_video(record, tmp / runfolder.VIDEO_MP4, progress=options.progress,
                                **video_args)
                    summary["video"] = runfolder.VIDEO_MP4
            saved = runfolder.decimate(arrays, built.model.opt.timestep,
                                       scenario.simulation.record_hz)
            replay = None
            if sizing is not None:  # the 3D replay of report.html (sim.analysis.replay)
                with stages.stage("replay"):
                    from sim.analysis.replay import replay_html

                    replay = replay_html(tmp / runfolder.MODEL_XML, saved, summary)
            with stages.stage("write"):
                summary["record_hz"] = runfolder.sample_rate(saved["t"])
                runfolder.write_trajectory(tmp, saved)
                if options.csv:
                    runfolder.write_csv(tmp, saved, scenario.system.joints)
                if sizing is not None:  # last: report.html links the video, shows the verdict
                    from sim.analysis.report import write_sizing

                    write_sizing(tmp, sizing, summary=summary, selection=selected, replay=replay)
            summary["timings_s"] = dict(stages.timings)
            summary["total_wall_s"] = stages.total_s
            summary["backend"] = options.backend
            runfolder.write_summary(tmp, summary)
            runfolder.write_marker(tmp, state="complete")
            runfolder.check_out_dir(out_dir)  # again: the place may have changed while we ran
        except RenderError as exc:  # name the run folder, not its hidden temporary sibling
            shutil.rmtree(tmp, ignore_errors=True)
            if str(tmp) in str(exc):
                raise RenderError(str(exc).replace(str(tmp), str(out_dir))) from exc
            raise
        except OSError as exc:
            shutil.rmtree(tmp, ignore_errors=True)
            # the user knows the run folder, not its hidden temporary sibling (gone by now)
            where = str(exc.filename) if exc.filename is not None else ""
            if where.startswith(str(tmp)):
                where = str(out_dir) + where[len(str(tmp)):]
            if exc.errno is None:
                raise
            raise OSError(exc.errno, exc.strerror or str(exc),
                          f"{where or out_dir} (nothing was replaced)") from exc
        except BaseException:
            if tmp.exists():
                shutil.rmtree(tmp, ignore_errors=True)
            raise
        if out_dir.exists():
            trash = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.old.", dir=out_dir.parent))
            os.replace(out_dir, trash / "old")
            shutil.rmtree(trash, ignore_errors=True)
        os.replace(tmp, out_dir)
        stale = runfolder.failed_folder(out_dir)
        if runfolder.is_run_folder(stale):
            shutil.rmtree(stale, ignore_errors=True)
    return evaluation


def add_collisions(summary: dict[str, Any], built: BuiltCell, motion: Any,
                   arrays: dict[str, NDArray[Any]]) -> None:
    """Check the recorded motion for collisions and clearance (:mod:`sim.simulation.collisions`)
    and put ``collisions``, ``clearance``, ``allowed_contacts`` and ``collision_check_s`` in
    the summary."""
    import time

    from sim.simulation.collisions import (
        check_motion,
        phase_seams,
        phase_weaves,
        samples_from_arrays,
    )

    start = time.perf_counter()
    report = check_motion(built, samples_from_arrays(arrays, motion),
                          [pm.name for pm in motion.phases],
                          phase_seams(motion), weaves=phase_weaves(motion))
    summary["collisions"] = report.collisions
    summary["clearance"] = report.clearance
    summary["allowed_contacts"] = report.allowed
    summary["collision_check_s"] = time.perf_counter() - start


def selection_options(scenario: Scenario, *, catalog: str | Path | None = None,
                      life_h: float | None = None, dwell_s: float | None = None,
                      rank: str | None = None, inertia_ratio_max: float | None = None) -> Any:
    """The selection settings of a run: the scenario's ``[sizing]`` keys, overridden by the
    given values (command-line flags). The catalogue is loaded here (the scenario's
    ``catalog`` is relative to the scenario file; the default is the shipped starter).

    Raises:
        CatalogError: The catalogue is missing or malformed.
        ScenarioError: A bad override (negative life, unknown rank, ...).
    """
    from sim.analysis.catalog import load_catalog, starter_catalog
    from sim.analysis.selection import RANKS, SelectionOptions
    from sim.errors import CatalogError, ScenarioError

    spec = scenario.sizing
    if catalog is not None:
        path = Path(catalog)
    elif spec.catalog is not None:
        path = Path(spec.catalog)
        if not path.is_absolute():
            path = scenario.source.parent / path
    else:
        path = starter_catalog()
    values = {"life_h": spec.life_h if life_h is None else life_h,
              "dwell_s": spec.dwell_s if dwell_s is None else dwell_s,
              "inertia_ratio_max": (spec.inertia_ratio_max if inertia_ratio_max is None
                                    else inertia_ratio_max)}
    for key, value in values.items():
        low = 0.0 if key == "dwell_s" else None
        if not np.isfinite(value) or (value < 0 if low == 0.0 else value <= 0):
            raise ScenarioError(f"--{key.replace('_', '-')}: must be a finite number "
                                f"{'>= 0' if low == 0.0 else '> 0'}, got {value!r}")
    rank = spec.rank if rank is None else rank
    if rank not in RANKS:
        raise ScenarioError(f"--rank: must be one of {', '.join(RANKS)}, got {rank!r}")
    cat = load_catalog(path)
    for kind, entries in (("motors", cat.motors), ("reducers", cat.reducers)):
        if not entries:  # every joint's pair is a motor and a reducer
            raise CatalogError(f"{cat.sources[0]}: the catalogue has no [[{kind}]]; the "
                               "selection pairs a motor with a reducer for every joint")
    return SelectionOptions(cat, rank=rank, inertia_ratio=spec.inertia_ratio, **values)


def _video_args(scenario: Scenario, options: RunOptions) -> dict[str, Any]:
    v = scenario.video
    args: dict[str, Any] = {}
    if v.cameras:
        args["cameras"] = tuple(v.cameras)
    for key in ("width", "height", "fps", "speed"):
        if getattr(v, key) is not None:
            args[key] = getattr(v, key)
    args.update({k: val for k, val in options.video_args.items() if val is not None})
    return args


def _size(scenario: Scenario, built: BuiltCell, record: runfolder.RunRecord,
          summary: dict[str, Any]) -> SizingResult:
    """Size the run's drives; the summary gets the ``sizing`` headline."""
    from sim.analysis.sizing import joint_armature, size_record

    # the compiled model's drive force range and armature are the same drives'
    # (Scenario.drive_train): the joint torque is checked against the drive's own limit
    result = size_record(record, scenario.system, scenario.drive_train, built.force_limits,
                         armature=joint_armature(built.model, built.joint_ids))
    summary["sizing"] = {"hardest_joint": result.hardest_joint,
                         "hardest_margin_pct": result.hardest_margin_pct,
                         "pass": bool(result.all_pass),
                         "verdict": result.verdict}
    return result


def _check_tcp_consistency(built: BuiltCell, scenario: Scenario) -> None:
    """The closed-form kinematics (with the tool) must place the tcp where MuJoCo does."""
    import mujoco

    model = built.model
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    lo = model.jnt_range[built.joint_ids, 0]
    hi = model.jnt_range[built.joint_ids, 1]
    q = lo + (hi - lo) * rng.uniform(0.3, 0.7, size=lo.size)
    data.qpos[built.robot_qpos] = q
    mujoco.mj_kinematics(model, data)
    site = built.tcp_site
    kin = built.context.kinematics
    T0 = frame0_in_world(built.context, q[kin.n_joints:])  # a track carries frame 0
    T = np.asarray(kin.fk(q[:kin.n_joints]), dtype=float)
    p_cf = T0[:3, :3] @ T[:3, 3] + T0[:3, 3]
    R_cf = T0[:3, :3] @ T[:3, :3]
    err = float(np.linalg.norm(data.site_xpos[site] - p_cf))
    rerr = float(np.max(np.abs(data.site_xmat[site].reshape(3, 3) - R_cf)))
    if err > 1e-6 or rerr > 1e-6:
        raise InternalError(f"closed-form tcp and MuJoCo tcp differ by "
                           f"{err * 1e3:.3f} mm / {rerr:.2e} in rotation for robot "
                           f"{scenario.robot.name} with tool "
                           f"{None if scenario.tool is None else scenario.tool.name!r}")


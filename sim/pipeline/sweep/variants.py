"""A sweep's variants: one ``(payload, speed scale)`` point each (:class:`Variant`), their
validation, what running one gives (:class:`Outcome`, from a run folder or from the
:class:`VariantMetrics` a metrics-only runner returns) and their rows of ``sweep.csv``."""

from __future__ import annotations

import json
import math
import re
import time
import traceback
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.analysis.sizing import (
    PEAK_WINDOW_S,
    load_summary,
    load_trajectory,
    peak_abs,
    rms,
    sustained,
)
from sim.errors import CellsimError, CellsimWarning, SweepError
from sim.scenario.schema import MAX_PAYLOAD_KG
from sim.simulation.runfolder import SIZING_JSON

#: Most variants of a sweep.
MAX_SWEEP_VARIANTS = 10_000


def _as_values(given: Any, field: str, example: str) -> list[float]:
    """``given`` as a list of floats: a sequence of real numbers, or one number; a string,
    a bool (``True`` is not 1 kg) or anything else that is not a number is a
    :class:`SweepError` naming ``field`` (the Python face's counterpart of the command line's
    parsing, :func:`sim.cli.size.parse_float_list`)."""
    import numbers

    if isinstance(given, (str, bytes)):
        raise SweepError(f"{field}: expected numbers like {example}, got the text {given!r} "
                         "(give a list of numbers)")
    items = [given] if isinstance(given, numbers.Real) else given
    try:
        items = list(items)
    except TypeError:
        raise SweepError(f"{field}: expected numbers like {example}, got "
                         f"{type(given).__name__} {given!r}") from None
    for v in items:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise SweepError(f"{field}: {v!r} is not a number (expected numbers like "
                             f"{example})")
    return [float(v) for v in items]


def unique_values(values: list[float], field: str) -> list[float]:
    """``values`` without repeats (first order kept); a warning names the repeated ones (each
    variant runs once)."""
    out = list(dict.fromkeys(values))
    if len(out) < len(values):
        repeated = sorted({v for v in values if values.count(v) > 1})
        warnings.warn(CellsimWarning(
            f"{field}: {', '.join(f'{v:.12g}' for v in repeated)} given more than once; "
            "each variant runs once"), stacklevel=3)
    return out


def validate_payloads(payloads: Sequence[float], field: str = "payload") -> list[float]:
    """Payloads in kg: 0 to :data:`~sim.scenario.schema.MAX_PAYLOAD_KG`, at least one;
    duplicates dropped. One number is a list of one.

    Raises:
        SweepError: One line naming ``field`` and the bad value (a string, a bool or another
            non-number too).
    """
    values = _as_values(payloads, field, "[0, 2.5, 5]")
    if not values:
        raise SweepError(f"{field}: no payload given (expected kg values like 0,2.5,5)")
    for p in values:
        if not math.isfinite(p) or p < 0 or p > MAX_PAYLOAD_KG:
            raise SweepError(f"{field}: payload must be a mass of 0 to {MAX_PAYLOAD_KG:g} kg, "
                             f"got {p:g}")
    return unique_values(values, field)


def validate_speed_scales(scales: Sequence[float], field: str = "speed scale") -> list[float]:
    """Speed scales: finite, > 0, at least one; duplicates dropped. One number is a list of
    one.

    Raises:
        SweepError: One line naming ``field`` and the bad value (a string, a bool or another
            non-number too).
    """
    values = _as_values(scales, field, "[0.5, 1, 1.5]")
    if not values:
        raise SweepError(f"{field}: no speed scale given (expected factors like 0.5,1,1.5)")
    for s in values:
        if not math.isfinite(s) or s <= 0:
            raise SweepError(f"{field}: speed scale must be a finite factor > 0 "
                             f"(1 = as planned, 2 = twice as fast), got {s:g}")
    return unique_values(values, field)


@dataclass(frozen=True)
class Variant:
    """One point of a sweep.

    Attributes:
        payload_kg: Payload at the tool, kg.
        speed_scale: Knot times are divided by this factor.
        scenario: The base scenario, passed to the runner unchanged (a name, a path or a
            loaded scenario object; must be picklable).
        run_dir: Suggested run folder for this variant (inside the sweep's ``out_dir``).
        index: Position in the sweep (payload-major order).
    """

    payload_kg: float
    speed_scale: float
    scenario: Any = None
    run_dir: Path = Path(".")
    index: int = 0

    @property
    def label(self) -> str:
        return f"payload {self.payload_kg:.12g} kg, speed x{self.speed_scale:.12g}"

    @property
    def slug(self) -> str:
        """Folder-safe name, e.g. ``payload_2.5kg_speed_1.5x``."""
        return re.sub(r"[^A-Za-z0-9_.-]", "_",
                      f"payload_{self.payload_kg:g}kg_speed_{self.speed_scale:g}x")


def make_variants(base_scenario: Any, payloads: Sequence[float], speed_scales: Sequence[float],
                  out_dir: str | Path) -> list[Variant]:
    """Every ``(payload, speed_scale)`` combination, payload-major, validated."""
    ps = validate_payloads(payloads)
    ss = validate_speed_scales(speed_scales)
    if len(ps) * len(ss) > MAX_SWEEP_VARIANTS:  # each list may be long, not their product
        raise SweepError(f"{len(ps)} payloads x {len(ss)} speed scales make "
                         f"{len(ps) * len(ss)} variants (at most {MAX_SWEEP_VARIANTS})")
    out = Path(out_dir)
    combos = [(p, s) for p in ps for s in ss]
    names = [Variant(p, s).slug for p, s in combos]
    clash = {n for n in names if names.count(n) > 1}
    # values that print alike (1.0000001 and 1.0000002 kg: both "1") get their exact digits,
    # so that no two variants share a run folder
    names = [re.sub(r"[^A-Za-z0-9_.-]", "_", f"payload_{p!r}kg_speed_{s!r}x") if n in clash
             else n for n, (p, s) in zip(names, combos, strict=True)]
    return [Variant(p, s, base_scenario, out / name, i)
            for i, ((p, s), name) in enumerate(zip(combos, names, strict=True))]


@dataclass(frozen=True)
class Outcome:
    """What one variant gave: its rows of sweep.csv, or the error that stopped it."""

    variant: Variant
    run_dir: str | None
    rows: tuple[dict[str, Any], ...] = ()
    error: str | None = None
    traceback: str | None = None
    wall_s: float = 0.0
    selection: dict[str, Any] | None = None
    timings_s: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class VariantMetrics:
    """What a metrics-only runner returns instead of a run folder: the variant's rows of
    sweep.csv, computed where the variant ran from every sample in memory, its actuator
    selection (``selection.json``'s content) when one was made, its stage timings, and its run
    folder when one was kept. Small: what crosses a process or a cluster is a few numbers per
    joint, never the arrays."""

    rows: tuple[dict[str, Any], ...]
    selection: dict[str, Any] | None = None
    timings_s: dict[str, float] = field(default_factory=dict)
    run_dir: str | None = None


#: Most failed checks a row names (then how many more there are).
FAILED_CHECKS_LISTED = 3


def failed_checks_text(summary: Mapping[str, Any]) -> str:
    """Why a variant's verdict failed, for its rows: each failed check of severity error as
    ``name: subject`` (``tool_payload: the vacuum_gripper holds 2.75 kg, rated 2.04 kg``), or
    ``name: joint`` for a joint's check without a subject (``saturation: j2``), the first
    :data:`FAILED_CHECKS_LISTED`, then how many more; "" when none failed."""
    failed = [c for c in summary.get("checks", ())
              if not c.get("pass", True) and c.get("severity", "error") == "error"]
    text = "; ".join(f"{c.get('name', '?')}: {c.get('subject') or c.get('joint') or ''}"
                     .rstrip(": ")
                     for c in failed[:FAILED_CHECKS_LISTED])
    more = len(failed) - FAILED_CHECKS_LISTED
    return text + (f"; and {more} more" if more > 0 else "")


def rows_from(variant: Variant, arrays: Mapping[str, NDArray[Any]], joints: Sequence[str],
              verdict: str, sized: Mapping[str, Mapping[str, Any]], run_dir: str = "",
              stats: Mapping[str, Mapping[str, Any]] | None = None,
              failed: str = "") -> list[dict[str, Any]]:
    """Rows of sweep.csv for one variant (one per joint), from its recorded arrays.

    Args:
        variant: The variant.
        arrays: ``t``, ``tau``, ``tau_id``, ``qd_ref``, ``qd`` (N samples; torques N m,
            speeds rad/s).
        joints: Joint names, one per column.
        verdict: The run's verdict (``"pass"``/``"fail"``).
        sized: ``sizing.json``'s joints by name (``margin_pct``, ``pass``, ``limiting``);
            empty when the run was not sized.
        run_dir: The variant's run folder ("" when none was kept).
        failed: Why the verdict failed (:func:`failed_checks_text`), "" when it passed.
        stats: The sizing's joint-side statistics of these arrays by joint and source
            (:attr:`sim.analysis.sizing.JointSizing.stats`: ``"id"`` with no window, ``"sim"``
            sustained over :data:`~sim.analysis.sizing.PEAK_WINDOW_S`), or None: the peaks,
            RMS values, speeds and powers are taken from them instead of computed again (the
            same functions of the same samples: the same values, bit for bit).

    Peak and RMS torques are computed from both sources; the unsuffixed value is the larger.
    The simulated peaks are of the torque sustained over
    :data:`~sim.analysis.sizing.PEAK_WINDOW_S`, as sizing takes them.
    """
    t = np.asarray(arrays["t"], dtype=float)
    rows = []
    given = _usable_stats(arrays, joints, stats)
    for k, name in enumerate(joints):
        if given is not None:
            sid, ssim = given[name]["id"], given[name]["sim"]
            pk_id, pk_sim = sid.peak_torque, ssim.peak_torque
            rms_id, rms_sim = sid.rms_torque, ssim.rms_torque
            speed = max(sid.peak_speed, ssim.peak_speed)
            power = max(sid.peak_power, ssim.peak_power)
        else:
            pk_id, pk_sim, rms_id, rms_sim, speed, power = _joint_figures(t, arrays, k)
        s = sized.get(name, {})
        margin = s.get("margin_pct")
        rows.append({
            "payload_kg": variant.payload_kg, "speed_scale": variant.speed_scale, "joint": name,
            "peak_torque_nm": max(pk_id, pk_sim), "rms_torque_nm": max(rms_id, rms_sim),
            "peak_torque_id_nm": pk_id, "peak_torque_sim_nm": pk_sim,
            "rms_torque_id_nm": rms_id, "rms_torque_sim_nm": rms_sim,
            "peak_speed_rad_s": speed, "peak_power_w": power,
            "duration_s": float(t[-1] - t[0]),
            "margin_pct": float("nan") if margin is None else float(margin),
            "pass": ("PASS" if s["pass"] else "FAIL") if "pass" in s else "",
            "limiting": s.get("limiting") or "",
            "verdict": verdict,
            "failed_checks": failed,
            "run_dir": str(run_dir),
        })
    return rows


def _joint_figures(t: NDArray[np.float64], arrays: Mapping[str, NDArray[Any]], k: int
                   ) -> tuple[float, float, float, float, float, float]:
    """Column ``k``'s peak torques (reference, simulated), RMS torques (the same), peak speed
    and peak power, as :func:`rows_from` gives them."""
    tau_id, tau = arrays["tau_id"][:, k], arrays["tau"][:, k]
    pk_id, _ = peak_abs(t, tau_id)
    # the simulated source's peaks as sizing takes them: sustained over PEAK_WINDOW_S
    pk_sim, _ = peak_abs(t, sustained(t, tau, PEAK_WINDOW_S))
    rms_id = float(rms(t, tau_id))
    rms_sim = float(rms(t, tau))
    speed = max(peak_abs(t, arrays["qd_ref"][:, k])[0], peak_abs(t, arrays["qd"][:, k])[0])
    power = max(peak_abs(t, tau_id * arrays["qd_ref"][:, k])[0],
                peak_abs(t, sustained(t, tau * arrays["qd"][:, k], PEAK_WINDOW_S))[0])
    return pk_id, pk_sim, rms_id, rms_sim, speed, power


def _usable_stats(arrays: Mapping[str, NDArray[Any]], joints: Sequence[str],
                  stats: Mapping[str, Mapping[str, Any]] | None
                  ) -> Mapping[str, Mapping[str, Any]] | None:
    """``stats`` when they are what :func:`_joint_figures` would compute: every joint with
    both sources, the reference's without a window and the simulation's over
    :data:`PEAK_WINDOW_S`, and float64 arrays (the sizing reads them as float64); else
    None."""
    if stats is None:
        return None
    if any(np.asarray(arrays[key]).dtype != np.float64
           for key in ("t", "tau_id", "tau", "qd_ref", "qd")):
        return None
    for name in joints:
        by_source = stats.get(name)
        if (by_source is None or "id" not in by_source or "sim" not in by_source
                or by_source["id"].window != 0.0
                or by_source["sim"].window != PEAK_WINDOW_S):
            return None
    return stats


def variant_rows(variant: Variant, run_dir: str | Path) -> list[dict[str, Any]]:
    """Rows of sweep.csv for one variant whose run folder was written (one per joint): the
    arrays from ``trajectory.npz``, the margins from ``sizing.json`` when there is one."""
    traj = load_trajectory(run_dir)
    summary = load_summary(run_dir)
    n = traj["tau"].shape[1]
    names = list(summary.get("joints") or [f"j{k + 1}" for k in range(n)])
    sizing_path = Path(run_dir) / SIZING_JSON
    sized: dict[str, dict[str, Any]] = {}
    if sizing_path.is_file():
        try:
            sized = {j["joint"]: j for j in json.loads(sizing_path.read_text()).get("joints", [])}
        except (json.JSONDecodeError, KeyError, TypeError):
            sized = {}
    return rows_from(variant, traj, names, summary.get("verdict", ""), sized, str(run_dir),
                     failed=failed_checks_text(summary))


def outcome_of(variant: Variant, got: Any, wall_s: float) -> Outcome:
    """The outcome of what a runner returned: metrics computed in memory, or a run folder to
    read the rows from."""
    if got is None:
        raise CellsimError("the runner returned no run folder")
    if isinstance(got, VariantMetrics):  # computed in memory (a run folder or none)
        return Outcome(variant, got.run_dir, tuple(got.rows), selection=got.selection,
                       wall_s=wall_s, timings_s=dict(got.timings_s))
    return Outcome(variant, str(got), tuple(variant_rows(variant, got)), wall_s=wall_s)


def run_variant(runner: Callable[[Variant], Any], variant: Variant) -> Outcome:
    """Run one variant and read its results; never raises (errors go into the outcome, as
    text, so that unpicklable exceptions cannot break the process pool)."""
    t0 = time.perf_counter()
    try:
        return outcome_of(variant, runner(variant), time.perf_counter() - t0)
    except BaseException as exc:  # noqa: BLE001 - reported per variant
        if isinstance(exc, KeyboardInterrupt):
            raise
        msg = f"{type(exc).__name__}: {exc}".splitlines()[0]
        return Outcome(variant, None, (), msg, traceback.format_exc(),
                       wall_s=time.perf_counter() - t0)


@dataclass
class SweepResult:
    """A finished sweep.

    Attributes:
        outcomes: One per variant, in variant order.
        workers: Worker processes used (1 = serial, in this process).
        wall_s: Wall-clock time of the runs, s.
        files: Files written, by name.
    """

    outcomes: list[Outcome]
    workers: int
    wall_s: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def rows(self) -> list[dict[str, Any]]:
        return [r for o in self.outcomes for r in o.rows]

    @property
    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.error is not None]


__all__ = ["FAILED_CHECKS_LISTED", "MAX_SWEEP_VARIANTS", "Outcome", "SweepResult", "Variant",
           "VariantMetrics", "failed_checks_text", "make_variants", "outcome_of", "rows_from",
           "run_variant", "unique_values", "validate_payloads", "validate_speed_scales",
           "variant_rows"]

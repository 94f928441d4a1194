"""Sizing reports of a run: ``sizing.csv``, ``sizing.json``, ``sizing.md``, ``report.html`` and
charts (``sizing/torques.png``, ``sizing/torque_speed_<joint>.png``).

Everything is written atomically (a temporary file in the same folder, then ``os.replace``),
so a reader never sees half a file. ``report.html`` is self-contained: the charts are embedded
as base64 data URIs; the only outside reference is a relative link to ``video.mp4`` when the
run has one.

Column convention of ``sizing.csv`` (one row per joint): a quantity without suffix is the one
the checks use (with the default basis ``"worst"``, the larger of the two sources); ``_id`` is
from inverse dynamics of the reference, ``_sim`` from the simulated actuator torque. Empty cells
mean "not applicable" (no drive data, no limit).

Owns the report's files and their text (CSV rows, Markdown, HTML, the selection's section); the
charts are drawn by :mod:`sim.analysis.sizing_charts`. Depends on :mod:`sim.analysis.selection`
(never the other way round).
May import: the analysis modules below it and :mod:`sim.simulation`.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.analysis.mechanism_report import AXIS_HEAD, mechanism_sections
from sim.analysis.report_text import num_text, pair_text, pct_text
from sim.analysis.robot_report import ROBOT_JOINT_HEAD, robot_sections
from sim.analysis.selection_report import (
    CHECK_HEAD,
    RANK_HEAD,
    SELECTION_HEAD,
    illustrative,
    pair_tables,
    selection_intro,
    selection_markdown,
    selection_table,
    verdict_text,
)
from sim.analysis.sizing import (
    CHECK_TITLES,
    PEAK_KNEE_FRACTION,
    PEAK_WINDOW_S,
    SOURCE_TITLES,
    JointSizing,
    SizingResult,
    load_summary,
)
from sim.analysis.sizing_charts import (  # the charts, importable from here as before
    chart_torque_speed,  # noqa: F401
    chart_torques,  # noqa: F401
    figure_png,  # noqa: F401
    sizing_charts,
)
from sim.core.files import write_atomic
from sim.simulation.collisions import CLEARANCE_RANGE_M, collision_phase
from sim.simulation.runfolder import (
    REPORT_HTML,
    SIZING_CHARTS_DIR,
    SIZING_CSV,
    SIZING_JSON,
    SIZING_MD,
    VIDEO_MP4,
)

#: Sub-folder of the run folder holding the charts.
PLOTS_DIR = SIZING_CHARTS_DIR

#: Required leading columns of sizing.csv.
REQUIRED_COLUMNS = ("joint", "peak_torque_nm", "rms_torque_nm", "peak_speed_rad_s", "peak_power_w",
                    "margin_pct", "pass")


# --------------------------------------------------------------------------------------------
# Atomic files
# --------------------------------------------------------------------------------------------

def csv_text(columns: Sequence[str], rows: Sequence[Mapping[str, Any]]) -> str:
    """CSV text with a header; floats in their shortest exact form, NaN/None as empty cells."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_cell(r.get(c)) for c in columns])
    return buf.getvalue()


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (float, np.floating)):
        return repr(float(v)) if np.isfinite(v) else ""  # shortest exact round trip
    return str(v)



# --------------------------------------------------------------------------------------------
# Table rows
# --------------------------------------------------------------------------------------------

def _basis_value(result: SizingResult, a: float, b: float) -> float:
    if result.basis == "id":
        return a
    if result.basis == "sim":
        return b
    return max(a, b)


def sizing_rows(result: SizingResult) -> tuple[list[str], list[dict[str, Any]]]:
    """``(columns, rows)`` of ``sizing.csv``, one row per joint."""
    nan = float("nan")
    rows = []
    for j in result.joints:
        sid, ssim = j.stats["id"], j.stats["sim"]
        r: dict[str, Any] = {"joint": j.joint, "pass": "PASS" if j.passed else "FAIL",
                             "margin_pct": j.margin_pct,
                             "limiting": j.limiting.key if j.limiting else ""}
        for name, attr, unit in (("peak_torque", "peak_torque", "nm"),
                                 ("rms_torque", "rms_torque", "nm"),
                                 ("peak_speed", "peak_speed", "rad_s"),
                                 ("peak_accel", "peak_accel", "rad_s2"),
                                 ("peak_power", "peak_power", "w"),
                                 ("energy", "energy", "j")):
            a, b = getattr(sid, attr), getattr(ssim, attr)
            r[f"{name}_{unit}"] = _basis_value(result, a, b)
            r[f"{name}_id_{unit}"] = a
            r[f"{name}_sim_{unit}"] = b
        r["peak_torque_time_id_s"] = sid.peak_torque_time
        r["peak_torque_time_sim_s"] = ssim.peak_torque_time
        r["momentary_torque_sim_nm"] = ssim.momentary_torque
        for name, attr, unit in (("mean_abs_power", "mean_abs_power", "w"),
                                 ("mean_power", "mean_power", "w"),
                                 ("net_energy", "net_energy", "j")):
            r[f"{name}_id_{unit}"] = getattr(sid, attr)
            r[f"{name}_sim_{unit}"] = getattr(ssim, attr)
        lo, hi = j.torque_range
        r["torque_limit_lo_nm"], r["torque_limit_hi_nm"] = lo, hi
        r["speed_limit_rad_s"] = j.speed_limit
        d = j.drive
        r["gear_ratio"] = d.gear_ratio if d else nan
        r["efficiency"] = d.efficiency if d else nan
        r["rotor_inertia_kg_m2"] = d.rotor_inertia if d else nan
        r["armature_kg_m2"] = j.armature
        for name, attr, unit in (("motor_peak_torque", "peak_torque", "nm"),
                                 ("motor_rms_torque", "rms_torque", "nm"),
                                 ("motor_peak_speed", "peak_speed_rpm", "rpm")):
            if j.motor:
                a, b = getattr(j.motor["id"], attr), getattr(j.motor["sim"], attr)
                r[f"{name}_{unit}"] = _basis_value(result, a, b)
                r[f"{name}_id_{unit}"], r[f"{name}_sim_{unit}"] = a, b
            else:
                r[f"{name}_{unit}"] = r[f"{name}_id_{unit}"] = r[f"{name}_sim_{unit}"] = nan
        r["motor_rated_torque_nm"] = d.rated_torque if d else nan
        r["motor_peak_torque_limit_nm"] = d.peak_torque if d else nan
        r["motor_max_speed_rpm"] = d.max_speed_rpm if d else nan
        for key in CHECK_TITLES:
            c = j.check(key)
            r[f"{key}_margin_pct"] = c.margin_pct if c else nan
        r["saturated"] = j.saturated
        rows.append(r if j.kind == "revolute" else {_linear_column(k): v for k, v in r.items()})
    columns = list(REQUIRED_COLUMNS[:-2]) + ["margin_pct", "pass", "limiting"]
    for k in (k for r in rows for k in r):
        if k not in columns:
            columns.append(k)
    return columns, rows


def _linear_column(key: str) -> str:
    """A prismatic joint's column (a track's axis): its joint-side torques are forces in N,
    its speeds m/s, its armature a mass in kg (``peak_torque_nm`` -> ``peak_force_n``); the
    motor's columns and the margins keep their names."""
    if key.startswith("motor_") or key.endswith("_margin_pct"):
        return key
    for a, b in (("torque", "force"), ("_nm", "_n"), ("_rad_s2", "_m_s2"), ("_rad_s", "_m_s"),
                 ("armature_kg_m2", "armature_kg")):
        key = key.replace(a, b)
    return key


# --------------------------------------------------------------------------------------------
# Markdown and HTML
# --------------------------------------------------------------------------------------------

_pct, _f, _pair = pct_text, num_text, pair_text


_TABLE_HEAD = ("joint", "peak torque or force (ID / sim)", "RMS torque or force (ID / sim)",
               "peak speed (ID / sim)", "peak power W (ID / sim)", "energy J (ID / sim)",
               "motor peak N m (ID / sim)", "motor RMS N m (ID / sim)", "motor speed rpm (ID / sim)",
               "limiting check", "margin %", "verdict")


def _table_cells(j: JointSizing) -> list[str]:
    lim = j.limiting
    return [j.joint, _pair(j, "peak_torque", unit=j.torque_unit),
            _pair(j, "rms_torque", unit=j.torque_unit), _pair(j, "peak_speed", unit=j.speed_unit),
            _pair(j, "peak_power"), _pair(j, "energy"), _pair(j, "peak_torque", True),
            _pair(j, "rms_torque", True), _pair(j, "peak_speed_rpm", True),
            (lim.title if lim else "n/a") + (" (simulated torque saturated)" if j.saturated else ""),
            _pct(j.margin_pct), "PASS" if j.passed else "FAIL"]


def _checks_cells(j: JointSizing) -> list[list[str]]:
    rows = []
    for c in j.checks:
        rows.append([j.joint, c.title, f"{_f(c.used)} {c.unit}", f"{_f(c.limit)} {c.unit}",
                     _pct(c.margin_pct), c.source,
                     "PASS" if c.passed else "FAIL"])
    return rows


_CHECK_HEAD = ("joint", "check", "used", "limit", "margin %", "source", "verdict")

_CONVENTIONS = (
    "RMS torque is time-weighted over the cycle, sqrt(1/T int tau^2 dt) by the trapezoidal rule. "
    "Mean power |P| is 1/T int |tau qd| dt, mean power P the net 1/T int tau qd dt; energy is "
    "int |tau qd| dt per cycle and the net (regenerative) energy int tau qd dt. Motor torque is "
    "(tau - armature qdd)/(N eta) + J_r N qdd when the motor drives the load or holds it at "
    "standstill (|qd| < 1e-3 rad/s) and (tau - armature qdd) eta/N + J_r N qdd when power "
    "flows back. Margin = (limit - used)/limit "
    "x 100; a check passes at margin >= 0. The peak envelope holds the peak torque up to "
    f"{PEAK_KNEE_FRACTION:g} x max speed, then falls linearly to the rated torque at max speed "
    "(generic shape, not catalogue data); the continuous envelope is the rated torque. "
    f"Simulated peaks (torque, acceleration, power, motor torque, envelope) are of the signal "
    f"sustained over {PEAK_WINDOW_S * 1e3:g} ms (its centred sliding mean): a contact's onset "
    "moves a joint within a step or two, an impulse whose one-step torque depends on the "
    "timestep; the largest instantaneous torque is the momentary torque (sizing.csv, "
    "sizing.json), for a reducer's momentary rating."
)


def _md_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def run_verdict_text(summary: Mapping[str, Any]) -> str | None:
    """The run's verdict in one line, as every report gives it (``report.html``,
    ``sizing.md``, the console): ``Run verdict: FAIL: 51 checks, 2 failed, 3 warning(s).``;
    None for a summary without a verdict."""
    if "verdict" not in summary:
        return None
    checks = summary.get("checks", [])
    failed = [c for c in checks if not c["pass"] and c.get("severity", "error") == "error"]
    warned = [c for c in checks if not c["pass"] and c.get("severity") == "warning"]
    return (f"Run verdict: {str(summary['verdict']).upper()}: {len(checks)} checks, "
            f"{len(failed)} failed, {len(warned)} warning(s).")


def sizing_markdown(result: SizingResult, chart_names: Sequence[str] = (),
                    summary: Mapping[str, Any] | None = None, selection: Any = None) -> str:
    """Text of ``sizing.md``: header, the run's verdict (``summary``'s: the same as
    ``report.html`` and ``summary.json``, with its failed checks and warnings), the sizing's
    own verdict paragraph, a section per mechanism (:mod:`sim.analysis.mechanism_report`),
    table, checks, the actuator selection (when the run made one), chart links."""
    parts = [f"# Actuator sizing: {result.scenario or 'run'}", ""]
    parts.append(f"Robot: {result.robot or 'n/a'}; cycle duration {result.duration:.3f} s; checks "
                 f"on basis '{result.basis}'.")
    if result.estimates_note:
        parts += ["", result.estimates_note]
    run_line = run_verdict_text(summary or {})
    if run_line is not None:
        checks = (summary or {}).get("checks", [])
        listed = [c for c in checks if not c["pass"]]
        parts += ["", "## Run verdict", "", run_line]
        if listed:
            parts += ["", _md_table(("check", "subject", "value", "limit", "unit", "severity"), [
                (str(c["name"]), str(c.get("subject") or c.get("joint", "")),
                 _f(float(c["value"])), _f(float(c["limit"])), str(c["unit"]),
                 str(c.get("severity", "error"))) for c in listed])]
        parts += ["", ("The sizing below is one part of it (the drives' torque, speed and "
                       "envelope checks).")]
    parts += ["", "## Sizing verdict" if run_line is not None else "## Verdict", "",
              result.verdict, ""]
    for sec in mechanism_sections(summary or {}, result):
        parts += [f"## Mechanism {sec.title}", "", sec.load, "", _md_table(AXIS_HEAD, sec.rows), ""]
    for rs in robot_sections(summary or {}, result):
        parts += [f"## Robot {rs.title}", "", rs.text, ""]
        if rs.welds:
            parts += [_md_table(WELD_HEAD, rs.welds), ""]
        parts += [_md_table(ROBOT_JOINT_HEAD, rs.joints), ""]
    parts += ["## Per joint", ""]
    parts.append(_md_table(_TABLE_HEAD, [_table_cells(j) for j in result.joints]))
    parts += ["", "## Checks", ""]
    parts.append(_md_table(_CHECK_HEAD, [r for j in result.joints for r in _checks_cells(j)]))
    if selection is not None:
        parts += ["", *selection_markdown(selection)]
    if chart_names:
        parts += ["", "## Charts", ""]
        for name in chart_names:
            parts.append(f"![{name}]({PLOTS_DIR}/{name})")
            parts.append("")
    parts += ["", "## Conventions", "", _CONVENTIONS, ""]
    return "\n".join(parts)


#: Columns of a robot section's weld table (a cell with several robots).
WELD_HEAD = ("phase", "seam", "length mm", "set mm/s", "travel mm/s", "path dev. mm",
             "torch angle err. deg")
#: Columns of a robot section's joint table.
def _html_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    h = "".join(f"<th>{html.escape(x)}</th>" for x in head)
    body = []
    for r in rows:
        cls = ' class="fail"' if r[-1] == "FAIL" else ""
        body.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(x)}</td>" for x in r) + "</tr>")
    return (f'<div class="scroll"><table><thead><tr>{h}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;padding:0 1em;max-width:1200px;color:#222}
.scroll{overflow-x:auto;-webkit-overflow-scrolling:touch}
table{border-collapse:collapse;margin:1em 0;font-size:0.85em}
details{margin:0.4em 0}summary{cursor:pointer;font-weight:600}
video{max-width:100%;height:auto}
@media (max-width:700px){body{margin:0.5em auto;font-size:15px}table{font-size:0.78em}th,td{padding:2px 4px}h1{font-size:1.3em}}
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}
th{background:#f0f0f0}td:first-child,th:first-child{text-align:left}
tr.fail td{background:#fde2e2}
.verdict{padding:0.8em 1em;border-left:6px solid #2a2;background:#effaef}
.verdict.fail{border-color:#c22;background:#fdeeee}
img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}
.small{font-size:0.85em;color:#555}
"""


def collision_rows(summary: Mapping[str, Any]) -> tuple[list[list[str]], list[list[str]]]:
    """Rows of the collisions table and of the per-phase clearance table of a summary."""
    coll = [[collision_phase(c), f"{c['t0']:.3f}-{c['t1']:.3f}", str(c["kind"]),
             f"{c['bodies'][0]} / {c['bodies'][1]}", f"{c['geoms'][0]} / {c['geoms'][1]}",
             f"{c['depth_mm']:.2f}"] for c in summary.get("collisions", ())]

    def mm(v: Any) -> str:
        return f"> {CLEARANCE_RANGE_MM:g}" if v is None else f"{v:.1f}"

    def pair(c: Mapping[str, Any], grp: str) -> str:
        return " / ".join(c.get(f"{grp}_bodies", c.get(f"{grp}_pair", ()))) or "-"

    clear = [[str(c["phase"]), mm(c.get("tool_mm")), pair(c, "tool"), mm(c.get("arm_mm")),
              pair(c, "arm")] for c in summary.get("clearance", ())]
    return coll, clear


#: Clearance is measured up to this distance, mm.
CLEARANCE_RANGE_MM = 1e3 * CLEARANCE_RANGE_M
_COLL_HEAD = ("phase", "t (s)", "kind", "bodies", "worst geoms", "depth (mm)")
_CLEAR_HEAD = ("phase", "tool (mm)", "tool closest to", "arm (mm)", "arm closest to")


def selection_html(sel: Any) -> list[str]:
    """The "Actuator selection" section: the choice per joint, its checks and the ranking
    (the rows of :mod:`sim.analysis.selection_report`, as ``sizing.md`` has them)."""
    esc = html.escape
    out = ["<h2>Actuator selection</h2>", f"<p>{esc(selection_intro(sel))}</p>"]
    if illustrative(sel):
        out.append('<p class="small">Entries marked [illustrative] hold numbers not verified '
                   "against their datasheet: verify before ordering.</p>")
    cls = "verdict" if sel.all_served else "verdict fail"
    out.append(f'<p class="{cls}">{esc(verdict_text(sel))}</p>')
    out.append(_html_table(SELECTION_HEAD, selection_table(sel)))
    for title, checks, ranking in pair_tables(sel):
        out.append(f"<details><summary>{esc(title)}</summary>")
        out.append(_html_table(CHECK_HEAD, checks))
        if ranking:
            out.append(_html_table(RANK_HEAD, ranking))
        out.append("</details>")
    return out


def _value(v: Any) -> str:
    """A summary value as a person reads it: floats to 4 significant digits."""
    if isinstance(v, bool) or not isinstance(v, float):
        return str(v)
    return _f(v)


def summary_html(summary: Mapping[str, Any], result: SizingResult) -> list[str]:
    """The report's first table: the verdict, then per joint the hardest check and its margin
    (of every check of the run on that joint: tracking, saturation, limits, sizing)."""
    esc = html.escape
    verdict = str(summary.get("verdict", "pass" if result.passed else "fail"))
    checks = summary.get("checks", [])
    failed = [c for c in checks if not c["pass"] and c.get("severity", "error") == "error"]
    warned = [c for c in checks if not c["pass"] and c.get("severity") == "warning"]
    cls = "verdict" if verdict == "pass" else "verdict fail"
    head = (f"{verdict.upper()}: {len(checks)} checks, {len(failed)} failed, "
            f"{len(warned)} warning(s); collisions: {len(summary.get('collisions', []))}; "
            f"cycle {result.duration:.4g} s")
    out = ["<h2>Summary</h2>", f'<p class="{cls}">{esc(head)}</p>']
    rows = []
    for j in result.joints:
        mine = [c for c in checks if c.get("joint") == j.joint and c.get("limit")
                and np.isfinite(c["limit"]) and c["limit"] != 0
                and c.get("severity", "error") == "error"]
        if not mine:
            continue

        def margin(c: Mapping[str, Any]) -> float:
            lim, val = float(c["limit"]), float(c["value"])
            return (lim - val) / abs(lim) * 100.0

        hard = min(mine, key=margin)
        rows.append((j.joint, str(hard["name"]), f"{_f(float(hard['value']), 3)} {hard['unit']}",
                     f"{_f(float(hard['limit']), 3)} {hard['unit']}", _pct(margin(hard)),
                     "PASS" if all(c["pass"] for c in mine) else "FAIL"))
    if rows:
        out.append(_html_table(("joint", "hardest check", "value", "limit", "margin %",
                                "verdict"), rows))
    return out


def _run_verdict_html(summary: Mapping[str, Any]) -> list[str]:
    """The run's verdict (every check: tracking, saturation, limits, sizing, collisions)."""
    if "verdict" not in summary:
        return []
    checks = summary.get("checks", [])
    failed = [c for c in checks if not c["pass"] and c.get("severity", "error") == "error"]
    warned = [c for c in checks if not c["pass"] and c.get("severity") == "warning"]
    cls = "verdict" if summary["verdict"] == "pass" else "verdict fail"
    text = run_verdict_text(summary)
    out = [f'<h2>Run verdict</h2><p class="{cls}">{html.escape(text)}</p>']
    if failed or warned:
        out.append(_html_table(("check", "subject", "value", "limit", "unit", "severity"), [
            (str(c["name"]), str(c.get("subject") or c.get("joint", "")), _f(float(c["value"])),
             _f(float(c["limit"])), str(c["unit"]), str(c.get("severity", "error")))
            for c in failed + warned]))
    return out


def _collision_html(summary: Mapping[str, Any]) -> list[str]:
    if "collisions" not in summary:
        return []
    coll, clear = collision_rows(summary)
    out = ["<h2>Collisions and clearance</h2>"]
    if coll:
        out.append(f'<p class="verdict fail">{len(coll)} collision(s): the motion is not '
                   "physically possible.</p>")
        out.append(_html_table(_COLL_HEAD, coll))
    else:
        out.append('<p class="verdict">No collision along the whole motion.</p>')
    out.append(_html_table(_CLEAR_HEAD, clear))
    return out


def sizing_html(result: SizingResult, charts: Mapping[str, bytes], summary: Mapping[str, Any],
                video: str | None = None, selection: Any = None, replay: str | None = None) -> str:
    """Text of the self-contained ``report.html`` (charts as base64 data URIs; ``replay``: the
    3D replay's section, :mod:`sim.analysis.replay`)."""
    esc = html.escape
    title = f"cellsim report: {result.scenario or 'run'}"
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           '<meta name="viewport" content="width=device-width, initial-scale=1">',
           f"<title>{esc(title)}</title><style>{_CSS}</style></head><body>",
           f"<h1>{esc(title)}</h1>"]
    out += summary_html(summary, result)
    if replay:
        out.append(replay)
    if video:
        out.append(f'<h2>Video</h2><video controls src="{esc(video)}"></video>'
                   f'<p><a href="{esc(video)}">{esc(video)}</a></p>')
    out += _run_verdict_html(summary)
    cls = "verdict" if result.passed else "verdict fail"
    out.append(f'<h2>Sizing verdict</h2><p class="{cls}">{esc(result.verdict)}</p>')
    if result.estimates_note:
        out.append(f'<p class="small">{esc(result.estimates_note)}</p>')
    out += _collision_html(summary)
    if selection is not None:
        out += selection_html(selection)
    for sec in mechanism_sections(summary, result):
        out += [f"<h2>Mechanism {esc(sec.title)}</h2>", f"<p>{esc(sec.load)}</p>",
                _html_table(AXIS_HEAD, sec.rows)]
    for rs in robot_sections(summary, result):
        out += [f"<h2>Robot {esc(rs.title)}</h2>", f"<p>{esc(rs.text)}</p>"]
        if rs.welds:
            out.append(_html_table(WELD_HEAD, rs.welds))
        out.append(_html_table(ROBOT_JOINT_HEAD, rs.joints))
    out.append("<h2>Per joint</h2>")
    out.append(_html_table(_TABLE_HEAD, [_table_cells(j) for j in result.joints]))
    out.append("<h2>Checks, per joint</h2>")
    for j in result.joints:
        rows = _checks_cells(j)
        failed = sum(r[-1] == "FAIL" for r in rows)
        out.append(f"<details{' open' if failed else ''}><summary>{esc(j.joint)}: "
                   f"{len(rows)} checks, {failed} failed</summary>")
        out.append(_html_table(_CHECK_HEAD, rows))
        out.append("</details>")
    out.append("<h2>Charts</h2>")
    for name, png in charts.items():
        b64 = base64.b64encode(png).decode("ascii")
        out.append(f'<figure><img alt="{esc(name)}" src="data:image/png;base64,{b64}">'
                   f"<figcaption class=\"small\">{esc(name)}</figcaption></figure>")
    out.append("<h2>Run details</h2>")
    scalars = [(k, v) for k, v in summary.items() if isinstance(v, (str, int, float, bool))]
    if result.robot and "robot" not in summary:
        scalars.insert(0, ("robot", result.robot))
    scalars.append(("cycle duration (s)", result.duration))
    out.append(_html_table(("field", "value"), [(str(k), _value(v)) for k, v in scalars]))
    if result.phases:
        out.append(_html_table(("phase", "kind", "t0 (s)", "t1 (s)"),
                               [(str(p.get("name", "")), str(p.get("kind", "")),
                                 _f(float(p.get("t0", np.nan))), _f(float(p.get("t1", np.nan))))
                                for p in result.phases]))
    out.append(f'<h2>Conventions</h2><p class="small">{esc(_CONVENTIONS)}</p>')
    srcs = "; ".join(f"{k}: {v}" for k, v in SOURCE_TITLES.items())
    out.append(f'<p class="small">Sources: {esc(srcs)}.</p>')
    out.append("</body></html>")
    return "\n".join(out)


# --------------------------------------------------------------------------------------------
# Entry point
# --------------------------------------------------------------------------------------------

def write_sizing(run_dir: str | Path, result: SizingResult, *, charts: bool = True,
                 summary: Mapping[str, Any] | None = None,
                 selection: Any = None, replay: str | None = None) -> dict[str, Path]:
    """Write the sizing files of a run into ``run_dir``.

    ``summary`` is the run's summary in memory (the runner's); without it the folder's
    ``summary.json`` is read and the video linked when ``video.mp4`` is there.

    Args:
        run_dir: The run folder (``summary.json`` and ``video.mp4`` are read from it when
            present).
        result: From :func:`sim.analysis.sizing.size_run`.
        charts: Draw the charts (PNG files in ``run_dir/sizing/``, embedded in the HTML).
        replay: The 3D replay's HTML section (:func:`sim.analysis.replay.replay_html`), or
            None for a report without it.

    Returns:
        Paths written, by name: ``csv``, ``json``, ``md``, ``html`` and one per chart.
    """
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}
    columns, rows = sizing_rows(result)
    written["csv"] = write_atomic(run_dir / SIZING_CSV, csv_text(columns, rows))
    written["json"] = write_atomic(run_dir / SIZING_JSON,
                                   json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
    pngs = sizing_charts(result) if charts else {}
    for name, png in pngs.items():
        written[name] = write_atomic(run_dir / PLOTS_DIR / name, png)
    if summary is None:  # a finished folder: read what it holds
        summary = load_summary(run_dir)
        video = VIDEO_MP4 if (run_dir / VIDEO_MP4).is_file() else None
    else:  # the runner's summary in memory names the video when it wrote one
        video = summary.get("video")
    written["md"] = write_atomic(run_dir / SIZING_MD, sizing_markdown(result, list(pngs), summary,
                                                                   selection))
    written["html"] = write_atomic(run_dir / REPORT_HTML,
                                   sizing_html(result, pngs, summary, video, selection,
                                                       replay))
    return written

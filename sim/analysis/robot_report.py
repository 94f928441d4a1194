"""The report's section per robot of a cell with several (``summary["robots"]``):
:func:`robot_sections` (the robot's model, tool, frame 0, joints, cycle end and tool point
deviation, its welds, its joints' tracking and sizing). May import: the sizing result types
and :mod:`sim.analysis.report_text`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from sim.analysis.report_text import num_text, pair_text, pct_text
from sim.analysis.sizing_result import SizingResult

ROBOT_JOINT_HEAD = ("joint", "tracking error", "peak torque (ID / sim)",
                    "RMS torque (ID / sim)", "margin %", "limiting check")


@dataclass(frozen=True)
class RobotSection:
    """One robot of a cell with several (``summary["robots"]``): its title, a sentence (model,
    tool, frame 0, joints, cycle end, tool point deviation), its welds and its joints."""

    title: str
    text: str
    welds: tuple[tuple[str, ...], ...]
    joints: tuple[tuple[str, ...], ...]


def robot_sections(summary: Mapping[str, Any], result: SizingResult | None = None
                   ) -> list[RobotSection]:
    """A section per robot of a cell with other robots (none for a cell with one): the
    robot's name on its joints, welds and figures."""
    robots = summary.get("robots") or {}
    if not robots:
        return []
    sized = {j.joint: j for j in result.joints} if result is not None else {}
    names = list(summary.get("joints", []))
    track = summary.get("max_tracking_error_deg", [])
    units = summary.get("joint_units") or ["deg"] * len(track)
    out = []
    for name, r in robots.items():
        pos = ", ".join(f"{float(x):.6g}" for x in r.get("frame0_pos_mm", ()))
        text = (f"{r['model']} with {r.get('tool') or 'no tool'}; frame 0 at {pos} mm; joints "
                f"{', '.join(r['joints'])}; its last phase ends at {float(r['t_end_s']):.4g} s; "
                f"tool point up to {num_text(float(r['max_tcp_deviation_mm']))} mm off its reference.")
        welds = tuple(
            (str(w["phase"]), str(w.get("seam") or "-"), num_text(float(w["seam_length_mm"])),
             num_text(float(w["set_speed_mm_s"])), num_text(float(w["travel_speed_mm_s"])),
             num_text(float(w["max_path_deviation_mm"])), num_text(float(w["torch_angle_error_deg"])))
            for w in summary.get("weld", ()) if w.get("robot") == name)
        joints = []
        for jn in r["joints"]:
            k = names.index(jn) if jn in names else None
            tr = (f"{num_text(float(track[k]), 3)} {units[k]}" if k is not None and k < len(track)
                  else "n/a")
            j = sized.get(jn)
            if j is None:
                joints.append((jn, tr, "n/a", "n/a", "n/a", "n/a"))
                continue
            joints.append((jn, tr, pair_text(j, "peak_torque", unit=j.torque_unit),
                           pair_text(j, "rms_torque", unit=j.torque_unit), pct_text(j.margin_pct),
                           j.limiting.title if j.limiting else "n/a"))
        out.append(RobotSection(title=f"{name} ({r['model']})", text=text, welds=welds,
                                joints=tuple(joints)))
    return out


__all__ = ["ROBOT_JOINT_HEAD", "RobotSection", "robot_sections"]

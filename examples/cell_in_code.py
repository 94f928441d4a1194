"""A cell built in code: a plate on a table, its seam length a parameter, welded and run.

    python examples/cell_in_code.py [OUT_DIR] [SEAM_MM]

The cell and the scenario are written from Python values (a cell file and a scenario file are
plain TOML, ``docs/cell-format.md`` and ``docs/scenario-format.md``), then run into a run
folder with its sizing report (no video here: ``video=False``); the result is read back from
the folder with :meth:`sim.RunResult.load`.
"""

import sys
from pathlib import Path

import sim


def toml(tables: dict) -> str:
    """A small TOML writer for this example's values (numbers, strings, lists, tables and
    arrays of tables)."""

    def value(v: object) -> str:
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(float(v)) if isinstance(v, float) else str(v)

    lines = [f"{k} = {value(v)}" for k, v in tables.items() if not isinstance(v, (dict, list))
             or (isinstance(v, list) and not (v and isinstance(v[0], dict)))]
    for k, v in tables.items():
        if isinstance(v, dict):
            lines += ["", f"[{k}]"] + [f"{kk} = {value(vv)}" for kk, vv in v.items()]
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines += ["", f"[[{k}]]"] + [f"{kk} = {value(vv)}" for kk, vv in item.items()]
    return "\n".join(lines) + "\n"


def make_cell(folder: Path, seam_mm: float) -> Path:
    """Write the cell and the scenario into ``folder``; returns the scenario's path."""
    table_top_mm = 400.0
    plate = {"name": "plate", "shape": "box", "role": "workpiece",
             "size_mm": [seam_mm + 100.0, 200.0, 10.0],
             "pos_mm": [550.0, 0.0, table_top_mm + 5.0]}
    cell = {
        "name": "plate_cell", "description": f"a plate on a table, a {seam_mm:g} mm seam",
        "tool": "mig_torch",
        "objects": [{"name": "table", "shape": "box", "size_mm": [600.0, 800.0, 40.0],
                     "pos_mm": [550.0, 0.0, table_top_mm - 20.0]}, plate],
        "seams": [{"name": "bead", "object": "plate", "kind": "line",
                   "points_mm": [[-seam_mm / 2, 0.0, 5.0], [seam_mm / 2, 0.0, 5.0]],
                   "normal": [0, 0, 1], "work_angle_deg": 90, "travel_angle_deg": 0}],
    }
    scenario = {
        "name": "plate_weld", "description": "weld the plate's bead", "robot": "lrmate200ic5l",
        "cell": "plate_cell.toml",
        "actions": [{"action": "arc_on", "phase": "weld"},
                    {"action": "arc_off", "phase": "weld", "at": "end"}],
        "phases": [
            {"name": "approach", "planner": "434", "durations_s": [2.0],
             "to_mm": [-seam_mm / 2, 0.0, 60.0], "frame": "plate",
             "euler_zyx_deg": [0, 180, 0]},
            {"name": "down", "kind": "linear", "to_mm": [-seam_mm / 2, 0.0, 5.0],
             "frame": "plate", "speed_mm_s": 50.0},
            {"name": "weld", "kind": "linear", "seam": "bead", "orientation": "seam",
             "speed_mm_s": 10.0},
            {"name": "lift", "kind": "linear", "to_mm": [seam_mm / 2, 0.0, 80.0],
             "frame": "plate", "speed_mm_s": 100.0},
        ],
    }
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "plate_cell.toml").write_text(toml(cell))
    path = folder / "plate_weld.toml"
    path.write_text(toml(scenario))
    return path


def main(out: Path, seam_mm: float) -> sim.RunResult:
    scenario = make_cell(out / "input", seam_mm)
    result = sim.run(scenario, out_dir=out / "run", video=False, plots=False)
    again = sim.RunResult.load(out / "run")  # what a colleague reads from the folder
    assert again.verdict == result.verdict
    weld = next(w for w in again.to_dict()["weld"] if w["phase"] == "weld")
    print(f"{again.scenario}: {again.verdict}, {len(again.checks)} checks; seam "
          f"{weld['seam_length_mm']:.1f} mm at {weld['travel_speed_mm_s']:.2f} mm/s, torch "
          f"within {weld['torch_angle_error_deg']:.3f} deg; results in {again.path}")
    return again


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("runs/cell_in_code"),
         float(sys.argv[2]) if len(sys.argv) > 2 else 200.0)

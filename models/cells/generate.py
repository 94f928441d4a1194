"""Write the shipped cell files (``models/cells/*.toml``) from their Python derivations.

Each shipped cell's numbers are derived in a module of ``sim/cells`` (``weld_cylinder.py``: the
part from seed 001's phase-I pose; ``weld_table.py``: seams a 5-axis arm can weld;
``pick.py``: a layout the analytic IK reaches); this script composes each variant (robot,
mount) and writes it as a cell file (``sim.cells.export``), which is what cellsim reads.

    python models/cells/generate.py          # rewrite the files
    python models/cells/generate.py --check  # exit 1 if a file differs
                                             # (tests/cells/test_cell_files.py)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

#: dims entries in kg (the rest are m, or deg where the name ends in _deg)
KG = {"part_mass": "kg"}


def variants():
    from sim.cells import DERIVED

    for name, spec in DERIVED.items():
        for robot in spec.robots:
            for mount in spec.mounts:
                parts = [name]
                if len(spec.robots) > 1:
                    parts.append(robot)
                if len(spec.mounts) > 1:
                    parts.append(mount)
                yield ".".join(parts) + ".toml", spec, robot, mount


def render(spec, robot: str, mount: str) -> str:
    from sim.cells import build_cell
    from sim.cells.export import cell_to_toml
    from sim.robots.registry import ROBOTS

    cell = build_cell(spec, ROBOTS[robot], mount=mount)
    module = spec.build.__module__
    header = (f"Shipped cell {spec.name!r} for {robot} ({mount} mount), written by "
              f"models/cells/generate.py from {module.replace('.', '/')}.py,\n"
              "which derives each number; edit that module and regenerate, not this file.\n"
              "Format: docs/cell-format.md.")
    return cell_to_toml(cell, spec, header=header, dims_units=KG)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare, do not write")
    args = ap.parse_args(argv)
    stale = []
    for fname, spec, robot, mount in variants():
        text = render(spec, robot, mount)
        path = HERE / fname
        if args.check:
            if not path.is_file() or path.read_text() != text:
                stale.append(fname)
        else:
            path.write_text(text)
            print(f"wrote {path}")
    if stale:
        print(f"out of date: {', '.join(stale)} (run models/cells/generate.py)")
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

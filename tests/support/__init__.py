"""What the tests share: independent oracles, the files they write (cells, robots, scenarios)
and the repository's paths. Nothing here is a test; pytest collects none of it.

* :mod:`support.seam_oracle`, :mod:`support.rnea_oracle`, :mod:`support.window_oracle`: judges
  written independently of cellsim (a weld from a cell file's own numbers, pinocchio's inverse
  dynamics, the sustained value of a signal).
* :mod:`support.mechanism_oracle`: a mechanism's (positioner, turntable, track) inverse dynamics
  with a payload on its mount, Newton-Euler written from first principles.
* :mod:`support.scenarios`: a scenario file from keyword arguments (:func:`~support.scenarios.
  scenario_text`, :func:`~support.scenarios.write_scenario`), and the scenarios several test
  files run (the hostile-input campaign's base, a TP program's).
* :mod:`support.cell_files`: a user's cell file with an STL bracket and the scenario that welds
  it (:func:`~support.cell_files.make_cell`).
* :mod:`support.mechanisms`: mechanism files (turntables, positioners, tracks): a TOML writer,
  hypothesis strategies of valid files and the oracle judging what is read from them.
* :mod:`support.robots`: a robot folder from a DH table (:data:`~support.robots.DH_ROBOT`) and
  a scenario that moves it.

``tests/`` is on ``sys.path`` (pytest puts ``conftest.py``'s folder there), so a test file in any
folder under ``tests/`` imports ``from support.scenarios import scenario_text``.
"""

from __future__ import annotations

from pathlib import Path

#: The repository's root folder.
ROOT = Path(__file__).resolve().parents[2]
#: The tests' data files (URDFs, TP programs): ``tests/data``.
DATA = ROOT / "tests" / "data"

__all__ = ["DATA", "ROOT"]

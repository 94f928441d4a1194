"""`pip install .` (not only editable) gives a cellsim that finds its models and scenarios."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out),
                    str(ROOT)], check=True, capture_output=True, text=True)
    (whl,) = out.glob("cellsim-*.whl")
    return whl


def test_wheel_ships_models_scenarios_and_packages(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for scenario in (ROOT / "scenarios").glob("*.toml"):
        assert f"sim/_data/scenarios/{scenario.name}" in names
    for xml in (ROOT / "models").rglob("*.xml"):
        assert f"sim/_data/models/{xml.relative_to(ROOT / 'models').as_posix()}" in names
    assert "sim/cli/__init__.py" in names and "planners/__init__.py" in names
    vendor = ROOT / "sim/analysis/replay/vendor"  # the replay's scripts and their licences
    assert {f"sim/analysis/replay/vendor/{p.name}" for p in vendor.iterdir()} <= names
    assert "sim/analysis/replay/app.js" in names
    assert not any(n.startswith(("tests/", ".venv/")) for n in names)


def test_installed_wheel_runs_from_elsewhere(wheel, tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(site), str(wheel)], check=True, capture_output=True, text=True)
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]);"
        "import sim, sim.core.resources as r;"
        "assert sim.__file__.startswith(sys.argv[1]), sim.__file__;"
        "print(r.scenarios_dir()); from sim.cli import main; sys.exit(main(['list']))"
    )
    res = subprocess.run([sys.executable, "-c", code, str(site)], cwd=tmp_path,
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    first, rest = res.stdout.split("\n", 1)
    assert first.startswith(str(site)), "scenarios must come from the installed wheel"
    assert "bugnar_5r_phase1" in rest and "robot_5r" in rest

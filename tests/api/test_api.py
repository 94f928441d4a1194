"""The Python API (issue 27): ``import sim`` and five lines give typed results.

Every figure the typed result reports is checked against what the run recorded (its arrays,
its summary.json) recomputed here; the examples under ``examples/`` run as a user runs them.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sim
from sim.errors import RunFolderError
from sim.scenario import parse_scenario

ROOT = Path(__file__).resolve().parents[2]
SHORT = "bugnar_5r_phase1"  # the shortest shipped scenario (10 s of cycle, a second to run)


@pytest.fixture(scope="module")
def short() -> sim.RunResult:
    return sim.evaluate(SHORT)


def _cpu_s_to_import(module: str) -> tuple[float, list[str]]:
    """CPU seconds a fresh interpreter spends importing ``module``, and which heavy libraries
    that import loaded (CPU time, not wall time: a loaded machine does not fail the test)."""
    code = (f"import sys, time; t = time.process_time(); import {module}; "
            "dt = time.process_time() - t; "
            "heavy = [m for m in ('mujoco', 'dm_control', 'matplotlib', 'trimesh', 'scipy') "
            "if m in sys.modules]; print(dt); print(','.join(heavy))")
    for _ in range(2):  # the first run may compile the modules' bytecode: measure the second
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             cwd=ROOT, check=True).stdout.split("\n")
    return float(out[0]), [m for m in out[1].split(",") if m]


@pytest.mark.parametrize("module", ["sim", "sim.cells"])
def test_import_is_cheap_and_loads_no_engine(module):
    """``import sim`` loads nothing heavy; ``import sim.cells`` reads no cell file and compiles
    no model until a cell is asked for (its registry fills on first use)."""
    cpu_s, heavy = _cpu_s_to_import(module)
    assert cpu_s < 1.0, cpu_s
    assert not {"mujoco", "dm_control", "matplotlib", "trimesh"} & set(heavy), heavy
    if module == "sim":
        assert heavy == []


def test_every_exported_name_resolves_and_is_documented():
    assert len(sim.__all__) == len(set(sim.__all__))
    for name in sim.__all__:
        value = getattr(sim, name)
        if name != "__version__":
            assert (getattr(value, "__doc__", None) or "").strip(), f"sim.{name} has no docstring"
    assert issubclass(sim.ScenarioError, sim.CellsimError)
    assert sim.evaluate.__module__ == "sim.api.runs"
    with pytest.raises(AttributeError):
        sim.no_such_name  # noqa: B018


def test_the_package_is_typed():
    assert (ROOT / "sim" / "py.typed").is_file()
    assert (ROOT / "planners" / "py.typed").is_file()


# ------------------------------------------------------------------------- in memory
def _trapezoid_rms(x: np.ndarray, t: np.ndarray) -> float:
    dt = np.diff(t)
    return math.sqrt(float(np.sum(dt * (x[1:] ** 2 + x[:-1] ** 2) / 2)) / float(t[-1] - t[0]))


def test_evaluate_reports_the_checks_summary_json_holds(short):
    summary = short.to_dict()
    assert [c.to_dict() for c in short.checks] == summary["checks"]
    failed = [c for c in summary["checks"] if not c["pass"] and c["severity"] == "error"]
    assert [c.to_dict() for c in short.failed_checks] == failed
    assert short.verdict == ("fail" if failed else "pass") == summary["verdict"]
    assert short.warnings == len(short.warning_checks) == summary["warnings"]
    assert short.joints == tuple(summary["joints"]) == ("j1", "j2", "j3", "j4", "j5")
    assert short.path is None and short.scenario == SHORT
    # to_dict is a copy: changing it changes nothing in the result
    summary["verdict"] = "changed"
    assert short.to_dict()["verdict"] != "changed"


def test_evaluate_sizing_agrees_with_the_recorded_torques(short):
    """Per joint, the typed peak and RMS are the worse of the two sources, recomputed here
    from the recorded arrays: the inverse dynamics of the reference (``tau_id``, exact
    samples) and the simulated torque (``tau``, whose peak sizing takes sustained over 5 ms,
    so it lies between the largest 5 ms mean and the largest sample)."""
    a = short.arrays
    t = a["t"]
    assert short.duration_s == pytest.approx(t[-1] - t[0])
    assert set(short.sizing) == set(short.joints) and short.sizing_passed is True
    for j, name in enumerate(short.joints):
        sized = short.sizing[name]
        tau_id, tau = a["tau_id"][:, j], a["tau"][:, j]
        peak_id, peak_sim = np.abs(tau_id).max(), np.abs(tau).max()
        assert peak_id * (1 - 1e-9) <= sized.peak_torque_nm <= max(peak_id, peak_sim) * (1 + 1e-9)
        rms = max(_trapezoid_rms(tau_id, t), _trapezoid_rms(tau, t))
        assert sized.rms_torque_nm == pytest.approx(rms, rel=1e-6)
        speed = max(np.abs(a["qd_ref"][:, j]).max(), np.abs(a["qd"][:, j]).max())
        assert sized.peak_speed_rad_s == pytest.approx(speed, rel=1e-3)
        assert sized.passed == all(c.passed for c in sized.checks)
        assert sized.margin_pct == pytest.approx(min(c.margin_pct for c in sized.checks))


def test_a_drive_too_weak_fails_the_verdict_and_the_result_says_where():
    """Planted fault: the 5R's J2 motor at a twentieth of its peak cannot hold the arm."""
    text = (ROOT / "scenarios" / f"{SHORT}.toml").read_text()
    weak = parse_scenario(text + "\n[drives.j2]\npeak_torque_nm = 2.3\nrated_torque_nm = 1.15\n")
    r = sim.evaluate(weak)
    assert r.verdict == "fail" and not r.passed
    assert any(c.name == "saturation" and c.joint == "j2" for c in r.failed_checks)
    assert r.saturation and {s.joint for s in r.saturation} == {"j2"}
    # each interval is where the recorded drive sat at its limit, seen in the arrays
    a = r.arrays
    for s in r.saturation:
        inside = (a["t"] >= s.t0) & (a["t"] <= s.t1)
        at_limit = np.abs(a["tau_actuator"][inside, 1]) >= a["tau_limit"][inside, 1] * (1 - 1e-6)
        assert at_limit.mean() > 0.5 and s.worst_excess_nm > 0
    assert r.sizing["j2"].saturated


# ------------------------------------------------------------------------ run folders
def test_run_writes_a_folder_that_loads_back_as_the_same_result(tmp_path):
    out = tmp_path / "run"
    done = sim.run(SHORT, out_dir=out, video=False, plots=False)
    assert done.path == out and (out / "summary.json").is_file()
    loaded = sim.RunResult.load(out)
    for field in ("scenario", "robot", "verdict", "checks", "warnings", "joints", "collisions",
                  "saturation", "sizing", "sizing_passed", "selection"):
        assert getattr(loaded, field) == getattr(done, field), field
    assert loaded.to_dict() == json.loads((out / "summary.json").read_text())
    assert loaded._arrays is None  # nothing read until asked
    saved = np.load(out / "trajectory.npz")
    assert np.array_equal(loaded.arrays["q"], saved["q"])
    # the folder keeps record_hz of the samples: each kept sample is the one simulated then
    idx = np.searchsorted(done.arrays["t"], loaded.arrays["t"])
    assert np.array_equal(done.arrays["q"][idx], loaded.arrays["q"])


@pytest.mark.parametrize("damage", ["no folder", "no summary", "not json", "no verdict",
                                    "writing"])
def test_load_refuses_what_is_not_a_finished_run_in_one_line(tmp_path, damage):
    folder = tmp_path / "run"
    if damage != "no folder":
        folder.mkdir()
        (folder / "summary.json").write_text({"no summary": "", "not json": "{oops",
                                              "no verdict": '{"scenario": "x"}',
                                              "writing": "{}"}[damage])
        if damage == "no summary":
            (folder / "summary.json").unlink()
        if damage == "writing":
            (folder / ".cellsim-run").write_text('{"written_by": "cellsim", "state": "writing"}')
    with pytest.raises(RunFolderError) as info:
        sim.RunResult.load(folder)
    message = str(info.value)
    assert str(folder) in message and "\n" not in message and "Traceback" not in message


def test_sweep_tabulates_every_variant(tmp_path):
    result = sim.sweep(SHORT, payloads_kg=[0.0, 4.0], out_dir=tmp_path / "sweep")
    rows = result.rows
    assert len(rows) == 2 * 5 and not result.failures
    assert (tmp_path / "sweep" / "sweep.csv").is_file()
    peak = {r["payload_kg"]: r["peak_torque_nm"] for r in rows if r["joint"] == "j2"}
    assert peak[4.0] > peak[0.0]  # 4 kg more at the flange loads the shoulder more


@pytest.mark.parametrize(("kw", "needle"), [
    ({"payloads_kg": "1,2"}, "payloads_kg: expected numbers like [0, 2.5, 5], got the text '1,2'"),
    ({"payloads_kg": [True]}, "payloads_kg: True is not a number"),  # True is not 1 kg
    ({"payloads_kg": [1.0, None]}, "payloads_kg: None is not a number"),
    ({"speed_scales": "fast"}, "speed_scales: expected numbers like [0.5, 1, 1.5], got the text"),
    ({"speed_scales": [1.0, "2"]}, "speed_scales: '2' is not a number"),
    ({"speed_scales": object()}, "speed_scales: expected numbers like [0.5, 1, 1.5], got object"),
])
def test_bad_sweep_values_are_one_line_cellsim_errors(tmp_path, kw, needle):
    """Values a script may pass by mistake (found by a new-user trial: a string raised
    ValueError, a bare float TypeError, and True ran as 1 kg): one line, a CellsimError (a
    SweepError), raised before anything is written."""
    with pytest.raises(sim.CellsimError) as info:
        sim.sweep(SHORT, out_dir=tmp_path / "sweep", **kw)
    assert needle in str(info.value) and "\n" not in str(info.value)
    assert not (tmp_path / "sweep").exists()


def test_one_number_is_a_sweep_of_one(tmp_path):
    """``speed_scales=1.0`` and ``payloads_kg=2.0`` (one number each, not a list) are a sweep
    of that one variant, as the docs' signature reads."""
    result = sim.sweep(SHORT, payloads_kg=2.0, speed_scales=1.0, out_dir=tmp_path / "sweep")
    assert {(r["payload_kg"], r["speed_scale"]) for r in result.rows} == {(2.0, 1.0)}


# ---------------------------------------------------------------------------- examples
EXAMPLES = {
    "payload_study.py": ([SHORT, "0", "5"], 2),
    "robot_comparison.py": (["m10ia"], 1),
    "cell_in_code.py": (["{tmp}", "150"], 1),
}


def test_every_example_is_tested():
    assert sorted(p.name for p in (ROOT / "examples").glob("*.py")) == sorted(EXAMPLES)


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_examples_run_as_a_user_runs_them(name, tmp_path):
    args, lines = EXAMPLES[name]
    res = subprocess.run([sys.executable, str(ROOT / "examples" / name),
                          *(a.format(tmp=tmp_path) for a in args)],
                         capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    out = [line for line in res.stdout.splitlines() if line.strip()]
    assert len(out) >= lines and "Traceback" not in res.stderr
    if name == "robot_comparison.py":  # the library arm with the shipped torch welds clean
        assert out[-1].split()[:2] == ["m10ia", "pass"], out
    if name == "cell_in_code.py":
        assert "seam 150.0 mm at 10.00 mm/s" in out[-1] and ": pass," in out[-1]
        shutil.rmtree(tmp_path / "run")


@pytest.mark.render
def test_a_script_gets_its_video_without_setting_up_opengl(tmp_path):
    """No ``configure_gl`` and no ``MUJOCO_GL`` in the script: ``sim.run`` finds a working
    backend itself, even after an evaluation has imported mujoco."""
    script = (
        "import sim\n"
        f"sim.evaluate({SHORT!r})\n"
        f"r = sim.run({SHORT!r}, out_dir={str(tmp_path / 'run')!r}, plots=False,\n"
        "            video_args={'width': 64, 'height': 48, 'fps': 2.0})\n"
        "print(r.to_dict()['video'])\n")
    env = {k: v for k, v in __import__("os").environ.items() if k != "MUJOCO_GL"}
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stderr[-3000:]
    video = tmp_path / "run" / res.stdout.split()[-1]
    assert video.is_file() and video.stat().st_size > 1000
    import imageio.v3 as iio

    frames = iio.imread(video)
    assert frames.shape[0] == 21 and frames.shape[1:3] == (48, 64)

"""Faults (issue 18): a killed run, two runs into one folder, a parent that is a file, a name
too long. Nothing is lost, nothing half-written is taken for a result, every refusal is one
line with exit 2.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from support.limits import cpu_seconds, popen_limited, run_limited, wait_until
from support.scenarios import joint_phase, scenario_text

from sim.cli import main
from sim.errors import RunFolderError
from sim.simulation.runfolder import MARKER, is_run_folder, load_run, marker_state

SLOW = "bugnar_5r_weld_cycle"  # ~15 s without video or plots: time to interrupt it
QUICK = "bugnar_5r_phase1"


def _start(out: Path, scenario: str = SLOW) -> subprocess.Popen:
    return popen_limited([sys.executable, "-I", "-m", "sim", "run", scenario, "--out",
                          str(out), "--no-video", "--no-plots", "--quiet"], cpu_s=600,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         cwd=Path(__file__).resolve().parents[2])


def _hidden(out: Path) -> list[Path]:
    return sorted(p for p in out.parent.iterdir() if p.name.startswith(f".{out.name}."))




@pytest.mark.slow
def test_sigkill_mid_run_leaves_nothing_taken_for_a_result(tmp_path, capsys):
    out = tmp_path / "run"
    proc = _start(out)
    # the hidden temporary folder appears with the model: the simulation is under way
    wait_until(lambda: any((p / "model.xml").is_file() for p in _hidden(out) if p.is_dir()),
               proc)
    time.sleep(1.0)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    left = [p for p in _hidden(out) if p.is_dir()]
    assert left and all(marker_state(p) == "writing" for p in left)
    assert not out.exists()
    for p in left:  # a killed run's folder is never read as a result
        with pytest.raises(RunFolderError, match="still being written"):
            load_run(p)
    # the next run into the same place removes the leftovers and writes a complete result
    assert main(["run", QUICK, "--out", str(out), "--no-video", "--no-plots", "--quiet"]) == 0
    assert _hidden(out) == []
    assert is_run_folder(out) and marker_state(out) == "complete"
    assert load_run(out).t.size > 0


@pytest.mark.slow
def test_a_second_run_into_a_busy_folder_refuses_cleanly(tmp_path, capsys):
    out = tmp_path / "run"
    first = _start(out)
    lock = out.with_name(f".{out.name}.lock")
    wait_until(lambda: lock.is_file() and lock.read_text().strip() == str(first.pid), first)
    rc = main(["run", QUICK, "--out", str(out), "--no-video", "--no-plots", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2
    assert f"being written by another cellsim run (pid {first.pid})" in err
    assert err.count("\n") == 1
    assert first.wait() == 0  # the first run is untouched and completes
    summary = load_run(out).summary
    assert summary["scenario"] == SLOW
    assert _hidden(out) == []  # its lock is gone too


def test_parent_that_is_a_file_and_a_name_too_long_are_one_line(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("mine")
    assert main(["run", QUICK, "--out", str(blocker / "run"), "--no-video", "--no-plots",
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(blocker) in err
    assert blocker.read_text() == "mine"
    long = tmp_path / ("x" * 300)
    assert main(["run", QUICK, "--out", str(long), "--no-video", "--no-plots", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "too long" in err.lower(), err
    assert not any(p.name.startswith(".x") for p in tmp_path.iterdir())


def test_marker_says_complete_only_at_the_end(tmp_path):
    out = tmp_path / "run"
    assert main(["run", QUICK, "--out", str(out), "--no-video", "--no-plots", "--quiet"]) == 0
    assert (out / MARKER).is_file() and marker_state(out) == "complete"
    assert not out.with_name(f".{out.name}.lock").exists()


def test_remove_stale_leaves_other_folders_alone(tmp_path):
    """Only this place's leftovers go: not another run's (``a.b`` next to ``a``), not a user's
    hidden folder that looks alike but was not written by cellsim."""
    from sim.simulation.runfolder import remove_stale, write_marker

    mine = tmp_path / ".a.abcd1234"
    mine.mkdir()
    write_marker(mine, state="writing")
    other = tmp_path / ".a.b.abcd1234"
    other.mkdir()
    write_marker(other, state="writing")
    user = tmp_path / ".a.zzzz9999"
    user.mkdir()
    (user / "notes.txt").write_text("mine")
    gone = remove_stale(tmp_path / "a")
    assert gone == [mine] and other.is_dir() and (user / "notes.txt").is_file()



def test_a_planted_mujoco_py_in_the_working_directory_is_never_run(tmp_path, monkeypatch):
    """The OpenGL probe's helper process runs isolated (``python -I``): a ``mujoco.py`` in the
    working directory is not imported by it."""
    import sim.render.gl as gl

    flag = tmp_path / "planted-ran"
    (tmp_path / "mujoco.py").write_text(f"open({str(flag)!r}, 'w').write('x')\n"
                                        "raise SystemExit(3)\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(gl, "_probe_cache", {})
    for backend in ("egl", "osmesa"):
        gl.probe_backend(backend)
    assert not flag.exists()


@pytest.mark.parametrize("edit, words", [
    (("speed_mm_s = 8.0", "speed_mm_s = 1e-9", 1), ["the move lasts", "longer than a run can "
                                                     "simulate", "2,000,000"]),
    (("speed_mm_s = 8.0", "speed_mm_s = 8.0\nsample_period_s = 1e-6", 1),
     ["inverse-kinematics samples", "1,000,000"]),
    (("[video]", "[simulation]\ntimestep_s = 1e-9\n\n[video]", 1), ["steps", "2,000,000",
                                                                    "simulation.timestep_s"]),
    (("[video]", "[simulation]\nsettle_s = 1e9\n\n[video]", 1), ["settle_s", "2,000,000"]),
])
def test_sizes_are_bounded_before_anything_is_allocated(tmp_path, capsys, edit, words):
    """A speed of 1e-9 mm/s, a 1e-9 s timestep or 1e9 s of settling: one line naming the key,
    the count it would give and the limit, exit 2, in well under a second of work."""
    from sim.core.resources import shipped_scenarios

    text = Path(shipped_scenarios()["lrmate200ic_weld_plate"]).read_text()
    old, new, n = edit
    assert old in text
    path = tmp_path / "s.toml"
    path.write_text(text.replace(old, new, n))
    start = time.process_time()
    rc = main(["run", str(path), "--out", str(tmp_path / "run"), "--no-video", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1, err
    assert all(w in err for w in words), err
    assert time.process_time() - start < 20.0  # CPU time: a loaded machine must not fail it
    assert not (tmp_path / "run").exists()


def test_sweep_ranges_are_bounded(tmp_path, capsys):
    rc = main(["size", "lrmate200ic_pick_place", "--payload", "0:1e308:1e-300", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "--payload" in err and "at most 10000" in err and err.count("\n") == 1
    # each list within its bound, their product not: refused before any folder or variant
    rc = main(["size", "lrmate200ic_pick_place", "--payload", "0:200:1", "--speed-scale",
               "0.5:1.5:0.01", "--quiet", "--out", str(tmp_path / "s")])
    err = capsys.readouterr().err
    assert rc == 2 and "201 payloads x 101 speed scales make 20301 variants (at most 10000)" \
        in err and err.count("\n") == 1
    assert not (tmp_path / "s").exists()


@pytest.mark.render
def test_frame_counts_are_bounded(tmp_path, capsys):
    """`cellsim render --fps 1000 --speed 0.001` (2 million frames of a 2 s run; a rate over
    1000 fps is refused as a rate): one line naming --fps, the count and the limit; no hang."""
    import sim.render.gl as gl
    from sim.render.synthetic import write_synthetic_run

    gl.configure_gl()
    run = write_synthetic_run(tmp_path / "run", duration=2.0)
    start = time.process_time()
    rc = main(["render", str(run), "--fps", "1000", "--speed", "0.001", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "--fps" in err and "108,000" in err and err.count("\n") == 1, err
    assert time.process_time() - start < 20.0  # CPU time, not wall time


COARSE = """name = "coarse"
description = "a linear move sampled too coarsely for its length"
robot = "lrmate200ic5l"
cell = "weld_table"
tool = "mig_torch"

[[phases]]
name = "start"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0]]

[[phases]]
name = "above"
planner = "434"
durations_s = [1.5]
to_mm = [330.0, 120.0, -60.0]
euler_zyx_deg = [0.0, 0.0, 180.0]

[[phases]]
name = "across"
kind = "linear"
to_mm = [330.0, 220.0, -60.0]
speed_mm_s = 100.0
sample_period_s = {period}
"""


@pytest.mark.parametrize("period, passes", [(0.4, False), (0.01, True)])
def test_a_cartesian_phase_that_misses_its_speed_fails_the_verdict(tmp_path, period, passes,
                                                                    monkeypatch):
    """100 mm at 100 mm/s sampled every 0.4 s, without the planner's halving of the intervals
    where the joint polynomial leaves the move (a planted fault:
    :data:`~sim.simulation.motion.sampling.PATH_REFINEMENTS` 0): the joint interpolation
    between so few samples runs the tool 7.8 % fast, a failed check; sampled every 10 ms it
    keeps the speed."""
    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario
    from sim.simulation.motion import sampling

    monkeypatch.setattr(sampling, "PATH_REFINEMENTS", 0)

    path = tmp_path / "coarse.toml"
    path.write_text(COARSE.format(period=period))
    summary = run_scenario(load_scenario(path), RunOptions(
        out_dir=tmp_path / "run", video=False, plots=False, sizing=False, progress=False))
    (check,) = [c for c in summary["checks"] if c["name"] == "cartesian_speed"]
    assert check["pass"] is passes and (check["value"] > 1.0) is not passes
    assert (summary["verdict"] == "pass") is passes


def test_a_phase_shorter_than_the_timestep_is_a_user_error(tmp_path, capsys):
    path = tmp_path / "short.toml"
    path.write_text(COARSE.format(period=0.01) + """
[[phases]]
name = "blink"
kind = "hold"
duration_s = 0.0004
""")
    rc = main(["run", str(path), "--out", str(tmp_path / "run"), "--no-video", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "phases[3] (blink)" in err and "shorter than one timestep" in err


def test_a_full_disk_is_one_line_and_the_previous_result_stays(tmp_path, capsys, monkeypatch):
    """ENOSPC while the run writes its files (simulated where the run writes trajectory.npz):
    one line with the path, exit 2, the previous result in the folder untouched and no hidden
    leftovers."""
    import errno

    import sim.simulation.runfolder as rf

    out = tmp_path / "run"
    assert main(["run", QUICK, "--out", str(out), "--no-video", "--no-plots", "--quiet"]) == 0
    before = (out / "summary.json").read_bytes()

    def full(folder, arrays):
        raise OSError(errno.ENOSPC, "No space left on device", str(Path(folder) / "trajectory.npz"))

    monkeypatch.setattr(rf, "write_trajectory", full)
    rc = main(["run", QUICK, "--out", str(out), "--no-video", "--no-plots", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "No space left on device" in err
    assert "trajectory.npz" in err
    assert (out / "summary.json").read_bytes() == before
    assert _hidden(out) == []


_FINISHED: list[Path] = []


def _finished_run(tmp_path) -> Path:
    """A finished run folder of :data:`QUICK` at ``tmp_path / "run"``: the module's one run,
    copied (each test may spoil its copy)."""
    import shutil
    import tempfile

    if not _FINISHED:
        first = Path(tempfile.mkdtemp(prefix="cellsim-faults-")) / "run"
        assert main(["run", QUICK, "--out", str(first), "--no-video", "--no-plots",
                     "--quiet"]) == 0
        _FINISHED.append(first)
    out = tmp_path / "run"
    shutil.copytree(_FINISHED[0], out)
    return out


@pytest.mark.parametrize("attack, words", [
    ("include", "includes"),
    ("mesh", "outside the run folder"),
    ("meshdir", "outside the run folder"),
])
def test_render_loads_only_files_inside_the_folder(tmp_path, capsys, attack, words):
    """A model.xml that would read a file elsewhere on disk is refused before MuJoCo opens
    anything."""
    out = _finished_run(tmp_path)
    xml = (out / "model.xml").read_text()
    secret = tmp_path / "secret.stl"
    secret.write_bytes(b"solid x\nendsolid x\n")
    if attack == "include":
        xml = xml.replace("<worldbody>", f'<include file="{tmp_path / "other.xml"}"/>\n'
                          "<worldbody>", 1)
    elif attack == "mesh":
        xml = xml.replace("<asset>", f'<asset>\n<mesh name="evil" file="{secret}"/>', 1)
    else:
        xml = xml.replace("<compiler", '<compiler meshdir="../.."', 1)
    (out / "model.xml").write_text(xml)
    rc = main(["render", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and err.count("\n") == 1, err


def test_render_refuses_nan_arrays_and_a_plots_symlink(tmp_path, capsys):
    import numpy as np

    out = _finished_run(tmp_path)
    arrays = dict(np.load(out / "trajectory.npz"))
    arrays["qpos"][5, 0] = np.nan
    np.savez(out / "trajectory.npz", **arrays)
    rc = main(["render", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "'qpos' holds NaN or inf" in err
    out2 = _finished_run(tmp_path / "b")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (out2 / "plots").symlink_to(elsewhere)
    rc = main(["render", str(out2), "--plots", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "symbolic link" in err and list(elsewhere.iterdir()) == []
    assert not (out2 / "video.mp4").exists()  # refused before rendering, not after


@pytest.mark.parametrize("time_s", [-1.0, 1e9])
def test_actions_outside_the_cycle_are_refused(tmp_path, capsys, time_s):
    path = tmp_path / "a.toml"
    path.write_text(COARSE.format(period=0.01).replace(
        'tool = "mig_torch"', f'tool = "mig_torch"\n\n[[actions]]\naction = "arc_on"\n'
                              f"time_s = {time_s}", 1))
    rc = main(["check", str(path)])
    err = capsys.readouterr().err
    assert rc == 2 and "actions[0].time_s" in err and "outside the cycle" in err, err


def test_workspace_out_that_is_a_folder_is_one_line(tmp_path, capsys):
    (tmp_path / "pic.png").mkdir()
    rc = main(["workspace", "lrmate100ib", "--out", str(tmp_path / "pic.png")])
    err = capsys.readouterr().err
    assert rc == 2 and "is a folder" in err and err.count("\n") == 1


@pytest.mark.slow
@pytest.mark.render
def test_sigkill_mid_video_then_rerun(tmp_path, capsys):
    """Killed while encoding the video (its stage lines on stderr say when): the next run
    into the place completes, video included, with no leftovers."""
    import select

    out = tmp_path / "run"
    proc = popen_limited([sys.executable, "-I", "-m", "sim", "run", QUICK, "--out", str(out),
                          "--no-plots", "--width", "160", "--height", "120"], cpu_s=600,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         cwd=Path(__file__).resolve().parents[2])
    seen = ""
    while "cellsim: sizing" not in seen:  # the next stage is the video
        assert cpu_seconds(proc.pid) < 300 and proc.poll() is None, seen
        ready, _, _ = select.select([proc.stderr], [], [], 1.0)
        if ready:
            seen += proc.stderr.readline()
    time.sleep(0.5)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not out.exists() and [p for p in _hidden(out) if p.is_dir()]
    assert main(["run", QUICK, "--out", str(out), "--no-plots", "--quiet", "--width", "160",
                 "--height", "120"]) == 0
    assert (out / "video.mp4").stat().st_size > 0 and _hidden(out) == []


@pytest.mark.parametrize("target", ["trajectory.npz", "summary.json", "model.xml"])
def test_render_of_a_damaged_folder_is_one_line(tmp_path, capsys, target):
    """Bytes overwritten in the middle of a run's file: `cellsim render` says which file is
    damaged, exit 2, no traceback."""
    out = _finished_run(tmp_path)
    path = out / target
    data = bytearray(path.read_bytes())
    mid = len(data) // 2
    data[mid:mid + 64] = b"\x00\xff" * 32
    path.write_bytes(bytes(data))
    rc = main(["render", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "Traceback" not in err and err.count("\n") == 1, err


def test_a_sweep_never_writes_into_the_working_directory_or_a_users_folder(tmp_path, capsys,
                                                                            monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "sweep.csv").write_text("my data")
    for out in (".", "mine"):
        rc = main(["size", QUICK, "--out", out, "--workers", "1", "--quiet"])
        err = capsys.readouterr().err
        assert rc == 2 and err.count("\n") == 1, (out, err)
    assert (tmp_path / "mine" / "sweep.csv").read_text() == "my data"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


# ---------------------------------------------------------- a real full disk, a read-only parent
def _namespace_mounts() -> bool:
    """Whether this machine lets an unprivileged user namespace mount a tmpfs (Linux with
    util-linux's ``unshare``; containers often allow it, some CI runners do not)."""
    import shutil

    if shutil.which("unshare") is None:
        return False
    try:
        probe = run_limited(["unshare", "-rm", "sh", "-c",
                                "mount -t tmpfs -o size=1m tmpfs /mnt"],
                               capture_output=True, cpu_s=30)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return probe.returncode == 0


_MOUNTS = _namespace_mounts()
needs_mounts = pytest.mark.skipif(not _MOUNTS, reason="this machine allows no tmpfs mount "
                                  "in a user namespace (unshare -rm)")

#: Runs inside ``unshare -rm`` (a private mount namespace): mounts a 20 MB tmpfs, writes a
#: result into it, fills it, runs again into the same folder, then runs into a read-only
#: bind mount; prints what it saw as JSON. The mounts vanish with the namespace.
_DRIVER = r"""
import json, os, subprocess, sys
root, scenario = sys.argv[1], sys.argv[2]
def sh(*cmd):
    subprocess.run(cmd, check=True)
def run(out, *extra):
    p = subprocess.run([sys.executable, "-I", "-m", "sim", "run", scenario, "--out", out,
                        "--no-plots", "--quiet", *extra], capture_output=True, text=True)
    return {"rc": p.returncode, "err": p.stderr}
disk = os.path.join(root, "disk")
sh("mount", "-t", "tmpfs", "-o", "size=20m", "tmpfs", disk)
seen = {"first": run(os.path.join(disk, "run"), "--no-video")}
summary = open(os.path.join(disk, "run", "summary.json"), "rb").read()
free = os.statvfs(disk).f_bavail * os.statvfs(disk).f_frsize
with open(os.path.join(disk, "filler"), "wb") as fh:   # leave 1 MB: less than one result
    fh.write(b"\0" * (free - (1 << 20)))
seen["full_npz"] = run(os.path.join(disk, "run"), "--no-video")
os.remove(os.path.join(disk, "filler"))
with open(os.path.join(disk, "filler"), "wb") as fh:   # room for model.xml, not the video
    fh.write(b"\0" * (free - (256 << 10)))
seen["full_video"] = run(os.path.join(disk, "run"))
seen["summary_kept"] = open(os.path.join(disk, "run", "summary.json"), "rb").read() == summary
seen["left"] = sorted(os.listdir(disk))
with open(os.path.join(disk, "filler2"), "wb") as fh:   # nothing left at all
    try:
        fh.write(b"\0" * (1 << 20))
    except OSError:
        pass
p = subprocess.run([sys.executable, "-I", "-m", "sim", "workspace", "lrmate200ic5l", "--out",
                    os.path.join(disk, "ws.png")], capture_output=True, text=True)
seen["workspace_full"] = {"rc": p.returncode, "err": p.stderr}
seen["ws_left"] = sorted(n for n in os.listdir(disk) if "ws.png" in n)
ro = os.path.join(root, "ro")
sh("mount", "--bind", ro, ro)
sh("mount", "-o", "remount,bind,ro", ro)
seen["read_only"] = run(os.path.join(ro, "run"), "--no-video")
seen["ro_left"] = sorted(os.listdir(ro))
print(json.dumps(seen))
"""


@pytest.mark.slow  # five cellsim processes, one encoding a video until the disk is full
@needs_mounts
def test_a_real_full_disk_and_a_read_only_parent(tmp_path):
    """A 20 MB tmpfs as --out: a first result fits; with the disk filled, a second run (failing
    while writing its arrays, then while encoding its video) is one line naming the file, exit
    2, the first result untouched and no hidden leftovers. A read-only parent: one line, exit 2,
    nothing written."""
    import json

    (tmp_path / "disk").mkdir()
    (tmp_path / "ro").mkdir()
    driver = tmp_path / "driver.py"
    driver.write_text(_DRIVER)
    done = run_limited(["unshare", "-rm", sys.executable, "-I", str(driver), str(tmp_path),
                           QUICK], capture_output=True, text=True, cpu_s=600,
                          cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert seen["first"]["rc"] == 0, seen["first"]["err"]
    disk = tmp_path / "disk"
    # a run writes its video before its arrays
    for case, file in (("full_npz", "trajectory.npz"), ("full_video", "video.mp4")):
        rc, err = seen[case]["rc"], seen[case]["err"]
        assert rc == 2 and err.count("\n") == 1, (case, err)
        assert err.startswith(f"cellsim: error: {disk / 'run' / file} ") and \
            "No space left on device" in err, (case, err)
    assert seen["summary_kept"]
    assert seen["left"] == ["filler", "run"]  # no hidden temporary folder, no lock
    rc, err = seen["workspace_full"]["rc"], seen["workspace_full"]["err"]
    assert rc == 2 and err.count("\n") == 1 and "No space left on device" in err, err
    assert str(disk / "ws.png") in err
    assert seen["ws_left"] == []  # neither a half-written picture nor its temporary file
    rc, err = seen["read_only"]["rc"], seen["read_only"]["err"]
    assert rc == 2 and err.count("\n") == 1 and "Read-only file system" in err, err
    assert str(tmp_path / "ro") in err
    assert seen["ro_left"] == []


# ---------------------------------------------------------------------------- every reader
def _readers():
    """Every reader of a file a user names: (what, function taking the path)."""
    from sim.analysis.catalog import load_catalog
    from sim.cells import load_cell
    from sim.cells.meshes import read_mesh
    from sim.cells.toolfile import load_tool_file
    from sim.robots.kinematics.chain import chain_from_urdf
    from sim.robots.robotfile import load_robot_folder
    from sim.scenario import load_scenario
    from sim.scenario.fanuc_ls import read_ls

    def robot_folder(path: Path):  # path: the folder's robot.toml
        return load_robot_folder(path.parent)

    return {"scenario": load_scenario, "cell": load_cell, "tool": load_tool_file,
            "robot.toml": robot_folder, "URDF": chain_from_urdf, "TP program": read_ls,
            "catalogue": load_catalog, "mesh": read_mesh}


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "folder"])
@pytest.mark.parametrize("reader", ["catalogue", "cell", "mesh", "robot.toml", "scenario",
                                    "TP program", "tool", "URDF"])
def test_every_reader_refuses_a_fifo_a_device_and_a_folder_in_one_line(reader, kind, tmp_path):
    """Issue 31: a FIFO with no writer (which blocked forever), /dev/zero (which read until
    memory ran out) or a folder given as any input file is refused before a byte is read:
    cellsim's own error, one line naming the path. The call returning at all is the check
    that nothing blocks (a FIFO with no writer blocks a plain open)."""
    import os

    from sim.errors import CellsimError

    suffix = {"mesh": ".stl", "TP program": ".ls", "URDF": ".urdf"}.get(reader, ".toml")
    path = tmp_path / f"input{suffix}"
    if reader == "robot.toml":
        path = tmp_path / "input" / "robot.toml"
        path.parent.mkdir()
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev_zero":
        path.symlink_to("/dev/zero")
    else:
        path.mkdir()
    with pytest.raises(CellsimError) as err:
        _readers()[reader](path)
    msg = str(err.value)
    assert "\n" not in msg and "input" in msg, msg


def test_a_binary_stl_is_bounded_by_its_header_before_it_is_loaded(tmp_path):
    """A binary STL whose header promises more triangles than the limit is refused from its
    84 bytes (it was loaded whole first: 48 s and 2.9 GB for 250 MB); one whose file is
    shorter than its header says is refused as truncated."""
    from sim.cells.meshes import MAX_FACES, read_mesh
    from sim.errors import CellError

    big = tmp_path / "big.stl"
    with open(big, "wb") as fh:
        fh.write(b"\0" * 80 + (MAX_FACES + 1).to_bytes(4, "little"))
        fh.truncate(84 + 50 * (MAX_FACES + 1))  # sparse: no disk used
    with pytest.raises(CellError, match="triangles .its header., more than"):
        read_mesh(big)
    short = tmp_path / "short.stl"
    short.write_bytes(b"\0" * 80 + (12).to_bytes(4, "little") + b"\0" * 50 * 11)
    with pytest.raises(CellError, match="truncated"):
        read_mesh(short)


@pytest.mark.parametrize("payload, passes", [(3.0, True), (15.0, False)])
def test_a_payload_over_the_robots_rating_fails_the_verdict(payload, passes, tmp_path):
    """Issue 31: three times the LR Mate 200iC/5L's 5 kg passed; the tool's mass and the
    payload are checked against the rating (check ``payload``): over it, the verdict fails."""
    from sim.cells.tools import TOOLS
    from sim.pipeline.run import RunOptions, evaluate_scenario
    from sim.robots.registry import ROBOTS
    from sim.scenario import parse_scenario

    text = scenario_text("lrmate200ic5l", [joint_phase(
        [[0, 0, 0, 0, -90, 0], [2, 2, -2, 0, -88, 0], [4, 4, -4, 0, -86, 0],
         [6, 6, -6, 0, -84, 0], [8, 8, -8, 0, -82, 0]], time_s=[0.0, 0.5, 1.0, 1.5, 2.0])],
        name="heavy", description="a joint move with a payload", cell="weld_table",
        tool="mig_torch", payload_kg=payload)
    ev = evaluate_scenario(parse_scenario(text), RunOptions(video=False, plots=False,
                                                            progress=False))
    check = next(c for c in ev.summary["checks"] if c["name"] == "payload")
    load = TOOLS.get("mig_torch").mass_kg + payload
    assert check["value"] == pytest.approx(load) and check["limit"] == ROBOTS[
        "lrmate200ic5l"].payload_kg
    assert check["pass"] is passes
    if not passes:
        assert ev.summary["verdict"] == "fail"


def test_check_is_bounded_like_run(tmp_path, capsys):
    """Issue 31: `cellsim check` sampled any duration (a joint move of 2.5e5 s: 2.5e8 samples)
    where `cellsim run` refuses it; now the same one line and exit 2 as run."""
    from sim.core.resources import shipped_scenarios

    text = Path(shipped_scenarios()["lrmate200ic_weld_plate"]).read_text()
    assert text.count("durations_s = [2.5]") == 1
    path = tmp_path / "s.toml"
    path.write_text(text.replace("durations_s = [2.5]", "durations_s = [2.5e5]"))
    rc = main(["check", str(path)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "2,000,000" in err, err

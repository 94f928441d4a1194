"""A run folder is cellsim's to replace, but not what a colleague put into it.

Found by a new-user trial: notes and an annotated plot added to a run folder vanished without a
word when the run was repeated into it; the folder was mode 0700 (colleagues could not open
its report); ``cellsim render --out`` overwrote any .mp4 and made missing folders. The rules
checked here: a rerun replaces only what cellsim wrote (listed in the folder's inventory)
and names anything else instead of deleting it; the folder gets the permissions ``mkdir``
gives; render refuses a file cellsim did not write and a folder that does not exist.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from sim.cli import main
from sim.simulation import runfolder

SCENARIO = "bugnar_5r_phase1"  # 10 s of motion: a run of a few seconds


def _run(out: Path) -> int:
    return main(["run", SCENARIO, "--out", str(out), "--no-video", "--no-plots", "--quiet"])


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("own") / "run"
    assert _run(out) == 0
    return out


def test_a_run_folder_has_the_permissions_mkdir_gives(run_dir):
    mask = os.umask(0)
    os.umask(mask)
    assert run_dir.stat().st_mode & 0o777 == 0o777 & ~mask


def test_the_inventory_lists_every_file_the_run_wrote(run_dir):
    listed = set((run_dir / runfolder.INVENTORY).read_text().splitlines())
    on_disk = {p.relative_to(run_dir).as_posix() + ("/" if p.is_dir() else "")
               for p in run_dir.rglob("*")} - {runfolder.MARKER, runfolder.INVENTORY}
    assert listed == on_disk and "summary.json" in listed
    assert runfolder.foreign_entries(run_dir) == []


def test_a_rerun_keeps_a_colleagues_files_and_says_which(tmp_path, capsys):
    out = tmp_path / "run"
    assert _run(out) == 0
    (out / "notes.txt").write_text("mine")
    (out / "mine").mkdir()
    (out / "mine" / "annotated.png").write_bytes(b"png")
    capsys.readouterr()
    assert _run(out) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds what cellsim did not write (mine/, notes.txt)" in err
    assert (out / "notes.txt").read_text() == "mine" and (out / "mine" / "annotated.png").is_file()
    (out / "notes.txt").unlink()
    (out / "mine" / "annotated.png").unlink()
    (out / "mine").rmdir()
    assert _run(out) == 0  # only cellsim's files: replaced as before


def test_render_refuses_a_file_it_did_not_write_and_a_missing_folder(run_dir, tmp_path, capsys):
    precious = tmp_path / "precious.mp4"
    precious.write_text("precious")
    assert main(["render", str(run_dir), "--out", str(precious), "--quiet"]) == 2
    assert "exists; cellsim does not overwrite files it did not write" in capsys.readouterr().err
    assert precious.read_text() == "precious"
    missing = tmp_path / "nodir" / "x.mp4"
    assert main(["render", str(run_dir), "--out", str(missing), "--quiet"]) == 2
    assert "no such folder" in capsys.readouterr().err and not missing.parent.exists()
    # the run's own video: a file cellsim wrote (listed), or one render adds (noted)
    assert runfolder.written_by_cellsim(run_dir / "summary.json", run_dir)
    assert not runfolder.written_by_cellsim(precious, run_dir)


def test_what_render_writes_into_a_run_folder_is_noted_as_cellsims(tmp_path):
    out = tmp_path / "run"
    assert _run(out) == 0
    video = out / "video.mp4"
    plot = out / "plots" / "joint_j1.png"
    plot.parent.mkdir()
    video.write_bytes(b"mp4")
    plot.write_bytes(b"png")
    assert runfolder.foreign_entries(out) == ["plots/", "video.mp4"]
    runfolder.note_written(out, [video, plot])
    assert runfolder.foreign_entries(out) == []
    assert runfolder.written_by_cellsim(video, out)

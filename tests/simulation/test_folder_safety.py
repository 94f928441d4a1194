"""Nothing the user owns is deleted: cellsim replaces only run folders it wrote itself."""

from __future__ import annotations

import os

import pytest

from sim.cli import main
from sim.errors import RunFolderError, ScenarioError
from sim.scenario import load_scenario
from sim.simulation.runfolder import MARKER, check_out_dir, is_run_folder, note_written

RUN = ["run", "kacso_lrmate100ib_sequence1", "--no-video", "--no-plots", "--quiet"]


def _user_folder(path):
    path.mkdir()
    (path / "thesis.tex").write_text("years of work")
    return path


def test_a_rerun_replaces_the_folder_cellsim_wrote(tmp_path):
    out = tmp_path / "run"
    assert main([*RUN, "--out", str(out)]) == 0
    assert is_run_folder(out) and (out / "summary.json").is_file()
    # a file of cellsim's that the second run does not write again (listed as cellsim's, as
    # `cellsim render` lists its video): gone with the folder it belonged to. A file that is
    # not cellsim's is refused instead (tests/pipeline/test_run_folder_own_files.py)
    (out / "stale.txt").write_text("from the first run")
    note_written(out, [out / "stale.txt"])
    assert main([*RUN, "--out", str(out)]) == 0
    assert (out / MARKER).is_file() and not (out / "stale.txt").exists()


@pytest.mark.parametrize("case", ["user_folder", "file", "symlink", "cwd", "cwd_parent", "dot"])
def test_refuses_to_replace_what_it_did_not_write(case, tmp_path, monkeypatch, capsys):
    user = _user_folder(tmp_path / "mine")
    if case == "user_folder":
        out = str(user)
    elif case == "file":
        out = str(user / "thesis.tex")
    elif case == "symlink":
        link = tmp_path / "link"
        link.symlink_to(user, target_is_directory=True)
        out = str(link)
    elif case == "cwd":
        monkeypatch.chdir(user)
        out = str(user)
    elif case == "cwd_parent":
        monkeypatch.chdir(user)
        out = str(tmp_path)
    else:
        monkeypatch.chdir(user)
        out = "."
    assert main([*RUN, "--out", out]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("cellsim: error: run folder") and "\n" not in err
    assert (user / "thesis.tex").read_text() == "years of work"
    assert sorted(os.listdir(user)) == ["thesis.tex"]
    assert not any(p.name.startswith(".mine.") for p in tmp_path.iterdir())  # no temp left


def test_an_empty_folder_may_be_used(tmp_path):
    out = tmp_path / "empty"
    out.mkdir()
    assert check_out_dir(out) == out.resolve()
    assert main([*RUN, "--out", str(out)]) == 0 and is_run_folder(out)


@pytest.mark.parametrize("name", [".", "..", ".hidden"])
def test_scenario_names_that_are_not_plain_folder_names_are_refused(name, tmp_path):
    text = load_scenario("kacso_lrmate100ib_sequence1").text.replace(
        'name = "kacso_lrmate100ib_sequence1"', f'name = "{name}"', 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError, match=r"bad.toml: name"):
        load_scenario(path)


def test_check_out_dir_is_the_one_gate(tmp_path):
    with pytest.raises(RunFolderError, match="symbolic link"):
        link = tmp_path / "l"
        link.symlink_to(tmp_path)
        check_out_dir(link)
    with pytest.raises(RunFolderError, match="give a folder name"):
        check_out_dir("..")


def test_a_run_folder_of_cellsim_0_1_without_the_marker_is_still_cellsim_s(tmp_path):
    """Folders written before the marker existed carry cellsim's manifest.json: a rerun may
    replace them; a folder whose manifest.json is anything else stays refused."""
    old = tmp_path / "old_run"
    old.mkdir()
    (old / "manifest.json").write_text('{"cellsim": "0.1.0", "scenario_sha256": "ab"}\n')
    (old / "summary.json").write_text("{}\n")
    assert is_run_folder(old)
    assert main([*RUN, "--out", str(old)]) == 0 and (old / MARKER).is_file()
    other = _user_folder(tmp_path / "other")
    (other / "manifest.json").write_text('{"name": "my web app"}\n')
    assert not is_run_folder(other)
    with pytest.raises(RunFolderError, match="not written by cellsim"):
        check_out_dir(other)

"""Sweeps at scale (issue 16): metrics-only variants, Ray as the distributed engine.

A metrics-only variant writes nothing of its own and gives the same table as a variant whose
run folder is kept; Ray and the process pool give the same table, bit for bit.
"""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from sim.cli import main

SCENARIO = "bugnar_5r_phase1"  # 10 s of 5R motion, about a second per variant


def _table(folder: Path) -> list[dict[str, str]]:
    with open(folder / "sweep.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _sweep(out: Path, *extra: str) -> list[dict[str, str]]:
    assert main(["size", SCENARIO, "--payload", "0,3", "--speed-scale", "1,2", "--out",
                 str(out), "--quiet", *extra]) == 0
    return _table(out)


@pytest.mark.slow
def test_metrics_only_variants_write_nothing_and_match_kept_runs(tmp_path, capsys):
    metrics = _sweep(tmp_path / "metrics", "--workers", "1")
    kept = _sweep(tmp_path / "kept", "--workers", "1", "--keep-runs")
    # the sweep folder holds the sweep's files and its marker, nothing per variant
    assert sorted(p.name for p in (tmp_path / "metrics").iterdir()) == [
        ".cellsim-files", ".cellsim-run", "sweep.csv", "sweep.json", "sweep.md", "sweep.svg"]
    assert all(r["run_dir"] == "" for r in metrics)
    kept_dirs = {r["run_dir"] for r in kept}
    assert len(kept_dirs) == 4 and all((Path(d) / "trajectory.npz").is_file() for d in kept_dirs)
    # the same numbers whether computed in memory or read back from the written run folders
    assert len(metrics) == len(kept) == 4 * 5
    for a, b in zip(metrics, kept):
        assert {k: v for k, v in a.items() if k != "run_dir"} == \
               {k: v for k, v in b.items() if k != "run_dir"}
    # and a heavier payload costs j2 more torque: the table says something
    j2 = {(float(r["payload_kg"]), float(r["speed_scale"])): float(r["peak_torque_nm"])
          for r in metrics if r["joint"] == "j2"}
    assert j2[(3.0, 1.0)] > j2[(0.0, 1.0)]


@pytest.mark.slow
def test_ray_and_pool_give_identical_tables(tmp_path, capsys):
    """Nine variants on a local Ray instance and on the process pool: the same sweep.csv, byte
    for byte (every number printed with full precision)."""
    pytest.importorskip("ray", reason="Ray is not installed (pip install 'cellsim[ray]')")
    args = ["size", SCENARIO, "--payload", "0,1.5,3", "--speed-scale", "0.5,1,1.5", "--quiet",
            "--workers", "2"]
    assert main([*args, "--out", str(tmp_path / "pool")]) == 0
    assert main([*args, "--out", str(tmp_path / "ray"), "--engine", "ray"]) == 0
    pool = (tmp_path / "pool" / "sweep.csv").read_bytes()
    ray = (tmp_path / "ray" / "sweep.csv").read_bytes()
    assert pool == ray
    assert len(_table(tmp_path / "ray")) == 9 * 5


@pytest.mark.parametrize("args, words", [
    (["--address", "auto"], "--address is for --engine ray"),
    (["--plots"], "give --keep-runs too"),
])
def test_engine_options_are_checked(tmp_path, capsys, args, words):
    rc = main(["size", SCENARIO, "--out", str(tmp_path / "s"), "--quiet", *args])
    err = capsys.readouterr().err
    assert rc == 2 and words in err, err
    assert not (tmp_path / "s").exists()


def test_an_unknown_engine_lists_the_valid_ones(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["size", SCENARIO, "--out", str(tmp_path / "s"), "--engine", "spark"])
    assert info.value.code == 2
    assert "invalid choice: 'spark' (choose from 'pool', 'ray')" in capsys.readouterr().err


def test_an_unreachable_ray_cluster_is_one_line(tmp_path, capsys):
    pytest.importorskip("ray", reason="Ray is not installed (pip install 'cellsim[ray]')")
    rc = main(["size", SCENARIO, "--out", str(tmp_path / "s"), "--quiet", "--engine", "ray",
               "--address", "127.0.0.1:1"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "cannot connect to Ray" in err, err
    assert not (tmp_path / "s").exists()  # refused before the sweep folder was made


def test_warp_backend_options_are_checked(tmp_path, capsys):
    path = SCENARIO
    for extra, words in ((["--engine", "ray"], "without --engine ray"),
                         (["--keep-runs"], "--keep-runs is for --backend mujoco")):
        rc = main(["size", str(path), "--out", str(tmp_path / "s"), "--quiet", "--backend",
                   "warp", *extra])
        err = capsys.readouterr().err
        assert rc == 2 and words in err, err
    assert not (tmp_path / "s").exists()

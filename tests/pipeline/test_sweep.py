"""Tests of sim.pipeline.sweep with fake module-level runners (picklable) whose torques are known in
closed form: peak = payload * g * L + k * s^2 (gravity of the payload on a lever L plus an
inertial part that grows with the square of the speed scale s)."""

from __future__ import annotations

import csv
import json
import math
import multiprocessing
import os
import time
from pathlib import Path

import numpy as np
import pytest
from support.window_oracle import sustained_peak

from sim.analysis.sizing import PEAK_WINDOW_S
from sim.cli.size import parse_float_list
from sim.errors import CellsimError, CellsimWarning, UnknownNameError
from sim.pipeline.sweep import (
    SWEEP_COLUMNS,
    SweepError,
    Variant,
    make_variants,
    run_sweep,
    validate_speed_scales,
)

G, L, K = 9.81, 0.5, 3.0
BASE_DURATION = 2.0
JOINTS = ["j1", "j2"]


def expected_peak(payload: float, scale: float) -> float:
    return payload * G * L + K * scale**2


def fake_runner(variant: Variant) -> Path:
    """j1 holds the torque constant; j2 swings it as a sine over one whole period."""
    run_dir = Path(variant.run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    T = BASE_DURATION / variant.speed_scale  # knot times divided by the scale
    t = np.linspace(0.0, T, 401)  # t[100] = T/4: the crest is sampled
    a = expected_peak(variant.payload_kg, variant.speed_scale)
    tau = np.stack([np.full_like(t, a), a * np.sin(2 * np.pi * t / T)], axis=1)
    qd = np.stack([np.full_like(t, 0.1), np.cos(2 * np.pi * t / T)], axis=1) * variant.speed_scale
    np.savez(run_dir / "trajectory.npz", t=t, q_ref=0 * tau, qd_ref=qd, qdd_ref=0 * tau, q=0 * tau,
             qd=qd, tau=tau, tau_id=0.99 * tau)
    (run_dir / "summary.json").write_text(json.dumps(
        {"scenario": str(variant.scenario), "joints": JOINTS, "pid": os.getpid()}))
    if multiprocessing.parent_process() is not None:
        time.sleep(0.25)  # in a worker: long enough for the pool to hand work to every worker
    return run_dir


def failing_runner(variant: Variant) -> Path:
    """Fails for the 5 kg variants with an exception whose pickling is awkward."""
    if variant.payload_kg == 5.0:
        raise UnknownNameError("tool", "torch9", ["mig_torch"])
    return fake_runner(variant)


def sizing_runner(variant: Variant) -> Path:
    """Also writes a sizing.json, as the real runner does."""
    run_dir = fake_runner(variant)
    margin = 100.0 - expected_peak(variant.payload_kg, variant.speed_scale)
    (run_dir / "sizing.json").write_text(json.dumps({"joints": [
        {"joint": j, "pass": margin >= 0, "margin_pct": margin, "limiting": "joint_torque"}
        for j in JOINTS]}))
    return run_dir


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


PAYLOADS = [0.0, 2.5, 5.0]
SCALES = [0.5, 1.0, 2.0]


def test_sweep_table_matches_closed_form(tmp_path) -> None:
    res = run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=1, out_dir=tmp_path,
                    progress=False)
    rows = read_csv(tmp_path / "sweep.csv")
    assert tuple(rows[0].keys()) == SWEEP_COLUMNS
    assert len(rows) == len(PAYLOADS) * len(SCALES) * len(JOINTS)
    seen = set()
    for r in rows:
        p, s = float(r["payload_kg"]), float(r["speed_scale"])
        seen.add((p, s))
        a = expected_peak(p, s)
        # the simulated peak is sustained over PEAK_WINDOW_S: the constant's is a, the sine's
        # its crest averaged over the window (window_oracle, on fake_runner's samples)
        T = BASE_DURATION / s
        t = np.linspace(0.0, T, 401)
        sim = a if r["joint"] == "j1" else sustained_peak(t, a * np.sin(2 * np.pi * t / T),
                                                          PEAK_WINDOW_S)
        assert float(r["peak_torque_sim_nm"]) == pytest.approx(sim, rel=1e-9)
        assert float(r["peak_torque_nm"]) == pytest.approx(max(sim, 0.99 * a), rel=1e-9)
        assert float(r["peak_torque_id_nm"]) == pytest.approx(0.99 * a, rel=1e-12)
        # RMS: constant -> a; sine over one whole period -> a / sqrt(2)
        rms = a if r["joint"] == "j1" else a / math.sqrt(2)
        assert float(r["rms_torque_nm"]) == pytest.approx(rms, rel=1e-9)
        assert float(r["duration_s"]) == pytest.approx(BASE_DURATION / s)
        assert Path(r["run_dir"]).is_dir()
    assert seen == {(p, s) for p in PAYLOADS for s in SCALES}
    assert res.failures == []
    md = (tmp_path / "sweep.md").read_text()
    assert "Peak |torque|" in md and "RMS torque" in md and "sweep.svg" in md
    # pivot cell: 5 kg at speed x2, joint j1
    assert f"| 5 | 2 | - | {expected_peak(5, 2):.4g} |" in md  # no verdict: "-"
    assert (tmp_path / "sweep.svg").read_text().startswith("<svg ")
    data = json.loads((tmp_path / "sweep.json").read_text())
    assert len(data["variants"]) == 9


def test_parallel_equals_serial(tmp_path) -> None:
    serial = run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=1,
                       out_dir=tmp_path / "serial", progress=False)
    parallel = run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=2,
                         out_dir=tmp_path / "parallel", progress=False)
    assert parallel.workers == 2

    def strip(rows):  # NaN (no sizing.json) compared as equal through its repr
        return [{k: repr(v) for k, v in r.items() if k != "run_dir"} for r in rows]

    assert strip(parallel.rows) == strip(serial.rows)  # same values, same order
    a = [{k: v for k, v in r.items() if k != "run_dir"}
         for r in read_csv(tmp_path / "serial" / "sweep.csv")]
    b = [{k: v for k, v in r.items() if k != "run_dir"}
         for r in read_csv(tmp_path / "parallel" / "sweep.csv")]
    assert a == b
    pids = {json.loads((Path(o.run_dir) / "summary.json").read_text())["pid"]
            for o in parallel.outcomes}
    assert os.getpid() not in pids and len(pids) == 2  # really ran in two worker processes
    # let go once the last variant was in (they exit while the report is written), the
    # workers are joined before run_sweep returns: none is left running
    assert multiprocessing.active_children() == []
    for pid in pids:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


@pytest.mark.parametrize("workers", [1, 2])
def test_failed_variants_reported_after_writing_the_others(tmp_path, workers: int) -> None:
    with pytest.raises(SweepError) as err:
        run_sweep("weld_demo", [0.0, 5.0], [1.0, 2.0], failing_runner, workers=workers,
                  out_dir=tmp_path, progress=False)
    msg = str(err.value)
    assert "2 of 4 sweep variants failed" in msg and "payload 5 kg" in msg and "torch9" in msg
    assert "\n" not in msg
    rows = read_csv(tmp_path / "sweep.csv")
    assert {float(r["payload_kg"]) for r in rows} == {0.0}
    assert "Failed variants" in (tmp_path / "sweep.md").read_text()


def test_margins_copied_from_sizing_json(tmp_path) -> None:
    run_sweep("s", [0.0, 20.0], [1.0], sizing_runner, workers=1, out_dir=tmp_path, progress=False)
    rows = {(float(r["payload_kg"]), r["joint"]): r for r in read_csv(tmp_path / "sweep.csv")}
    assert rows[(0.0, "j1")]["pass"] == "PASS"
    assert float(rows[(20.0, "j1")]["margin_pct"]) == pytest.approx(100 - expected_peak(20, 1))
    assert rows[(20.0, "j1")]["pass"] == "FAIL"
    assert "Sizing margin" in (tmp_path / "sweep.md").read_text()


@pytest.mark.parametrize("payloads, scales, field", [
    ([-1.0], [1.0], "payload"),
    ([0.0, float("nan")], [1.0], "payload"),
    ([], [1.0], "payload"),
    ([0.0], [0.0], "speed scale"),
    ([0.0], [-0.5], "speed scale"),
    ([0.0], [float("inf")], "speed scale"),
    ([0.0], [], "speed scale"),
])
def test_bad_sweep_inputs_are_one_line_errors(tmp_path, payloads, scales, field) -> None:
    with pytest.raises(CellsimError) as err:
        run_sweep("s", payloads, scales, fake_runner, workers=1, out_dir=tmp_path, progress=False)
    assert str(err.value).startswith(field) and "\n" not in str(err.value)
    assert not (tmp_path / "sweep.csv").exists()


@pytest.mark.parametrize("workers", [0, -2, 1.5, True])
def test_bad_workers(tmp_path, workers) -> None:
    with pytest.raises(SweepError, match="workers"):
        run_sweep("s", [0.0], [1.0], fake_runner, workers=workers, out_dir=tmp_path)


def test_variants_are_every_combination_payload_major(tmp_path) -> None:
    with pytest.warns(CellsimWarning, match="payload: 2.5 given more than once"):
        vs = make_variants("base", [0, 2.5, 2.5], [1, 0.5], tmp_path)
    assert [(v.payload_kg, v.speed_scale) for v in vs] == [(0, 1), (0, 0.5), (2.5, 1), (2.5, 0.5)]
    assert [v.index for v in vs] == [0, 1, 2, 3]
    assert len({v.run_dir for v in vs}) == 4 and all(v.scenario == "base" for v in vs)
    assert vs[2].slug == "payload_2.5kg_speed_1x"


def test_parse_float_list() -> None:
    assert parse_float_list("0,2.5,5", field="--payload") == [0.0, 2.5, 5.0]
    assert parse_float_list(" 1 , 0.5 ", field="--speed") == [1.0, 0.5]
    assert parse_float_list("0:10:2.5", field="--payload") == [0.0, 2.5, 5.0, 7.5, 10.0]
    assert parse_float_list("0.5:1.1:0.2,2", field="--speed") == pytest.approx([0.5, 0.7, 0.9, 1.1, 2])
    assert parse_float_list("1,1,2", field="--speed") == [1.0, 1.0, 2.0]
    with pytest.warns(CellsimWarning, match=r"--speed: 1 given more than once; each variant "
                      "runs once"):  # dropped, not silently (a new-user trial)
        assert validate_speed_scales(parse_float_list("1,1,2", field="--speed"),
                                     field="--speed") == [1.0, 2.0]


@pytest.mark.parametrize("text, fragment", [
    ("", "empty list"),
    ("1,,2", "empty item"),
    ("0,abc", "'abc' is not a number"),
    ("nan", "not a finite number"),
    ("1:0:1", "stop < start"),
    ("0:1:0", "positive step"),
    ("0:1", "start:stop:step"),
])
def test_parse_float_list_errors(text: str, fragment: str) -> None:
    with pytest.raises(SweepError) as err:
        parse_float_list(text, field="--payload")
    assert str(err.value).startswith("--payload:") and fragment in str(err.value)


# ---------------------------------------------------------------- nothing lost (issue 31)
def all_failing_runner(variant: Variant) -> Path:
    raise UnknownNameError("tool", "torch9", ["mig_torch"])


def interrupted_runner(variant: Variant) -> Path:
    if variant.index == 1:
        raise KeyboardInterrupt
    return fake_runner(variant)


def test_variants_whose_values_print_alike_get_their_own_run_folders(tmp_path) -> None:
    """1.0000001 and 1.0000002 kg both print as 1: each variant keeps its own run folder
    (the second silently replaced the first), named with its exact digits."""
    res = run_sweep("weld_demo", [1.0000001, 1.0000002], [1.0], fake_runner, workers=1,
                    out_dir=tmp_path / "sw", progress=False)
    dirs = [Path(o.run_dir) for o in res.outcomes]
    assert len(set(dirs)) == 2 and all(d.is_dir() and d.parent == tmp_path / "sw" for d in dirs)
    assert {d.name for d in dirs} == {"payload_1.0000001kg_speed_1.0x",
                                      "payload_1.0000002kg_speed_1.0x"}
    rows = read_csv(tmp_path / "sw" / "sweep.csv")
    assert {r["run_dir"] for r in rows} == {str(d) for d in dirs}
    # and sweep.md's tables keep them two rows that read apart (both read "| 1 | 1 |" once)
    md = (tmp_path / "sw" / "sweep.md").read_text()
    assert "| 1.0000001 | 1 |" in md and "| 1.0000002 | 1 |" in md


def test_a_second_sweep_into_a_busy_folder_refuses(tmp_path) -> None:
    """While a sweep (or run) holds the folder, another sweep into it refuses in one line
    instead of both succeeding with one table lost."""
    from sim.errors import RunFolderError
    from sim.simulation.runfolder import RunLock

    out = tmp_path / "sw"
    with RunLock(out), pytest.raises(RunFolderError, match="being written by another"):
        run_sweep("weld_demo", [0.0], [1.0], fake_runner, workers=1, out_dir=out,
                  progress=False)
    assert not out.exists()


def test_a_sweep_whose_every_variant_failed_leaves_the_previous_table(tmp_path) -> None:
    """A good sweep, then one whose every variant fails into the same folder: the good table
    and run folders are as they were, the failed sweep's report is in <out>.failed."""
    out = tmp_path / "sw"
    run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=1, out_dir=out,
              progress=False)
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    with pytest.raises(SweepError, match="every variant failed: the previous .* is as it was"):
        run_sweep("weld_demo", PAYLOADS, SCALES, all_failing_runner, workers=1, out_dir=out,
                  progress=False)
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before
    failed = tmp_path / "sw.failed"
    assert "torch9" in (failed / "sweep.md").read_text()
    # a later good sweep into the place: the failed report, cellsim's and now stale, goes (a
    # new-user trial found it left next to the new table); a folder of the user's by that name
    # is never touched
    run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=1, out_dir=out,
              progress=False)
    assert not failed.exists() and (out / "sweep.csv").is_file()
    failed.mkdir()
    (failed / "mine.txt").write_text("mine")
    run_sweep("weld_demo", PAYLOADS, SCALES, fake_runner, workers=1, out_dir=out,
              progress=False)
    assert (failed / "mine.txt").read_text() == "mine"


def test_an_interrupted_sweep_leaves_the_previous_folder_and_nothing_marked_complete(
        tmp_path) -> None:
    """A sweep stopped mid-way (here by an interrupt in its second variant) leaves the
    previous folder as it was and no hidden folder behind; one killed outright leaves its
    hidden folder marked "writing" (never read as a result), which the next sweep removes."""
    import shutil

    from sim.simulation.runfolder import marker_state, write_marker

    out = tmp_path / "sw"
    run_sweep("weld_demo", [0.0], [1.0], fake_runner, workers=1, out_dir=out, progress=False)
    table = (out / "sweep.csv").read_bytes()
    with pytest.raises(KeyboardInterrupt):
        run_sweep("weld_demo", PAYLOADS, SCALES, interrupted_runner, workers=1, out_dir=out,
                  progress=False)
    assert (out / "sweep.csv").read_bytes() == table and marker_state(out) == "complete"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".sw.") and p.is_dir()]
    # what SIGKILL leaves: a hidden sibling marked "writing"
    killed = tmp_path / ".sw.abcd1234"
    killed.mkdir()
    write_marker(killed, state="writing")
    shutil.copytree(out / "payload_0kg_speed_1x", killed / "payload_0kg_speed_1x")
    run_sweep("weld_demo", [0.0], [1.0], fake_runner, workers=1, out_dir=out, progress=False)
    assert not killed.exists() and marker_state(out) == "complete"


def test_a_variant_whose_verdict_fails_says_why_in_the_table_and_the_report(tmp_path,
                                                                            capsys):
    """The pick-and-place gripper is rated 2.04 kg: with a 2.5 kg payload (and the 0.25 kg
    part it carries) the variant is simulated and sized, its verdict fails, and both
    ``sweep.csv`` (``failed_checks``) and ``sweep.md`` (a verdict column and a section) say
    why; the 0 kg variant passes. (Found by a new-user trial: only the CSV's ``verdict``
    column said fail, and no file said why; every margin in sweep.md was positive.)"""
    from sim.cli import main

    assert main(["size", "lrmate200ic_pick_place", "--payload", "0,2.5", "--workers", "1",
                 "--quiet", "--out", str(tmp_path / "s")]) == 0  # a result, not an error
    out = capsys.readouterr().out
    rows = read_csv(tmp_path / "s" / "sweep.csv")
    by_payload = {float(r["payload_kg"]): r for r in rows}
    assert by_payload[0.0]["verdict"] == "pass" and by_payload[0.0]["failed_checks"] == ""
    why = by_payload[2.5]["failed_checks"]
    assert by_payload[2.5]["verdict"] == "fail"
    assert why.startswith("tool_payload: the vacuum_gripper holds 2.75 kg, rated 2.04 kg"), why
    md = (tmp_path / "s" / "sweep.md").read_text()
    assert "2 variants (2 succeeded, 1 of them with a failed verdict)" in md
    assert "| 2.5 | 1 | fail |" in md and "| 0 | 1 | pass |" in md
    assert f"- payload 2.5 kg, speed x1: {why}" in md
    assert f"  verdict fail, payload 2.5 kg, speed x1: {why}" in out.splitlines()  # console
    assert "payload 0 kg" not in out
    # --strict: a CI job's gate, 1 when a variant's verdict failed, 0 when none did
    assert main(["size", "lrmate200ic_pick_place", "--payload", "0,2.5", "--workers", "1",
                 "--quiet", "--strict", "--out", str(tmp_path / "s")]) == 1
    assert main(["size", "lrmate200ic_pick_place", "--payload", "0", "--workers", "1",
                 "--quiet", "--strict", "--out", str(tmp_path / "s")]) == 0

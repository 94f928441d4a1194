"""A script that passes an argument of the wrong kind gets one line from cellsim's exception
tree naming the argument, before anything runs.

A new-user trial found ``sim.load_scenario(42)``, ``sim.evaluate(3)``, ``sim.run(sc, out_dir=5)``,
``sim.RunResult.load(5)`` and ``scaled(payload_kg="2")`` raising a ``TypeError`` from deep
inside, ``sim.run(sc, foo=1)`` a ``TypeError`` from a dataclass, ``video_args=[1, 2]`` an
``AttributeError`` once simulated, and ``RunOptions(feedforward="no")`` or
``scaled(payload_kg=True)`` taken (the text "no" is true). Specification, on generated values
of every other kind for each argument: a :class:`sim.CellsimError` (never a bare TypeError,
AttributeError or ValueError), one line, naming the argument (its ``key`` is the argument);
the right kinds are still taken. Nothing is simulated: each refusal comes before the run.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sim
from sim.core.arguments import flag_argument, number_argument, path_argument

SCENARIO = "kacso_lrmate100ib_sequence1"

#: Values of every kind a script might pass by mistake.
ANY = st.one_of(
    st.none(), st.booleans(), st.integers(-10, 10), st.floats(allow_nan=True),
    st.text(max_size=8), st.binary(max_size=4), st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.just(object()), st.just(np.float64(1.5)), st.just(Path("x")))


@pytest.fixture(scope="module")
def base():
    return sim.load_scenario(SCENARIO)


def _refused(call, name: str) -> sim.CellsimError:
    with pytest.raises(sim.CellsimError) as exc:
        call()
    err = exc.value
    assert "\n" not in str(err) and name in str(err), str(err)
    return err


def _not_a_path(v) -> bool:
    return not isinstance(v, (str, Path)) or not str(v).strip()


@settings(max_examples=40, deadline=None)
@given(value=ANY.filter(_not_a_path))
def test_a_scenario_that_is_not_a_path_or_a_name(value):
    err = _refused(lambda: sim.load_scenario(value), "scenario")
    assert err.key == "scenario"
    _refused(lambda: sim.evaluate(value), "scenario")


@settings(max_examples=40, deadline=None)
@given(value=ANY.filter(lambda v: isinstance(v, bool) or not isinstance(v, (int, float))))
def test_scaled_takes_numbers_only(value, base):
    if value is not None:  # None: the scenario's own payload
        assert _refused(lambda: base.scaled(payload_kg=value), "payload_kg").key == "payload_kg"
    assert _refused(lambda: base.scaled(speed_scale=value), "speed_scale").key == "speed_scale"


@pytest.mark.parametrize("kg", [0, 2, 2.5, np.float32(1.25), np.int64(3)])
def test_scaled_takes_every_kind_of_number(kg, base):
    assert base.scaled(payload_kg=kg).payload_kg == pytest.approx(float(kg))


@pytest.mark.parametrize("value, name", [(-1, "payload_kg"), (math.nan, "payload_kg"),
                                         (1e9, "payload_kg")])
def test_scaled_out_of_range_names_the_argument(value, name, base):
    assert _refused(lambda: base.scaled(payload_kg=value), name).key == name


@settings(max_examples=40, deadline=None)
@given(field=st.sampled_from(["video", "plots", "sizing", "progress", "csv", "feedforward"]),
       value=ANY.filter(lambda v: not isinstance(v, (bool, np.bool_)) and v is not None))
def test_run_options_flags_are_true_or_false(field, value):
    err = _refused(lambda: sim.RunOptions(**{field: value}), f"RunOptions.{field}")
    assert isinstance(err, sim.CellsimError)


def test_run_options_of_the_right_kinds_are_taken():
    o = sim.RunOptions(video=False, feedforward=None, out_dir="runs/x", plots=np.bool_(False),
                       video_args={"fps": 10, "width": None}, backend="mujoco")
    assert o.video is False and o.video_args["fps"] == 10


@settings(max_examples=30, deadline=None)
@given(value=ANY.filter(lambda v: not isinstance(v, dict) or (v and "" not in v)))
def test_video_args_is_a_mapping_of_video_settings(value):
    _refused(lambda: sim.RunOptions(video_args=value), "RunOptions.video_args")


def test_an_unknown_video_setting_is_named_with_the_known_ones():
    err = _refused(lambda: sim.RunOptions(video_args={"fsp": 5}), "'fsp'")
    assert "fps" in str(err) and "width" in str(err)


@settings(max_examples=30, deadline=None)
@given(value=ANY.filter(lambda v: v is not None and _not_a_path(v)))
def test_out_dir_is_a_path(value, base):
    _refused(lambda: sim.RunOptions(out_dir=value), "RunOptions.out_dir")
    _refused(lambda: sim.run(base, out_dir=value, video=False), "RunOptions.out_dir")
    _refused(lambda: sim.sweep(base, [0.0], out_dir=value), "out_dir")


def test_run_refuses_an_unknown_option_listing_the_known_ones(base, tmp_path):
    err = _refused(lambda: sim.run(base, foo=1), "foo")
    assert err.key == "foo" and "out_dir" in str(err) and "video" in str(err)
    assert list(tmp_path.iterdir()) == []


@settings(max_examples=30, deadline=None)
@given(value=ANY.filter(lambda v: v is not None))
def test_options_are_run_options(value, base):
    _refused(lambda: sim.evaluate(base, options=value), "options")
    _refused(lambda: sim.run(base, options=value), "options")


@settings(max_examples=30, deadline=None)
@given(value=ANY.filter(lambda v: isinstance(v, bool) or not isinstance(v, int) or v < 1))
def test_sweep_workers_is_a_whole_number(value, base):
    _refused(lambda: sim.sweep(base, [0.0], workers=value, out_dir="never"), "workers")
    assert not Path("never").exists()


@pytest.mark.parametrize("kw, name", [({"engine": "foo"}, "engine"),
                                      ({"backend": "cuda"}, "backend"),
                                      ({"keep_runs": "no"}, "keep_runs"),
                                      ({"select": 1}, "select")])
def test_sweep_choices_and_flags(kw, name, base):
    _refused(lambda: sim.sweep(base, [0.0], out_dir="never", **kw), name)
    assert not Path("never").exists()


@settings(max_examples=30, deadline=None)
@given(value=ANY.filter(_not_a_path))
def test_a_run_folder_is_a_path(value):
    err = _refused(lambda: sim.RunResult.load(value), "path")
    assert isinstance(err, sim.RunFolderError) if hasattr(sim, "RunFolderError") else True


def test_a_missing_run_folder_names_it(tmp_path):
    err = _refused(lambda: sim.RunResult.load(tmp_path / "nope"), "nope")
    assert err.file == str(tmp_path / "nope")


def test_the_checks_give_back_the_value_of_its_kind():
    """The planted faults of the checks themselves: what they take and what they refuse."""
    assert path_argument("a/b", "p") == Path("a/b") and path_argument(Path("c"), "p") == Path("c")
    assert number_argument(np.int32(3), "n") == 3.0 and isinstance(number_argument(2, "n"), float)
    assert flag_argument(np.bool_(True), "f") is True and flag_argument(None, "f", optional=True) \
        is None
    for bad in (True, "1", None, [1]):
        with pytest.raises(sim.CellsimError):
            number_argument(bad, "n")
    for bad in ("no", 0, 1, None):
        with pytest.raises(sim.CellsimError):
            flag_argument(bad, "f")

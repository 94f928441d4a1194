"""The house rules: layers import downwards only, one exception root, one registry type."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import planners
import sim
from planners.errors import CellsimError
from planners.registry import PLANNERS, Registry
from sim.cells import CELLS
from sim.cells.tools import TOOLS
from sim.core.resources import shipped_scenarios
from sim.layers import LAYERS, ROOT_EXPORTS, layer_of
from sim.robots.registry import ROBOTS

ROOT = Path(__file__).resolve().parents[2]


def _modules() -> list[tuple[str, Path]]:
    out = []
    for package in ("planners", "sim"):
        for path in sorted((ROOT / package).rglob("*.py")):
            rel = path.relative_to(ROOT).with_suffix("")
            parts = list(rel.parts)
            if parts[-1] == "__init__":
                parts.pop()
            out.append((".".join(parts), path))
    return out


MODULES = _modules()
MODULE_NAMES = {m for m, _ in MODULES}


def _imports(module: str, path: Path) -> list[tuple[int, str]]:
    """Every cellsim module ``module`` imports (also inside functions and TYPE_CHECKING)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            # "from sim.render import gl" imports the module sim.render.gl (the package's
            # __init__ runs first as for any submodule, no arrow of its own); a name that is
            # no module ("from sim.render.gl import configure_gl") is the module's
            subs = [f"{name}.{a.name}" for a in node.names if f"{name}.{a.name}" in MODULE_NAMES]
            if len(subs) < len(node.names):
                found.append((node.lineno, name))
            found += [(node.lineno, sub) for sub in subs]
    return [(ln, n) for ln, n in found if n.split(".")[0] in ("sim", "planners")]


def test_every_module_has_a_layer():
    for module, _ in MODULES:
        layer_of(module)  # raises for a module no layer claims


@pytest.mark.parametrize("module,path", MODULES, ids=[m for m, _ in MODULES])
def test_no_module_imports_a_higher_layer(module, path):
    own = layer_of(module)
    for line, name in _imports(module, path):
        if module == "sim" and any(name == e or name.startswith(e + ".")
                                   for e in ROOT_EXPORTS):
            continue  # the package root re-exports the API (lazily) and the exceptions
        other = layer_of(name)
        assert other <= own, (
            f"{path.relative_to(ROOT)}:{line}: {module} (layer {LAYERS[own][0]}) imports "
            f"{name} (layer {LAYERS[other][0]}, higher)")


def test_the_layer_check_catches_an_upward_import(tmp_path):
    """The checker itself: a robots module importing the pipeline is reported."""
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from sim.pipeline.run import run_scenario\n")
    names = [n for _, n in _imports("sim.robots.bad", bad)]
    assert "sim.pipeline.run" in names
    assert layer_of("sim.pipeline.run") > layer_of("sim.robots.bad")


def test_sim_top_level_keeps_at_most_four_modules():
    top = [p.name for p in (ROOT / "sim").glob("*.py")]
    assert len(top) <= 4, top


def test_every_sim_package_says_what_it_owns():
    for init in (ROOT / "sim").glob("*/__init__.py"):
        doc = ast.get_docstring(ast.parse(init.read_text()))
        assert doc and "import" in doc.lower(), f"{init.relative_to(ROOT)} lacks a layer docstring"


def _all_classes() -> list[type]:
    classes = []
    for package in (planners, sim):
        names = [package.__name__] + [m.name for m in pkgutil.walk_packages(
            package.__path__, package.__name__ + ".")]
        for name in names:
            if name == "sim.__main__":
                continue  # running it would start the command line
            mod = importlib.import_module(name)  # a broken module fails here, loudly
            classes += [obj for _, obj in inspect.getmembers(mod, inspect.isclass)
                        if obj.__module__ == name]
    return classes


def test_every_exception_derives_from_the_root():
    classes = _all_classes()
    exceptions = [c for c in classes if issubclass(c, BaseException)]
    assert len(exceptions) >= 20  # the walk found the tree, not an empty list
    stray = [f"{c.__module__}.{c.__qualname__}" for c in exceptions
             if not issubclass(c, CellsimError)]
    assert not stray, f"exceptions outside the CellsimError tree: {stray}"


def test_warnings_are_cellsim_errors_too():
    """A script that turns warnings into errors catches cellsim's with its one except clause,
    and a plain warnings filter on UserWarning silences them."""
    from sim.errors import SingularityWarning

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(CellsimError):
            warnings.warn("x", SingularityWarning, stacklevel=1)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", category=UserWarning)
        warnings.warn("x", SingularityWarning, stacklevel=1)
    assert seen == []


@pytest.mark.parametrize("registry", [ROBOTS, TOOLS, CELLS, PLANNERS, shipped_scenarios()],
                         ids=["robots", "tools", "cells", "planners", "scenarios"])
def test_every_registry_is_the_one_type_and_suggests_names(registry):
    from sim.errors import UnknownNameError

    assert isinstance(registry, Registry)
    name = registry.names()[0]
    assert registry.get(name) is registry[name]
    with pytest.raises(UnknownNameError) as info:
        registry.get(name + "x")
    msg = str(info.value)
    assert f"did you mean {name!r}" in msg and "\n" not in msg
    for n in registry.names():
        assert n in msg


def test_registry_refuses_a_name_twice():
    from sim.errors import InternalError

    r: Registry[int] = Registry("thing")
    r.add("a", 1)
    with pytest.raises(InternalError):
        r.add("a", 2)


@pytest.mark.parametrize("planner", PLANNERS.names())
def test_every_registered_planner_plans_a_scenario_and_a_wrong_name_lists_them(planner):
    """A scenario takes each planner the registry holds (planned here, end knots reached), and
    a name the registry lacks is refused naming every name it holds."""
    from sim.errors import ScenarioError
    from sim.scenario import parse_scenario, plan_scenario

    text = (ROOT / "scenarios" / "bugnar_5r_phase1.toml").read_text()
    assert 'planner = "434"' in text
    scenario = parse_scenario(text.replace('planner = "434"', f'planner = "{planner}"'))
    plan = plan_scenario(scenario)[0]
    phase = scenario.phases[0]
    for t, q in zip(phase.times, phase.q, strict=True):  # every knot, from the file's numbers
        assert np.allclose(plan.trajectory.at(t).q, q, atol=1e-9)
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text.replace('planner = "434"', f'planner = "{planner}x"'))
    assert all(repr(n) in str(info.value) for n in PLANNERS.names()), str(info.value)


def test_no_string_tests_on_the_kinematic_family():
    """A family is an object: nothing compares it (or its name) with a string."""
    for module, path in MODULES:
        text = path.read_text()
        for needle in ('family == "', 'family != "', "family == '", 'family.name == "',
                       'family.name != "', 'family in ("'):
            assert needle not in text, f"{path.relative_to(ROOT)}: {needle}"


def test_cli_exit_codes_separate_user_mistakes_from_internal_faults(monkeypatch, capsys):
    """A user mistake is one line and exit 2; an internal fault prints its traceback, exit 3."""
    import sim.cli.list as list_command
    from sim.cli import main
    from sim.errors import InternalError, ScenarioError

    def mistake(args):
        raise ScenarioError("x.toml: phases[0].time_s: knot times must increase")

    def fault(args):
        raise InternalError("closed-form tcp and MuJoCo tcp differ")

    monkeypatch.setattr(list_command, "run", mistake)
    assert main(["list"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "cellsim: error: x.toml: phases[0].time_s: knot times must increase"
    monkeypatch.setattr(list_command, "run", fault)
    assert main(["list"]) == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and "internal error" in err and "report" in err


@pytest.mark.parametrize("exc", [ValueError("could not convert string to float: 'x'"),
                                 ZeroDivisionError("float division by zero"),
                                 OverflowError("cannot convert float infinity to integer"),
                                 KeyError("phases"), FileNotFoundError(2, "gone"),
                                 OSError(5, "Input/output error")])
def test_any_exception_that_is_not_cellsims_is_an_internal_fault_never_exit_1(
        exc, monkeypatch, capsys):
    """Issue 31: an exception escaping cellsim's readers (a fault planted in a command) is
    exit 3 with its traceback and one line naming it, never exit 1, which a --strict run
    returns for a failed verdict; a disk error the OS reports for a path stays exit 2."""
    import sim.cli.list as list_command
    from sim.cli import main

    def planted(args):
        raise exc

    monkeypatch.setattr(list_command, "run", planted)
    code = main(["list"])
    err = capsys.readouterr().err
    if type(exc) is OSError:  # EIO: the place's error, one line with the path
        assert code == 2 and "Traceback" not in err
        return
    assert code == 3, err
    assert "Traceback" in err and f"internal error: {type(exc).__name__}" in err


# ---------------------------------------------------------------------- the house (issue 27)
def _import_graph() -> dict[str, set[str]]:
    """Module -> the cellsim modules it imports, at module level or inside functions (an
    import placed in a function to dodge a circle is still an arrow). The package root's
    exports are no arrow: it imports them on first use of a name, after every import is done
    (PEP 562), never while a module that imports ``sim`` is being imported."""
    graph: dict[str, set[str]] = {}
    for module, path in MODULES:
        targets = set()
        for _, name in _imports(module, path):
            if module == "sim" and any(name == e or name.startswith(e + ".")
                                       for e in ROOT_EXPORTS):
                continue
            while name and name not in MODULE_NAMES:  # "from sim.x import Name" -> sim.x
                name = name.rpartition(".")[0]
            if name and name != module:
                targets.add(name)
        graph[module] = targets
    return graph


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    import sys

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(graph)))
    try:
        for v in sorted(graph):
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return out


def test_no_import_circle_in_sim_or_planners():
    """A package's ``__init__`` re-exporting its modules is no circle unless one of those
    modules imports the package back."""
    circles = _circles(_import_graph())
    assert not circles, "import circles: " + "; ".join(" <-> ".join(c) for c in circles)


def test_the_circle_finder_finds_a_planted_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _circles(graph) == [["a", "b", "c"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


MAX_MODULE_LINES = 600


def test_no_module_is_over_600_lines():
    long = {m: n for m, p in MODULES if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES}
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"

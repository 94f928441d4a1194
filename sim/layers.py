"""The layer order of cellsim, declared once.

A module may import modules of its own layer and of the layers listed before it, never of a
layer listed after it (``tests/house/test_architecture.py`` checks every import, including
those inside functions). ``planners`` is the bottom layer and imports nothing from ``sim``.
"""

from __future__ import annotations

from sim.errors import UsageError

#: ``(layer, package or module prefixes)``, bottom first.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("planners", ("planners",)),
    ("base", ("sim.errors", "sim.layers", "sim.core")),
    ("robots", ("sim.robots",)),
    ("cells", ("sim.cells",)),
    ("scenario", ("sim.scenario",)),
    ("simulation", ("sim.simulation",)),
    ("analysis", ("sim.analysis",)),
    ("render", ("sim.render",)),
    ("pipeline", ("sim.pipeline",)),
    ("api", ("sim.api",)),
    ("cli", ("sim.cli", "sim.__main__")),
)

#: The package root: every layer may import it (version, MUJOCO_GL default); it imports only
#: what it exports (:data:`ROOT_EXPORTS`), lazily, on first use of a name.
ROOT = "sim"

#: The modules the package root re-exports from: the API layer and the exception tree.
ROOT_EXPORTS: tuple[str, ...] = ("sim.api", "sim.errors")


def layer_of(module: str) -> int:
    """Index in :data:`LAYERS` of a dotted module name of cellsim (-1 for the package root).

    Raises:
        ValueError: Not a cellsim module, or a module no layer claims.
    """
    if module == ROOT:
        return -1
    for index, (_, prefixes) in enumerate(LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return index
    raise UsageError(f"module {module!r} belongs to no layer of sim.layers.LAYERS")

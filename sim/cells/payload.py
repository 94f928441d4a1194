"""The payload at a robot's tool point: a lumped mass with the inertia of a solid steel sphere
of that mass, and the sphere drawn as its marker (:func:`sim.cells.compose.prepare_robot` adds
the body ``<robot>/payload``; :mod:`sim.simulation.build_cache` sets another payload in a kept
cell). Every cell has the body: at 0 kg it is massless and its marker invisible, so every
payload has one model structure. May import: numpy only.
"""

from __future__ import annotations

import numpy as np

#: Density of the payload's sphere, kg/m^3 (steel).
STEEL_DENSITY = 7850.0
#: The payload marker's colour (a translucent sphere at the tcp; invisible at 0 kg).
PAYLOAD_RGBA = (0.9, 0.8, 0.1, 0.35)
#: The marker's radius at 0 kg, m (MuJoCo needs a positive size; the marker is invisible).
EMPTY_MARKER_RADIUS_M = 0.001


def payload_radius(mass_kg: float) -> float:
    """Radius of a solid steel sphere of that mass, m (the payload's inertia model)."""
    return float((3.0 * mass_kg / (4.0 * np.pi * STEEL_DENSITY)) ** (1.0 / 3.0))


def payload_inertia(mass_kg: float) -> float:
    """Each principal moment of the payload's sphere (:func:`payload_radius`), kg m^2."""
    return 0.4 * mass_kg * payload_radius(mass_kg) ** 2


def payload_marker(mass_kg: float) -> tuple[float, tuple[float, float, float, float]]:
    """The payload marker sphere's radius (:func:`payload_radius`) and colour: at 0 kg a
    radius of :data:`EMPTY_MARKER_RADIUS_M` and a transparent colour. It touches nothing and
    carries no mass (the payload body's inertial is explicit)."""
    if mass_kg > 0.0:
        return payload_radius(mass_kg), PAYLOAD_RGBA
    return EMPTY_MARKER_RADIUS_M, (*PAYLOAD_RGBA[:3], 0.0)


__all__ = ["EMPTY_MARKER_RADIUS_M", "PAYLOAD_RGBA", "STEEL_DENSITY", "payload_inertia",
           "payload_marker", "payload_radius"]

"""Reach and workspace sections of the cellsim robots.

Reach (documented definition): the largest distance from the J1 axis, over every configuration
inside the joint ranges, of

* the wrist centre: 200iC the J4/J5/J6 intersection (seed 004, O4 = O5 = O6); 5R the J4/J5
  intersection (seed 000 Table 1, point (l1 + l2, 0, d1) at q = 0). For the 200iC/5L this is
  ``d2 + d3 + sqrt(R4^2 + d4^2) = 891.8 mm`` when the ranges allow it: FANUC's catalogue
  reach of 892 mm (seed 004 Table 2);
* the tcp (tool point, with the tool).

Sections (the picture ``cellsim workspace`` draws): for the 200iC, seed 004's map of the
(theta2, theta3) plane inside the joint ranges with the singular curves of eq. (24) (elbow,
``R4 c3 - d4 s3 = 0``) and eq. (25) (shoulder, wrist centre on the J1 axis), and the x-z
section (J1 = 0) of the wrist centre these angles reach, with the same curves mapped into it.
For the 5R robots the same pair: the (q2, q3) map with the elbow singularity ``cos q3 = 0`` and
the shoulder curve, and the x-z section of the wrist point and of the tcp (q4 swept).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize

from sim.robots.kinematics.model import KinematicModel


@dataclass(frozen=True)
class Reach:
    """Reach of a robot (see the module docstring), metres, and where it is attained.

    Attributes:
        wrist: Max distance of the wrist centre from the J1 axis, m.
        tcp: Max distance of the tcp from the J1 axis, m.
        q_wrist: A configuration attaining ``wrist``, rad, shape (n,).
        q_tcp: A configuration attaining ``tcp``, rad, shape (n,).
    """

    wrist: float
    tcp: float
    q_wrist: NDArray[np.float64]
    q_tcp: NDArray[np.float64]


def _bounds(model: KinematicModel) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    n = model.n_joints
    lo = np.full(n, -np.pi) if model.lower is None else np.maximum(model.lower, -2 * np.pi)
    hi = np.full(n, np.pi) if model.upper is None else np.minimum(model.upper, 2 * np.pi)
    return lo, hi


def wrist_points(model: KinematicModel, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Wrist centre(s) in frame 0, m, for q of shape (n,) or (N, n): (3,) or (N, 3)."""
    axes, points, _ = model.joint_frames(q)
    return points[..., model.family.wrist_centre_index, :]


def _maximize(f, lo: NDArray[np.float64], hi: NDArray[np.float64], n_grid: int
              ) -> tuple[float, NDArray[np.float64]]:
    """Max of a vectorized ``f`` over a box: grid search then bounded L-BFGS-B refinement."""
    grids = np.meshgrid(*[np.linspace(a, b, n_grid) for a, b in zip(lo, hi)], indexing="ij")
    X = np.stack([g.ravel() for g in grids], -1)
    vals = f(X)
    best = X[np.argsort(vals)[-5:]]
    results = []
    for x0 in best:
        res = minimize(lambda x: -f(x[None])[0], x0, method="L-BFGS-B",
                       bounds=list(zip(lo, hi)))
        results.append((-res.fun, res.x))
    results.append((float(vals.max()), X[np.argmax(vals)]))
    val, x = max(results, key=lambda r: r[0])
    return float(val), np.asarray(x)


def compute_reach(model: KinematicModel) -> Reach:
    """Reach of the wrist centre and of the tcp (module docstring), within the joint ranges."""
    lo, hi = _bounds(model)
    n = model.n_joints

    def full(x: NDArray[np.float64], free: list[int]) -> NDArray[np.float64]:
        Q = np.zeros((x.shape[0], n))
        Q[:, free] = x
        return Q

    def radial(P: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.hypot(P[:, 0], P[:, 1])

    arm = [1, 2]
    wr, xw = _maximize(lambda x: radial(wrist_points(model, full(x, arm))), lo[arm], hi[arm], 61)
    free = list(model.family.reach_free_joints)
    tc, xt = _maximize(lambda x: radial(model.fk(full(x, free))[:, :3, 3]), lo[free], hi[free],
                       21 if len(free) == 3 else 13)
    return Reach(wrist=wr, tcp=tc, q_wrist=full(xw[None], arm)[0], q_tcp=full(xt[None], free)[0])


#: The PNG's ``Software`` text: marks a picture ``cellsim workspace`` wrote (another run may
#: replace it; any other file at ``--out`` is refused).
PNG_SOFTWARE = "cellsim workspace"
#: The PNG's text naming the file it was written as (its absolute path): a picture copied or
#: moved elsewhere is the user's file there, not cellsim's.
PNG_WRITTEN_AS = "cellsim written as"


def written_by_workspace(path: str | Path) -> bool:
    """Whether ``path`` is a PNG that :func:`plot_workspace` wrote at this very place (its
    ``Software`` text and the absolute path it was written as)."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            return (im.format == "PNG" and im.info.get("Software") == PNG_SOFTWARE
                    and im.info.get(PNG_WRITTEN_AS) == str(Path(path).resolve()))
    except (OSError, UnidentifiedImageError, ValueError, SyntaxError):  # PIL: a broken PNG
        return False


def plot_workspace(model: KinematicModel, out: str | Path, title: str = "") -> Reach:
    """Draw the workspace section (module docstring) into a PNG; return the reach.

    Args:
        model: The robot's kinematic model (ranges used when known, else +-180 deg).
        out: PNG file to write.
        title: Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    reach = compute_reach(model)
    lo, hi = _bounds(model)
    n = model.n_joints
    g2 = np.linspace(lo[1], hi[1], 241)
    g3 = np.linspace(lo[2], hi[2], 241)
    T2, T3 = np.meshgrid(g2, g3, indexing="ij")
    Q = np.zeros((T2.size, n))
    Q[:, 1], Q[:, 2] = T2.ravel(), T3.ravel()
    W = wrist_points(model, Q)
    elbow, shoulder, elbow_label, shoulder_label = model.family.singular_curves(T2, T3)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 6))
    im = ax1.pcolormesh(np.rad2deg(g2), np.rad2deg(g3), 1e3 * shoulder.T, shading="auto",
                        cmap="viridis")
    fig.colorbar(im, ax=ax1, label="wrist centre distance from J1 axis (signed), mm")
    cs_elbow = ax1.contour(np.rad2deg(g2), np.rad2deg(g3), elbow.T, levels=[0.0],
                           colors="red", linewidths=2)
    cs_shoulder = ax1.contour(np.rad2deg(g2), np.rad2deg(g3), shoulder.T, levels=[0.0],
                              colors="white", linewidths=2, linestyles="--")
    ax1.plot([], [], "r-", label=elbow_label)
    ax1.plot([], [], "w--", label=shoulder_label)
    ax1.set_xlabel(f"{model.family.joint_symbol}2 (deg)")
    ax1.set_ylabel(f"{model.family.joint_symbol}3 (deg)")
    ax1.set_title("joint ranges and singular curves")
    ax1.legend(loc="lower left", fontsize=8, facecolor="0.6")

    ax2.scatter(1e3 * W[:, 0], 1e3 * W[:, 2], s=1, c="0.6", label="wrist centre (J1 = 0)")
    if model.family.section_shows_tcp:
        rng = np.random.default_rng(0)
        Qt = rng.uniform(lo, hi, size=(60000, n))
        Qt[:, 0] = 0.0
        P = model.fk(Qt)[:, :3, 3]
        ax2.scatter(1e3 * P[:, 0], 1e3 * P[:, 2], s=0.3, c="tab:blue", alpha=0.3,
                    label="tcp (q4 swept)")
    # the singular curves of the left panel mapped into the section (wrist centre, J1 = 0)
    for cs, style, label in ((cs_elbow, "r-", "elbow singular"),
                             (cs_shoulder, "k--", "shoulder singular")):
        for k, seg in enumerate(cs.allsegs[0]):
            Qs = np.zeros((len(seg), n))
            Qs[:, 1:3] = np.deg2rad(seg)
            Ws = wrist_points(model, Qs)
            ax2.plot(1e3 * Ws[:, 0], 1e3 * Ws[:, 2], style, lw=2, label=label if k == 0 else None)
    ax2.axvline(0.0, color="k", lw=0.5)
    ax2.axvline(1e3 * reach.wrist, color="green", ls=":",
                label=f"wrist-centre reach {1e3 * reach.wrist:.1f} mm")
    ax2.set_aspect("equal")
    ax2.set_xlabel("x in frame0 (mm)")
    ax2.set_ylabel("z in frame0 (mm)")
    ax2.set_title("x-z section (J1 = 0)")
    ax2.legend(loc="lower left", fontsize=8, markerscale=4)
    fig.suptitle(title or f"{model.name} workspace")
    fig.tight_layout()
    out = Path(out)
    import io

    from sim.core.files import write_atomic

    try:
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=90,
                    metadata={"Software": PNG_SOFTWARE, PNG_WRITTEN_AS: str(out.resolve())})
        write_atomic(out, buf.getvalue())  # a full disk leaves no half-written picture
    finally:
        plt.close(fig)
    return reach

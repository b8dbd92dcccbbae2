"""Contacts in the mechanism picture: the circles, lines, cam profiles and followers of the
``[[contact]]`` entries at each snapshot (a closed contact's surfaces drawn bold)."""
from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..validate import GROUND
from .canvas import GROUND_COLOUR
from .geometry import Poses, profile_points

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

_NCIRCLE = 73
_NPROFILE = 361
_FOLLOWERS = {1: "point", 2: "roller", 3: "flat"}
_PROFILES = {1: "circle", 2: "spline", 3: "fourier"}


def contact_profile(contact: Any) -> np.ndarray:
    """(n, 2) points of a follower-profile contact's cam profile in its body frame."""
    g = contact.geometry
    cam = SimpleNamespace(profile=tuple(g[6:]), profile_kind=_PROFILES[int(g[5])],
                          describe=contact.describe)
    return profile_points(cam, np.linspace(0.0, 2 * np.pi, _NPROFILE))  # type: ignore[arg-type]


def _circle(c: np.ndarray, r: float) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, _NCIRCLE)
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)])


def draw_contacts(ax: "Axes", model: Any, snap: Poses, rows: np.ndarray, result: Any,
                  shade_of: Callable[[str, int], Any], z: Callable[[int], float],
                  scale: float) -> None:
    """Draw every contact of the model at the snapshot rows (see the module docstring)."""
    contacts = getattr(model, "contacts", [])
    if not contacts:
        return
    closed = _closed(result, rows, contacts)
    m = len(rows)

    def colour(body: str, k: int) -> Any:
        return GROUND_COLOUR if body == GROUND else shade_of(body, k)

    def place(body: str, pts: np.ndarray, k: int) -> np.ndarray:
        if body == GROUND:
            return np.asarray(pts, dtype=float)
        return snap.place_many(body, np.asarray(pts, dtype=float), k)

    for c in contacts:
        bi, bj = c.bodies
        g = c.geometry
        for k in range(m):
            lw = 2.4 if closed.get((c.name, k)) else 1.2
            if c.type == "circle-line":
                circ = place(bi, _circle(np.array(g[0:2]), g[2]), k)
                ax.plot(circ[:, 0], circ[:, 1], color=colour(bi, k), lw=lw, zorder=z(k) + 0.2)
                p = place(bj, np.array([g[3:5]]), k)[0]
                nrm = (np.asarray(g[5:7]) if bj == GROUND
                       else snap.turn(bj, g[5:7])[k])
                nrm = nrm / np.hypot(*nrm)
                tan = np.array([-nrm[1], nrm[0]])
                a, b = p - 0.6 * scale * tan, p + 0.6 * scale * tan
                ax.plot([a[0], b[0]], [a[1], b[1]], color=colour(bj, k), lw=2.0,
                        zorder=z(k) + 0.1)
            elif c.type in ("circle-circle", "circle-in-circle"):
                for body, cc, r in ((bi, g[0:2], g[2]), (bj, g[3:5], g[5])):
                    circ = place(body, _circle(np.array(cc), r), k)
                    ax.plot(circ[:, 0], circ[:, 1], color=colour(body, k), lw=lw,
                            zorder=z(k) + 0.2)
            else:
                _follower_profile(ax, c, place, colour, snap, k, lw, z, scale)


def _follower_profile(ax: "Axes", c: Any, place: Callable[..., np.ndarray],
                      colour: Callable[[str, int], Any], snap: Poses, k: int, lw: float,
                      z: Callable[[int], float], scale: float) -> None:
    bi, bj = c.bodies
    g = c.geometry
    pr = place(bi, contact_profile(c), k)
    ax.fill(pr[:, 0], pr[:, 1], color=colour(bi, k), alpha=0.15, lw=0, zorder=z(k) - 0.2)
    ax.plot(pr[:, 0], pr[:, 1], color=colour(bi, k), lw=lw, zorder=z(k) - 0.1)
    kind = _FOLLOWERS[int(g[0])]
    f = place(bj, np.array([g[1:3]]), k)[0]
    if kind == "roller":
        circ = _circle(f, g[3])
        ax.plot(circ[:, 0], circ[:, 1], color=colour(bj, k), lw=lw, zorder=z(k) + 0.1)
    elif kind == "flat":
        nrm = np.asarray(g[3:5]) if bj == GROUND else snap.turn(bj, g[3:5])[k]
        nrm = nrm / np.hypot(*nrm)
        tan = np.array([-nrm[1], nrm[0]])
        a, b = f - 0.35 * scale * tan, f + 0.35 * scale * tan
        ax.plot([a[0], b[0]], [a[1], b[1]], color=colour(bj, k), lw=3.0, zorder=z(k) + 0.1)
    else:
        ax.plot(*f, marker="o", ms=4, color=colour(bj, k), zorder=z(k) + 0.1)


def _closed(result: Any, rows: np.ndarray, contacts: list[Any]) -> dict[tuple[str, int], bool]:
    """Which contacts touch at the snapshot rows (a dynamic result's penetration > 0)."""
    out: dict[tuple[str, int], bool] = {}
    history = getattr(result, "contact", None)
    if history is None:
        return out
    for c in contacts:
        try:
            pen = history(c.name).penetration
        except (KeyError, IndexError):
            continue
        for k, r in enumerate(rows):
            out[(c.name, k)] = bool(pen[r] > 0.0)
    return out


def contact_extent(model: Any, full: Poses, n: int) -> list[np.ndarray]:
    """Points of the contacts' surfaces over the run (for the picture's scale)."""
    out = []
    for c in getattr(model, "contacts", []):
        g = c.geometry
        if c.type == "follower-profile":
            local = [(c.bodies[0], contact_profile(c))]
        elif c.type == "circle-line":
            local = [(c.bodies[0], _circle(np.array(g[0:2]), g[2]))]
        else:
            local = [(c.bodies[0], _circle(np.array(g[0:2]), g[2])),
                     (c.bodies[1], _circle(np.array(g[3:5]), g[5]))]
        for body, pts in local:
            for k in np.unique(np.linspace(0, n - 1, 12).astype(int)):
                out.append(pts if body == GROUND else full.place_many(body, pts, k))
    return out


__all__ = ["draw_contacts", "contact_extent", "contact_profile"]

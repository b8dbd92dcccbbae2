"""Contacts in the mechanism picture: the circles, lines, cam profiles and followers of the
``[[contact]]`` entries, drawn by :class:`ContactDrawer` like every other element
(:mod:`mbd2d.plots.elements`), a touching contact's surfaces bold."""
from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..validate import GROUND
from .elements import Element, Look, Updater
from .geometry import profile_points

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

_NCIRCLE = 73
_NPROFILE = 361
_FOLLOWERS = {1: "point", 2: "roller", 3: "flat"}
_PROFILES = {1: "circle", 2: "spline", 3: "fourier"}
_THIN, _BOLD = 1.2, 2.4


def contact_profile(contact: Any) -> np.ndarray:
    """(n, 2) points of a follower-profile contact's cam profile in its body frame."""
    g = contact.geometry
    cam = SimpleNamespace(profile=tuple(g[6:]), profile_kind=_PROFILES[int(g[5])],
                          describe=contact.describe)
    return profile_points(cam, np.linspace(0.0, 2 * np.pi, _NPROFILE))  # type: ignore[arg-type]


def _circle(c: Any, r: float) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, _NCIRCLE)
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)])


class ContactDrawer(Element):
    """A contact: its two surfaces on their bodies at each row (circles, a line, a cam
    profile and its follower), bold while the contact touches (penetration > 0)."""

    batchable = False                           # its outline thickens in contact

    def _shapes(self) -> list[tuple[str, np.ndarray]]:
        """The closed surfaces (body, local points) of the contact."""
        c = self.item
        g = c.geometry
        bi, bj = c.bodies
        if c.type == "circle-line":
            return [(bi, _circle(g[0:2], g[2]))]
        if c.type in ("circle-circle", "circle-in-circle"):
            return [(bi, _circle(g[0:2], g[2])), (bj, _circle(g[3:5], g[5]))]
        shapes = [(bi, contact_profile(c))]
        if _FOLLOWERS[int(g[0])] == "roller":
            shapes.append((bj, _circle(g[1:3], g[3])))
        return shapes

    def _segment(self, half: float) -> tuple[str, np.ndarray] | None:
        """The straight surface (body, two local points) of a circle-line contact or a flat
        follower, half long on each side."""
        c = self.item
        g = c.geometry
        if c.type == "circle-line":
            p, n = np.asarray(g[3:5], float), np.asarray(g[5:7], float)
        elif c.type == "follower-profile" and _FOLLOWERS[int(g[0])] == "flat":
            p, n = np.asarray(g[1:3], float), np.asarray(g[3:5], float)
        else:
            return None
        n = n / np.hypot(*n)
        tan = np.array([-n[1], n[0]])
        return c.bodies[1], np.array([p - half * tan, p + half * tan])

    def _touching(self) -> np.ndarray:
        """Per output row: does the contact touch (a dynamic result's penetration > 0)."""
        history = getattr(self.scene.result, "contact", None)
        n = len(self.scene.result.t)
        if history is None:
            return np.zeros(n, dtype=bool)
        try:
            return np.asarray(history(self.item.name).penetration) > 0.0
        except (KeyError, IndexError, AttributeError):
            return np.zeros(n, dtype=bool)

    def size_points(self) -> list[np.ndarray]:
        full, n = self.scene.full, len(self.scene.result.t)
        out = []
        for body, pts in self._shapes():
            for k in np.unique(np.linspace(0, n - 1, 12).astype(int)):
                out.append(full.place_many(body, pts, int(k)))
        return out

    def extent(self) -> list[np.ndarray]:
        return self.size_points()

    def fixed(self, ax: "Axes") -> None:
        from .canvas import GROUND_COLOUR
        seg = self._segment(0.6 * self.scene.scale)
        if seg is not None and seg[0] == GROUND:
            ax.plot(seg[1][:, 0], seg[1][:, 1], color=GROUND_COLOUR, lw=2.0, zorder=1.9)
        for body, pts in self._shapes():
            if body == GROUND:
                ax.plot(pts[:, 0], pts[:, 1], color=GROUND_COLOUR, lw=_THIN, zorder=1.9)

    def make(self, ax: "Axes", look: Look) -> Updater | None:
        full = self.scene.full
        touching = self._touching()
        moving = [(body, pts) for body, pts in self._shapes() if body != GROUND]
        lines = [ax.plot([], [], color=look.colour(body), lw=_THIN, zorder=look.z + 0.2)[0]
                 for body, _ in moving]
        seg = self._segment(0.35 * self.scene.scale if self.item.type != "circle-line"
                            else 0.6 * self.scene.scale)
        seg_line = None
        if seg is not None and seg[0] != GROUND:
            seg_line = ax.plot([], [], color=look.colour(seg[0]), lw=2.0,
                               zorder=look.z + 0.1)[0]
        point = None
        g = self.item.geometry
        if self.item.type == "follower-profile" and _FOLLOWERS[int(g[0])] == "point" \
                and self.item.bodies[1] != GROUND:
            point = ax.plot([], [], marker="o", ms=4, color=look.colour(self.item.bodies[1]),
                            ls="none", zorder=look.z + 0.1)[0]
        if not (lines or seg_line or point):
            return None

        def update(k: int) -> None:
            lw = _BOLD if touching[k] else _THIN
            for line, (body, pts) in zip(lines, moving):
                xy = full.place_many(body, pts, k)
                line.set_data(xy[:, 0], xy[:, 1])
                line.set_linewidth(lw)
            if seg_line is not None and seg is not None:
                xy = full.place_many(seg[0], seg[1], k)
                seg_line.set_data(xy[:, 0], xy[:, 1])
            if point is not None:
                xy = full.place_many(self.item.bodies[1], np.array([g[1:3]], float), k)
                point.set_data(xy[:, 0], xy[:, 1])
        return update


__all__ = ["ContactDrawer", "contact_profile"]

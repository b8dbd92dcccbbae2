"""How each element of a model is drawn: one class per kind, in one place.

Every drawer answers the same few questions, so a new kind (a contact, a new joint) is one
new class and one line in :data:`DRAWERS`:

* ``attach()``: the body points it fixes (they shape the links: a body is drawn as the
  plate or bar through its attachment points),
* ``owns()``: the bodies it draws itself (a gear, a disc, a cam), so no link is drawn for them,
* ``extent()``: global points over the run (the picture's limits),
* ``fixed(ax)``: the parts on ground, drawn once,
* ``make(ax, look)``: the moving parts' artists, and a function that moves them to a row.

A snapshot picture calls ``make`` once per snapshot; an animation once, then moves the
artists frame by frame. Positions are body-local points placed with r + A(theta) s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Protocol, Sequence

import numpy as np

from ..description.forces import PointForce, RotationalSpring, Spring, Torque
from ..description.joints import (Absolute, Cam, Distance, Gear, PinInSlot, PointOnCurve,
                                  PointOnLine, RackPinion, Revolute, RollingDisc, Translational,
                                  Weld)
from ..validate import GROUND
from .batch import ArrowMark, Recorder
from .canvas import GROUND_COLOUR, LOAD_COLOUR, REACTION_COLOUR
from .geometry import Poses, convex_hull, function_values, profile_points

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

Updater = Callable[[int], None]
Point = tuple[float, float]

NPROFILE = 181        # points along a drawn cam profile or curve
NCIRCLE = 73          # points along a drawn circle


class Scene(Protocol):
    """What a drawer reads from the scene that holds it (:class:`mbd2d.plots.scene.Scene`)."""

    result: Any                                  #: the run (a Motion)
    model: Any                                   #: its model description
    full: Poses                                  #: body poses at every output row
    scale: float                                 #: size of the picture (model units)
    attach: dict[str, list[tuple[float, float]]]  #: attachment points of each body

    def force_length(self, f: np.ndarray, kind: str) -> np.ndarray:
        """Arrow vectors for forces f (n, 2) of a kind ("load" or "reaction")."""

    def alpha_column(self, cam: Any) -> int | None:
        """Column of a cam's contact parameter in q."""

    def slide_axis(self, body: str) -> tuple[float, float] | None:
        """Axis (body frame) of the body's first translational joint."""

    @property
    def owned(self) -> set[str]:
        """Bodies drawn by their own element (gears, discs, cams)."""


@dataclass
class Look:
    """How one copy of the mechanism is drawn (a snapshot, or the animation)."""

    colour: Callable[[str], Any]      #: body name -> colour (ground included)
    fill: float = 0.3                 #: opacity of filled shapes
    z: float = 2.0                    #: base drawing order
    label: bool = False               #: give legend labels


def _circle(c: Sequence[float], r: float, n: int = NCIRCLE) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, n)
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)])


def _stadium(a: np.ndarray, b: np.ndarray, w: float, n: int = 12) -> np.ndarray:
    """Outline of a bar of half-width w around the segment a-b (round ends)."""
    d = b - a
    length = float(np.hypot(*d))
    u = d / length if length > 0 else np.array([1.0, 0.0])
    ang = math.atan2(u[1], u[0])
    s1 = np.linspace(ang - np.pi / 2, ang + np.pi / 2, n)
    s2 = s1 + np.pi
    return np.vstack([b + w * np.column_stack([np.cos(s1), np.sin(s1)]),
                      a + w * np.column_stack([np.cos(s2), np.sin(s2)])])


def _joined(segments: list[np.ndarray]) -> np.ndarray:
    """Polylines joined into one array with NaN rows between them (one Line2D)."""
    out: list[np.ndarray] = []
    for s in segments:
        out += [s, np.full((1, 2), np.nan)]
    return np.vstack(out) if out else np.zeros((0, 2))


def hatch(a: np.ndarray, b: np.ndarray, h: float, nrm: np.ndarray) -> np.ndarray:
    """Short hatch ticks on the nrm side of a ground line from a to b (one NaN-joined
    polyline)."""
    d = b - a
    length = float(np.hypot(*d))
    if length == 0.0:
        return np.zeros((0, 2))
    u = d / length
    ticks = []
    for s in np.arange(h, length + 1e-12, 2 * h):
        p = a + s * u
        ticks.append(np.array([p, p + h * nrm - h * u]))
    return _joined(ticks)


class Element:
    """A drawer of one model element (a joint, a force, a trace, a body)."""

    #: whether its moving artists keep their look and only move (then a large scene may
    #: draw them joined with others of the same look: :mod:`.batch`)
    batchable = True

    def __init__(self, item: Any, scene: Scene) -> None:
        self.item = item
        self.scene = scene

    @property
    def name(self) -> str:
        return str(getattr(self.item, "name", ""))

    def attach(self) -> list[tuple[str, Point]]:
        """Body points this element fixes (they shape the links)."""
        return []

    def owns(self) -> set[str]:
        """Bodies this element draws itself (no link is drawn for them)."""
        return set()

    def extent(self) -> list[np.ndarray]:
        """Global points (k, 2) the picture must contain."""
        return []

    def size_points(self) -> list[np.ndarray]:
        """Global points (k, 2) that set the picture's size (``scene.scale``) besides the
        attachment points; they must not depend on the scale."""
        return []

    def fixed(self, ax: "Axes") -> None:
        """Draw the parts on ground (once)."""

    def make(self, ax: "Axes", look: Look) -> Updater | None:
        """Artists of the moving parts, and a function moving them to a row."""
        return None

    # helpers ------------------------------------------------------------------------------
    def place(self, body: str, s: Any) -> np.ndarray:
        """(n, 2) global path of a body point over every row."""
        return self.scene.full.place(body, s)

    def moving(self, body: str) -> bool:
        return body != GROUND


# ----------------------------------------------------------------------------- bodies
class BodyLink(Element):
    """A moving body: the plate (three or more attachment points), bar (two) or slider
    block (one, on a slide) through its attachment points; its centre of mass as '+'."""

    def __init__(self, item: Any, scene: Scene) -> None:
        super().__init__(item, scene)
        body = item.name
        pts = np.array(scene.attach.get(body, [(0.0, 0.0)]), dtype=float)
        hull = convex_hull(pts)
        w = 0.022 * scene.scale
        self.shape: np.ndarray | None = None
        self.kind = "none"
        if len(hull) >= 3:
            self.shape, self.kind = hull, "plate"
        elif len(hull) == 2:
            self.shape, self.kind = _stadium(hull[0], hull[1], w), "bar"
        elif body not in scene.owned:
            axis = scene.slide_axis(body)
            c = hull[0] if len(hull) else np.zeros(2)
            if axis is not None:
                bw, bh = 0.05 * scene.scale, 0.032 * scene.scale
                blk = np.array([[-bw, -bh], [bw, -bh], [bw, bh], [-bw, bh]])
                ang = math.atan2(axis[1], axis[0])
                ca, sa = math.cos(ang), math.sin(ang)
                self.shape = blk @ np.array([[ca, sa], [-sa, ca]]) + c
                self.kind = "block"
            else:
                self.shape, self.kind = _circle(c, 1.3 * w, 25), "mass"

    def make(self, ax: "Axes", look: Look) -> Updater:
        from matplotlib.patches import Polygon

        body = self.item.name
        col = look.colour(body)
        arts: list[Any] = []
        if self.shape is not None:
            face = col if self.kind != "block" else col
            poly = Polygon(self.shape, closed=True, facecolor=face, alpha=None, edgecolor=col,
                           lw=1.6, zorder=look.z, label=body if look.label else None)
            poly.set_facecolor(_with_alpha(face, look.fill if self.kind != "block"
                                           else min(1.0, look.fill + 0.35)))
            ax.add_patch(poly)
            arts.append(poly)
        (com,) = ax.plot([], [], marker="+", ms=6, mew=1.2, color=col, ls="none",
                         zorder=look.z + 0.05,
                         label=body if look.label and self.shape is None else None)
        full = self.scene.full
        shape = self.shape

        def update(k: int) -> None:
            if shape is not None:
                arts[0].set_xy(full.place_many(body, shape, k))
            o = full.pose(body)[k]
            com.set_data([o[0]], [o[1]])
        return update


def _with_alpha(colour: Any, a: float) -> tuple[float, float, float, float]:
    from matplotlib.colors import to_rgba

    r, g, b, _ = to_rgba(colour)
    return (r, g, b, a)


# ----------------------------------------------------------------------------- joints
def ground_pivot(ax: "Axes", g: np.ndarray, scale: float) -> None:
    """A hatched triangle under a ground pivot at g."""
    d = 0.03 * scale
    tri = np.array([g, g + [-d, -1.6 * d], g + [d, -1.6 * d]])
    ax.fill(tri[:, 0], tri[:, 1], facecolor="0.85", edgecolor=GROUND_COLOUR, lw=1.2,
            zorder=1.2)
    y0 = g[1] - 1.6 * d
    ax.plot([g[0] - 1.5 * d, g[0] + 1.5 * d], [y0, y0], color=GROUND_COLOUR, lw=1.5,
            zorder=1.2)
    h = hatch(np.array([g[0] - 1.5 * d, y0]), np.array([g[0] + 1.5 * d, y0]), 0.5 * d,
              np.array([0.0, -1.0]))
    ax.plot(h[:, 0], h[:, 1], color=GROUND_COLOUR, lw=0.8, zorder=1.2)


def ground_line(ax: "Axes", a: np.ndarray, b: np.ndarray, scale: float,
                side: np.ndarray) -> None:
    """A fixed line from a to b hatched on its ``side``."""
    ax.plot([a[0], b[0]], [a[1], b[1]], color=GROUND_COLOUR, lw=1.8, solid_capstyle="butt",
            zorder=1.0)
    h = hatch(a, b, 0.02 * scale, side)
    ax.plot(h[:, 0], h[:, 1], color=GROUND_COLOUR, lw=0.8, zorder=0.9)


def _pin(ax: "Axes", col: Any, z: float, size: float = 6.0) -> Any:
    (pin,) = ax.plot([], [], marker="o", ms=size, mfc="white", mec=col, mew=1.4, ls="none",
                     zorder=z + 0.3)
    return pin


class RevoluteDrawer(Element):
    """A pin: a white circle at the joint; on ground a hatched pivot."""

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, tuple(s)) for b, s in zip(self.item.bodies, self.item.points)
                if self.moving(b)]

    def _carrier(self) -> tuple[str, Any]:
        j = self.item
        b = j.bodies[1] if j.bodies[0] == GROUND else j.bodies[0]
        return b, j.points[j.bodies.index(b)]

    def fixed(self, ax: "Axes") -> None:
        j = self.item
        if GROUND in j.bodies:
            ground_pivot(ax, np.asarray(j.points[j.bodies.index(GROUND)], dtype=float),
                         self.scene.scale)

    def make(self, ax: "Axes", look: Look) -> Updater:
        body, s = self._carrier()
        pin = _pin(ax, look.colour(body), look.z)
        path = self.place(body, s)

        def update(k: int) -> None:
            pin.set_data([path[k, 0]], [path[k, 1]])
        return update


class LineDrawer(Element):
    """Common part of translational joints, pins in straight slots and points on lines: the
    line of body i along which point j moves, over the range it uses."""

    def axis_of_i(self) -> np.ndarray:
        j = self.item
        return np.asarray(j.axes[0] if isinstance(j, Translational) else j.axis, dtype=float)

    def offset(self) -> float:
        return float(getattr(self.item, "offset", 0.0) or 0.0)

    def local_segment(self, margin: float) -> tuple[np.ndarray, np.ndarray]:
        """Ends (in body i's frame) of the used part of the line."""
        j = self.item
        bi, bj = j.bodies
        full = self.scene.full
        u = self.axis_of_i()
        u = u / np.hypot(*u)
        n = np.array([-u[1], u[0]])
        si = np.asarray(j.points[0], dtype=float) + self.offset() * n
        # the points of body j that slide along (a slider's whole shape), in body i's frame
        own = [tuple(j.points[1])]
        if isinstance(j, Translational) and bj != GROUND:
            own += self.scene.attach.get(bj, [])
        pi_ = full.pose(bi)
        c, sn = np.cos(pi_[:, 2]), np.sin(pi_[:, 2])
        lo, hi = np.inf, -np.inf
        for p in own:
            d = full.place(bj, p) - pi_[:, :2]
            loc = np.column_stack([c * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + c * d[:, 1]])
            s = (loc - si) @ u
            lo, hi = min(lo, float(s.min())), max(hi, float(s.max()))
        return si + (lo - margin) * u, si + (hi + margin) * u

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, tuple(s)) for b, s in zip(self.item.bodies, self.item.points)
                if self.moving(b)]

    def extent(self) -> list[np.ndarray]:
        a, b = self.local_segment(0.1 * self.scene.scale)
        bi = self.item.bodies[0]
        return [self.place(bi, a), self.place(bi, b)]


class TranslationalDrawer(LineDrawer):
    """A slide: on ground two hatched rails; on a moving body its guide line (dashed). The
    slider itself is its body's block."""

    def fixed(self, ax: "Axes") -> None:
        j = self.item
        if j.bodies[0] != GROUND:
            return
        sc = self.scene.scale
        a, b = self.local_segment(0.12 * sc)
        u = (b - a) / max(np.hypot(*(b - a)), 1e-300)
        nrm = np.array([-u[1], u[0]])
        for side in (1.0, -1.0):
            off = side * 0.045 * sc * nrm
            ground_line(ax, a + off, b + off, sc, side * nrm)

    def make(self, ax: "Axes", look: Look) -> Updater | None:
        bi = self.item.bodies[0]
        if bi == GROUND:
            return None
        a, b = self.local_segment(0.12 * self.scene.scale)
        (line,) = ax.plot([], [], color=look.colour(bi), lw=1.2, ls="--", zorder=look.z - 0.5)
        full = self.scene.full
        seg = np.array([a, b])

        def update(k: int) -> None:
            g = full.place_many(bi, seg, k)
            line.set_data(g[:, 0], g[:, 1])
        return update


class SlotDrawer(LineDrawer):
    """A pin in a straight slot (revolute-translational): the slot's outline in body i, the
    pin in body j; a point on a line: the line and the point."""

    def _shape(self) -> np.ndarray:
        sc = self.scene.scale
        a, b = self.local_segment(0.04 * sc)
        if isinstance(self.item, PinInSlot):
            return _stadium(a, b, 0.02 * sc)
        return np.array([a, b])

    def fixed(self, ax: "Axes") -> None:
        bi = self.item.bodies[0]
        if bi != GROUND:
            return
        g = self._shape()
        if isinstance(self.item, PinInSlot):
            ax.fill(g[:, 0], g[:, 1], facecolor="white", edgecolor=GROUND_COLOUR, lw=1.6,
                    zorder=1.0)
        else:
            u = (g[1] - g[0]) / max(np.hypot(*(g[1] - g[0])), 1e-300)
            ground_line(ax, g[0], g[1], self.scene.scale, np.array([u[1], -u[0]]))

    def make(self, ax: "Axes", look: Look) -> Updater:
        from matplotlib.patches import Polygon

        bi, bj = self.item.bodies
        full = self.scene.full
        shape = self._shape()
        slot = None
        if bi != GROUND:
            if isinstance(self.item, PinInSlot):
                slot = Polygon(shape, closed=True, facecolor="white", edgecolor=look.colour(bi),
                               lw=1.5, zorder=look.z + 0.15)
                ax.add_patch(slot)
            else:
                (slot,) = ax.plot([], [], color=look.colour(bi), lw=1.4, zorder=look.z + 0.15)
        pin = _pin(ax, look.colour(bj), look.z, 5.0)
        path = self.place(bj, self.item.points[1])
        is_slot = isinstance(self.item, PinInSlot)

        def update(k: int) -> None:
            if slot is not None:
                g = full.place_many(bi, shape, k)
                if is_slot:
                    slot.set_xy(g)
                else:
                    slot.set_data(g[:, 0], g[:, 1])
            pin.set_data([path[k, 0]], [path[k, 1]])
        return update


class DistanceDrawer(Element):
    """A massless link of fixed length: a thin rod between two pins."""

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, tuple(s)) for b, s in zip(self.item.bodies, self.item.points)
                if self.moving(b)]

    def fixed(self, ax: "Axes") -> None:
        j = self.item
        if GROUND in j.bodies:
            ground_pivot(ax, np.asarray(j.points[j.bodies.index(GROUND)], dtype=float),
                         self.scene.scale)

    def make(self, ax: "Axes", look: Look) -> Updater:
        (rod,) = ax.plot([], [], color="0.25", lw=2.2, solid_capstyle="round",
                         zorder=look.z + 0.2)
        pins = _pin(ax, "0.25", look.z, 5.0)
        a = self.place(self.item.bodies[0], self.item.points[0])
        b = self.place(self.item.bodies[1], self.item.points[1])

        def update(k: int) -> None:
            rod.set_data([a[k, 0], b[k, 0]], [a[k, 1], b[k, 1]])
            pins.set_data([a[k, 0], b[k, 0]], [a[k, 1], b[k, 1]])
        return update


class WeldDrawer(Element):
    """A rigid connection: a filled square at the weld point."""

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, tuple(s)) for b, s in zip(self.item.bodies, self.item.points)
                if self.moving(b)]

    def make(self, ax: "Axes", look: Look) -> Updater:
        j = self.item
        body = j.bodies[1] if j.bodies[1] != GROUND else j.bodies[0]
        (sq,) = ax.plot([], [], marker="s", ms=6, color=look.colour(body), mec="k", mew=0.8,
                        ls="none", zorder=look.z + 0.3)
        path = self.place(body, j.points[j.bodies.index(body)])

        def update(k: int) -> None:
            sq.set_data([path[k, 0]], [path[k, 1]])
        return update


def _wheel(r: float, teeth: int, inward: bool, tooth: float) -> np.ndarray:
    """Local polyline (NaN-joined) of a pitch circle's tooth ticks and its mark (a radius
    at angle 0), about the origin."""
    segs = []
    for a in np.linspace(0.0, 2 * np.pi, teeth, endpoint=False):
        u = np.array([math.cos(a), math.sin(a)])
        r2 = r - tooth if inward else r + tooth
        segs.append(np.array([r * u, r2 * u]))
    segs.append(np.array([[0.0, 0.0], [r, 0.0]]))
    return _joined(segs)


class CircleDrawer(Element):
    """Common part of wheels: a pitch circle (dash-dot) with tooth ticks and a mark that
    shows its turning, or a disc with a spoke."""

    def wheels(self) -> list[tuple[str, np.ndarray, float, str]]:
        """(body, centre in its frame, radius, style: 'gear' | 'gear-in' | 'disc')."""
        return []

    def owns(self) -> set[str]:
        return {b for b, _, _, _ in self.wheels() if b != GROUND}

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, (float(c[0]), float(c[1]))) for b, c, _, _ in self.wheels()
                if self.moving(b)]

    def size_points(self) -> list[np.ndarray]:
        out = []
        for b, c, r, _ in self.wheels():
            p = self.place(b, c)
            out += [p + [r, r], p - [r, r]]
        return out

    def extent(self) -> list[np.ndarray]:
        return self.size_points()

    def _local(self, c: np.ndarray, r: float, style: str) -> tuple[np.ndarray, np.ndarray]:
        circle = _circle(c, r)
        tooth = 0.04 * self.scene.scale
        if style == "disc":
            marks = np.array([c, c + [r, 0.0]])
        else:
            teeth = int(min(72, max(8, round(2 * np.pi * r / (2.2 * tooth)))))
            marks = _wheel(r, teeth, style == "gear-in", min(tooth, 0.3 * r)) + c
        return circle, marks

    def fixed(self, ax: "Axes") -> None:
        for b, c, r, style in self.wheels():
            if b != GROUND:
                continue
            circle, marks = self._local(c, r, style)
            ax.plot(circle[:, 0], circle[:, 1], color=GROUND_COLOUR,
                    lw=1.4, ls="-." if style != "disc" else "-", zorder=1.1)
            ax.plot(marks[:, 0], marks[:, 1], color=GROUND_COLOUR, lw=1.0, zorder=1.1)

    def make(self, ax: "Axes", look: Look) -> Updater | None:
        parts = []
        for b, c, r, style in self.wheels():
            if b == GROUND:
                continue
            col = look.colour(b)
            circle, marks = self._local(c, r, style)
            if style == "disc":
                from matplotlib.patches import Polygon

                disc = Polygon(circle, closed=True, facecolor=_with_alpha(col, look.fill),
                               edgecolor=col, lw=1.8, zorder=look.z + 0.1)
                ax.add_patch(disc)
                (m,) = ax.plot([], [], color=col, lw=1.4, zorder=look.z + 0.12)
                parts.append((b, circle, marks, disc, m))
            else:
                (ln,) = ax.plot([], [], color=col, lw=1.6, ls="-.", zorder=look.z + 0.1)
                (m,) = ax.plot([], [], color=col, lw=1.2, zorder=look.z + 0.12)
                parts.append((b, circle, marks, ln, m))
        if not parts:
            return None
        full = self.scene.full

        def update(k: int) -> None:
            for b, circle, marks, art, m in parts:
                g = full.place_many(b, circle, k)
                if hasattr(art, "set_xy"):
                    art.set_xy(g)
                else:
                    art.set_data(g[:, 0], g[:, 1])
                g = full.place_many(b, marks, k)
                m.set_data(g[:, 0], g[:, 1])
        return update


class GearDrawer(CircleDrawer):
    """A gear pair: the two pitch circles, tooth ticks (inward on an internal ring) and a
    mark on each."""

    def wheels(self) -> list[tuple[str, np.ndarray, float, str]]:
        g = self.item
        out = []
        big = int(np.argmax(g.radii))
        for k in (0, 1):
            style = "gear-in" if (g.internal and k == big) else "gear"
            out.append((g.bodies[k], self.centre(k), float(g.radii[k]), style))
        return out

    def centre(self, k: int) -> np.ndarray:
        """Centre of gear k in its frame: ``centers``, the revolute to the carrier, else
        the origin."""
        g = self.item
        if g.centers is not None:
            return np.asarray(g.centers[k], dtype=float)
        body = g.bodies[k]
        for c in self.scene.model.joints:
            if isinstance(c, Revolute) and set(c.bodies) == {body, g.carrier}:
                return np.asarray(c.points[c.bodies.index(body)], dtype=float)
        return np.zeros(2)


class RackDrawer(CircleDrawer):
    """Rack and pinion, or a rolling disc: the pinion's pitch circle (or the disc) on body
    i, the rack line (teeth toward the pinion) or the rolling line on body j."""

    def wheels(self) -> list[tuple[str, np.ndarray, float, str]]:
        j = self.item
        style = "disc" if isinstance(j, RollingDisc) else "gear"
        return [(j.bodies[0], np.asarray(j.center, dtype=float), float(j.radius), style)]

    def _line(self) -> tuple[np.ndarray, np.ndarray]:
        """Local segment (body j's frame) of the line the wheel uses, and the unit normal
        toward the wheel."""
        j = self.item
        bi, bj = j.bodies
        full = self.scene.full
        u = np.asarray(j.axis, dtype=float)
        u = u / np.hypot(*u)
        p0 = np.asarray(j.point, dtype=float)
        c = full.place(bi, j.center)
        pj = full.pose(bj)
        cs, sn = np.cos(pj[:, 2]), np.sin(pj[:, 2])
        d = c - pj[:, :2]
        loc = np.column_stack([cs * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + cs * d[:, 1]])
        s = (loc - p0) @ u
        m = float(j.radius) + 0.1 * self.scene.scale
        n = np.array([-u[1], u[0]])
        side = n if float(np.mean((loc - p0) @ n)) >= 0 else -n
        return np.array([p0 + (s.min() - m) * u, p0 + (s.max() + m) * u]), side

    def _rack(self) -> np.ndarray:
        seg, side = self._line()
        if isinstance(self.item, RollingDisc):
            return seg
        tooth = 0.03 * self.scene.scale
        a, b = seg
        length = float(np.hypot(*(b - a)))
        u = (b - a) / length
        ticks = [np.array([a + s * u, a + s * u + tooth * side])
                 for s in np.arange(0.0, length + 1e-12, 2.2 * tooth)]
        return _joined([seg] + ticks)

    def attach(self) -> list[tuple[str, Point]]:
        out = super().attach()
        j = self.item
        if self.moving(j.bodies[1]):
            out.append((j.bodies[1], tuple(j.point)))
        return out

    def extent(self) -> list[np.ndarray]:
        seg, _ = self._line()
        bj = self.item.bodies[1]
        return super().extent() + [self.place(bj, seg[0]), self.place(bj, seg[1])]

    def fixed(self, ax: "Axes") -> None:
        super().fixed(ax)
        bj = self.item.bodies[1]
        if bj != GROUND:
            return
        seg, side = self._line()
        if isinstance(self.item, RollingDisc):
            ground_line(ax, seg[0], seg[1], self.scene.scale, -side)
        else:
            g = self._rack()
            ax.plot(g[:, 0], g[:, 1], color=GROUND_COLOUR, lw=1.4, zorder=1.0)

    def make(self, ax: "Axes", look: Look) -> Updater | None:
        wheel = super().make(ax, look)
        bj = self.item.bodies[1]
        if bj == GROUND:
            return wheel
        rack = self._rack()
        (ln,) = ax.plot([], [], color=look.colour(bj), lw=1.6, zorder=look.z + 0.1)
        full = self.scene.full

        def update(k: int) -> None:
            if wheel is not None:
                wheel(k)
            g = full.place_many(bj, rack, k)
            ln.set_data(g[:, 0], g[:, 1])
        return update


class CamDrawer(Element):
    """A cam: its profile (from the core) on body i, filled; the follower on body j (knife
    edge, roller or flat face) and the contact point. A point on a curve: the curve drawn
    as a slot, with the pin."""

    def __init__(self, item: Any, scene: Scene) -> None:
        super().__init__(item, scene)
        self.profile = profile_points(item, np.linspace(0.0, 2 * np.pi, NPROFILE))
        self.slot = isinstance(item, PointOnCurve)

    def owns(self) -> set[str]:
        bi = self.item.bodies[0]
        return set() if self.slot or bi == GROUND else {bi}

    def attach(self) -> list[tuple[str, Point]]:
        bj = self.item.bodies[1]
        f = self.item.follower
        return [(bj, (float(f[0]), float(f[1])))] if self.moving(bj) else []

    def extent(self) -> list[np.ndarray]:
        return self.size_points()

    def size_points(self) -> list[np.ndarray]:
        bi = self.item.bodies[0]
        full = self.scene.full
        n = len(self.scene.result.t)
        return [full.place_many(bi, self.profile, int(k))
                for k in np.unique(np.linspace(0, n - 1, min(n, 24)).astype(int))]

    def _profile_art(self, ax: "Axes", col: Any, fill: float, z: float) -> list[Any]:
        from matplotlib.patches import Polygon

        if self.slot:
            (outer,) = ax.plot([], [], color=col, lw=7.0, solid_capstyle="round", zorder=z)
            (inner,) = ax.plot([], [], color="white", lw=4.6, solid_capstyle="round",
                               zorder=z + 0.01)
            return [outer, inner]
        poly = Polygon(self.profile, closed=True, facecolor=_with_alpha(col, fill),
                       edgecolor=col, lw=1.8, zorder=z)
        ax.add_patch(poly)
        return [poly]

    def fixed(self, ax: "Axes") -> None:
        if self.item.bodies[0] != GROUND:
            return
        for a in self._profile_art(ax, GROUND_COLOUR, 0.15, 1.0):
            if hasattr(a, "set_xy"):
                a.set_xy(self.profile)
            else:
                a.set_data(self.profile[:, 0], self.profile[:, 1])

    def make(self, ax: "Axes", look: Look) -> Updater:
        from matplotlib.patches import Polygon

        cam = self.item
        bi, bj = cam.bodies
        full = self.scene.full
        arts = [] if bi == GROUND else self._profile_art(ax, look.colour(bi), look.fill,
                                                        look.z - 0.2)
        fcol = look.colour(bj)
        kind = cam.follower_kind
        fol: Any
        if self.slot:
            fol = _pin(ax, fcol, look.z, 5.0)
            local = None
        elif kind == "roller":
            local = _circle(cam.follower[:2], cam.follower[2])
            fol = Polygon(local, closed=True, facecolor="white", edgecolor=fcol, lw=1.8,
                          zorder=look.z + 0.25)
            ax.add_patch(fol)
        elif kind == "flat":
            n = np.asarray(cam.follower[2:], dtype=float)
            n = n / np.hypot(*n)
            tan = np.array([-n[1], n[0]])
            half = 0.15 * self.scene.scale
            f0 = np.asarray(cam.follower[:2], dtype=float)
            local = np.array([f0 - half * tan, f0 + half * tan])
            (fol,) = ax.plot([], [], color=fcol, lw=3.0, solid_capstyle="butt",
                             zorder=look.z + 0.25)
        else:
            local = None
            (fol,) = ax.plot([], [], marker="v", ms=7, color=fcol, ls="none",
                             zorder=look.z + 0.25)
        (contact,) = ax.plot([], [], marker="o", ms=3.5, color="k", ls="none",
                             zorder=look.z + 0.4)
        fpath = self.place(bj, cam.follower[:2])
        col = self.scene.alpha_column(cam)
        alphas = self.scene.result.q[:, col] if col is not None else None

        def update(k: int) -> None:
            if arts:
                g = full.place_many(bi, self.profile, k)
                for a in arts:
                    if hasattr(a, "set_xy"):
                        a.set_xy(g)
                    else:
                        a.set_data(g[:, 0], g[:, 1])
            if local is None:
                fol.set_data([fpath[k, 0]], [fpath[k, 1]])
            else:
                g = full.place_many(bj, local, k)
                if hasattr(fol, "set_xy"):
                    fol.set_xy(g)
                else:
                    fol.set_data(g[:, 0], g[:, 1])
            if alphas is not None:
                p = full.place_many(bi, profile_points(cam, alphas[[k]]), k)
                contact.set_data(p[:, 0], p[:, 1])
        return update


class AbsoluteDrawer(Element):
    """A fixed coordinate: x fixed, a short hatched wall along which the body's origin slides
    (vertical), y fixed likewise (horizontal); theta fixed, a short hatched line along the
    body's fixed direction."""

    def make(self, ax: "Axes", look: Look) -> Updater:
        j = self.item
        body = j.bodies[0]
        h = 0.05 * self.scene.scale
        (wall,) = ax.plot([], [], color=GROUND_COLOUR, lw=1.6, zorder=look.z + 0.3)
        (ticks,) = ax.plot([], [], color=GROUND_COLOUR, lw=0.8, zorder=look.z + 0.3)
        o = self.place(body, (0.0, 0.0))
        coord = j.coordinate
        th = self.scene.full.pose(body)[:, 2]

        def update(k: int) -> None:
            if coord == "x":
                u = np.array([0.0, 1.0])
            elif coord == "y":
                u = np.array([1.0, 0.0])
            else:
                u = np.array([math.cos(th[k]), math.sin(th[k])])
            a, b = o[k] - h * u, o[k] + h * u
            wall.set_data([a[0], b[0]], [a[1], b[1]])
            g = hatch(a, b, 0.3 * h, np.array([u[1], -u[0]]))
            ticks.set_data(g[:, 0], g[:, 1])
        return update


# ----------------------------------------------------------------------------- forces
def _zigzag(a: np.ndarray, b: np.ndarray, w: float, coils: int = 7) -> np.ndarray:
    """A spring's zigzag from a to b: straight ends, coils of half-width w between."""
    d = b - a
    length = float(np.hypot(*d))
    if length == 0.0:
        return np.array([a, b])
    u = d / length
    n = np.array([-u[1], u[0]])
    s = np.concatenate([[0.0, 0.2], 0.2 + 0.6 * (np.arange(1, 2 * coils) / (2 * coils)),
                        [0.8, 1.0]])
    off = np.zeros_like(s)
    off[2:-2] = w * np.where(np.arange(len(s) - 4) % 2 == 0, 1.0, -1.0)
    return a + np.outer(s * length, u) + np.outer(off, n)


class SpringDrawer(Element):
    """A spring-damper: a zigzag between its two points."""

    def attach(self) -> list[tuple[str, Point]]:
        return [(b, tuple(s)) for b, s in zip(self.item.bodies, self.item.points)
                if self.moving(b)]

    def extent(self) -> list[np.ndarray]:
        return [self.place(b, s) for b, s in zip(self.item.bodies, self.item.points)]

    def make(self, ax: "Axes", look: Look) -> Updater:
        (ln,) = ax.plot([], [], color="0.3", lw=1.3, zorder=look.z + 0.2)
        a = self.place(self.item.bodies[0], self.item.points[0])
        b = self.place(self.item.bodies[1], self.item.points[1])
        w = 0.03 * self.scene.scale

        def update(k: int) -> None:
            g = _zigzag(a[k], b[k], w)
            ln.set_data(g[:, 0], g[:, 1])
        return update


class RotationalSpringDrawer(Element):
    """A rotational spring: a spiral at the revolute joint between its bodies (else at body
    j's origin), turning with body j."""

    def _site(self) -> tuple[str, np.ndarray]:
        bi, bj = self.item.bodies
        for c in self.scene.model.joints:
            if isinstance(c, Revolute) and set(c.bodies) == {bi, bj}:
                b = bj if bj != GROUND else bi
                return b, np.asarray(c.points[c.bodies.index(b)], dtype=float)
        return (bj if bj != GROUND else bi), np.zeros(2)

    def make(self, ax: "Axes", look: Look) -> Updater:
        body, s = self._site()
        a = np.linspace(0.0, 5 * np.pi, 90)
        r = 0.015 * self.scene.scale + 0.05 * self.scene.scale * a / a[-1]
        local = s + np.column_stack([r * np.cos(a), r * np.sin(a)])
        (ln,) = ax.plot([], [], color="0.3", lw=1.1, zorder=look.z + 0.35)
        full = self.scene.full

        def update(k: int) -> None:
            g = full.place_many(body, local, k)
            ln.set_data(g[:, 0], g[:, 1])
        return update


class Arrow:
    """One arrow artist moved frame by frame (hidden when the vector is zero); in a large
    scene (ax a Recorder) one of a batch, drawn with the others of its look as one quiver."""

    def __init__(self, ax: "Axes", colour: Any, z: float, width: float = 1.6) -> None:
        from matplotlib.patches import FancyArrowPatch

        self.patch: Any = None
        self.mark: ArrowMark | None = None
        if isinstance(ax, Recorder):
            self.mark = ax.arrow(colour, z, width)
            return
        self.patch = FancyArrowPatch((0, 0), (0, 0), arrowstyle="-|>", mutation_scale=11,
                                     color=colour, lw=width, zorder=z, shrinkA=0, shrinkB=0)
        ax.add_patch(self.patch)

    def set(self, tail: np.ndarray, head: np.ndarray) -> None:
        if self.mark is not None:
            self.mark.set(tail, head)
            return
        self.patch.set_positions(tuple(tail), tuple(head))
        self.patch.set_visible(bool(np.hypot(*(head - tail)) > 0))


class PointForceDrawer(Element):
    """An applied force: an arrow from its point, as long as the force is large (the
    largest applied force over the run is drawn a fifth of the picture long)."""

    def __init__(self, item: Any, scene: Scene) -> None:
        super().__init__(item, scene)
        t = scene.result.t
        self.f = np.column_stack([function_values(item.fx, t, item.describe()),
                                  function_values(item.fy, t, item.describe())])

    def attach(self) -> list[tuple[str, Point]]:
        b = self.item.bodies[0]
        return [(b, tuple(self.item.point))] if self.moving(b) else []

    def magnitude(self) -> float:
        return float(np.hypot(self.f[:, 0], self.f[:, 1]).max(initial=0.0))

    def extent(self) -> list[np.ndarray]:
        p = self.place(self.item.bodies[0], self.item.point)
        return [p, p + self.scene.force_length(self.f, "load")]

    def make(self, ax: "Axes", look: Look) -> Updater:
        arrow = Arrow(ax, LOAD_COLOUR, look.z + 0.5)
        p = self.place(self.item.bodies[0], self.item.point)
        v = self.scene.force_length(self.f, "load")

        def update(k: int) -> None:
            arrow.set(p[k], p[k] + v[k])
        return update


class TorqueDrawer(Element):
    """An applied torque: a curved arrow around the body's centre of mass, turning the way
    the torque does (hidden while it is zero)."""

    batchable = False                           # its arrowhead turns

    def __init__(self, item: Any, scene: Scene) -> None:
        super().__init__(item, scene)
        self.f = function_values(item.f, scene.result.t, item.describe())

    def make(self, ax: "Axes", look: Look) -> Updater:
        body = self.item.bodies[0]
        r = 0.06 * self.scene.scale
        (arc,) = ax.plot([], [], color=LOAD_COLOUR, lw=1.6, zorder=look.z + 0.5)
        (head,) = ax.plot([], [], marker=(3, 0, 0), ms=8, color=LOAD_COLOUR, ls="none",
                          zorder=look.z + 0.5)
        o = self.place(body, (0.0, 0.0))
        a = np.linspace(-0.75 * np.pi, 0.75 * np.pi, 40)
        f = self.f

        def update(k: int) -> None:
            if f[k] == 0.0:
                arc.set_data([], [])
                head.set_data([], [])
                return
            arc.set_data(o[k, 0] + r * np.cos(a), o[k, 1] + r * np.sin(a))
            end = a[-1] if f[k] > 0 else a[0]
            head.set_data([o[k, 0] + r * math.cos(end)], [o[k, 1] + r * math.sin(end)])
            # the triangle points along the direction of turning
            head.set_marker((3, 0, math.degrees(end) + (0.0 if f[k] > 0 else 180.0)))
        return update


class ReactionDrawer(Element):
    """The force of a joint on one of its bodies (body j, or i when j is ground): an arrow
    at the joint point (the largest reaction over the run a fifth of the picture long)."""

    def __init__(self, item: Any, scene: Scene, reaction: Any) -> None:
        super().__init__(item, scene)
        j = item
        k = 1 if j.bodies[1] != GROUND else 0
        self.body = j.bodies[k]
        r = reaction
        self.f = np.column_stack([r.fx_j, r.fy_j]) if k == 1 else np.column_stack([r.fx, r.fy])
        pts = getattr(j, "points", None)
        if pts is not None:
            self.s = tuple(pts[k])
        elif isinstance(j, (RackPinion, Gear)):
            self.s = (0.0, 0.0)
        else:
            self.s = tuple(getattr(j, "follower", (0.0, 0.0))[:2]) if k == 1 else (0.0, 0.0)

    def magnitude(self) -> float:
        return float(np.hypot(self.f[:, 0], self.f[:, 1]).max(initial=0.0))

    def extent(self) -> list[np.ndarray]:
        p = self.place(self.body, self.s)
        return [p, p + self.scene.force_length(self.f, "reaction")]

    def make(self, ax: "Axes", look: Look) -> Updater:
        arrow = Arrow(ax, REACTION_COLOUR, look.z + 0.55, 1.3)
        p = self.place(self.body, self.s)
        v = self.scene.force_length(self.f, "reaction")

        def update(k: int) -> None:
            arrow.set(p[k], p[k] + v[k])
        return update


#: THE table: the drawer of each joint and force class (subclasses first; a kind not
#: listed, such as an absolute constraint, is not drawn).
DRAWERS: list[tuple[type, type[Element]]] = [
    (Revolute, RevoluteDrawer),
    (Translational, TranslationalDrawer),
    (PinInSlot, SlotDrawer),
    (PointOnLine, SlotDrawer),
    (Distance, DistanceDrawer),
    (Weld, WeldDrawer),
    (Gear, GearDrawer),
    (RollingDisc, RackDrawer),
    (RackPinion, RackDrawer),
    (PointOnCurve, CamDrawer),
    (Cam, CamDrawer),
    (Absolute, AbsoluteDrawer),
    (Spring, SpringDrawer),
    (RotationalSpring, RotationalSpringDrawer),
    (PointForce, PointForceDrawer),
    (Torque, TorqueDrawer),
]


def drawer_for(item: Any) -> type[Element] | None:
    """The drawer class of a joint or force (None: not drawn)."""
    for cls, drawer in DRAWERS:
        if type(item) is cls:
            return drawer
    for cls, drawer in DRAWERS:
        if isinstance(item, cls):
            return drawer
    return None

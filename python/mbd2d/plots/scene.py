"""The scene: every element of a model with its drawer (:mod:`.elements`), the bodies as
links through their attachment points, traced paths, loads and reactions, and the picture's
size; drawn as snapshots or moved frame by frame."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from ..description.joints import Cam, Translational
from ..errors import ModelError
from ..validate import GROUND
from .batch import BATCH_MIN, Recorder, place
from .canvas import GROUND_COLOUR, LEGEND_MAX, PALETTE
from .contacts import ContactDrawer
from .elements import (BodyLink, CamDrawer, Element, Look, ReactionDrawer, Updater,
                       convex_hull, drawer_for)
from .geometry import Motion, Poses, TracePoint, check_trace

#: details are sized from the picture, but at most from this many typical bodies
DETAIL_BODIES = 10.0

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

#: longest arrow (the largest force of its kind over the run), as a fraction of the picture
ARROW_FRACTION = 0.2


class TraceDrawer(Element):
    """A traced body point: its path over the whole run, and the point itself."""

    def __init__(self, item: TracePoint, scene: "Scene", index: int) -> None:
        super().__init__(item, scene)
        self.index = index
        self.path = scene.full.place(item[0], item[1])

    def attach(self) -> list[tuple[str, tuple[float, float]]]:
        return [self.item]

    def extent(self) -> list[np.ndarray]:
        return [self.path]

    def fixed(self, ax: "Axes") -> None:
        body, s = self.item
        ax.plot(self.path[:, 0], self.path[:, 1], color="k", lw=1.0,
                ls=(0, (4, 2)) if self.index else "-", alpha=0.8, zorder=1.5,
                label=f"path of {body} ({s[0]:g}, {s[1]:g})")

    def make(self, ax: "Axes", look: Look) -> Updater:
        (dot,) = ax.plot([], [], marker="o", ms=4, color=look.colour(self.item[0]), ls="none",
                         zorder=look.z + 0.3)
        path = self.path

        def update(k: int) -> None:
            dot.set_data([path[k, 0]], [path[k, 1]])
        return update


class Scene:
    """A result's model ready to draw.

    Parameters
    ----------
    result : Motion
        The run (it must carry its model).
    trace : sequence of (body, (sx, sy)), optional
        Points whose paths are drawn.
    forces : bool
        Also draw the joints' reaction forces as arrows (results with multipliers only).
    """

    def __init__(self, result: Motion, trace: Sequence[TracePoint] | None = None,
                 forces: bool = False, what: str = "plot_mechanism") -> None:
        model = getattr(result, "model", None)
        if model is None:
            raise ModelError("the result carries no model (result.model is None); the "
                             "pictures need the joints to draw the bodies", what)
        if len(result.t) == 0:
            raise ModelError("the result has no rows to draw", what)
        self.result = result
        self.model = model
        self.full = Poses(result, np.arange(len(result.t)))
        self.trace = check_trace(result, trace)
        self.colours = {b.name: PALETTE[i % len(PALETTE)] for i, b in enumerate(model.bodies)}
        self._fmax: dict[str, float] = {}

        items = [*model.joints, *model.forces]
        self.items: list[Element] = []
        for item in items:
            cls = drawer_for(item)
            if cls is not None:
                self.items.append(cls(item, self))
        self.items += [ContactDrawer(c, self) for c in getattr(model, "contacts", [])]
        self.traces = [TraceDrawer(tp, self, i) for i, tp in enumerate(self.trace)]

        # attachment points of each body (its origin first) and the bodies drawn by others
        self.attach: dict[str, list[tuple[float, float]]] = {
            b.name: [(0.0, 0.0)] for b in model.bodies}
        for e in [*self.items, *self.traces]:
            for body, s in e.attach():
                if body != GROUND:
                    self.attach[body].append((float(s[0]), float(s[1])))
        self.owned: set[str] = set()
        for e in self.items:
            self.owned |= e.owns()

        # the picture's size from the points that move or stay (margins come later)
        pts = [self.full.place(b, s) for b, ss in self.attach.items() for s in ss]
        for j in model.joints:
            for body, s in zip(j.bodies, getattr(j, "points", ())):
                if body == GROUND:
                    pts.append(np.array([s], dtype=float))
        for e in self.items:
            pts += e.size_points()
        allp = np.vstack(pts)
        extent = float(max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1e-300))
        # the size of the details (pins, hatching, blocks, stems, arrows): the picture's,
        # but at most DETAIL_BODIES typical bodies (a chain of a hundred links keeps its pins
        # at a link's proportions, not the whole chain's)
        self.scale = min(extent, DETAIL_BODIES * self._body_size(extent))
        self._stems()

        self.reactions: list[Element] = []
        if forces:
            self.reactions = self._reaction_drawers()
        self.links = [BodyLink(b, self) for b in model.bodies]

    # ------------------------------------------------------------------ helpers
    def _body_size(self, extent: float) -> float:
        """The median size of the bodies that have one (the largest distance between the
        points attached to them); the extent if none has."""
        sizes = []
        for pts in self.attach.values():
            a = np.array(pts, dtype=float)
            d = float(np.max(np.hypot(*(a[:, None, :] - a[None, :, :]).transpose(2, 0, 1))))
            if d > 0.0:
                sizes.append(d)
        return float(np.median(sizes)) if sizes else extent

    def colour(self, body: str) -> Any:
        return GROUND_COLOUR if body == GROUND else self.colours[body]

    def slide_axis(self, body: str) -> tuple[float, float] | None:
        """The axis, in the body frame, of the first translational joint of body."""
        for j in self.model.joints:
            if isinstance(j, Translational) and body in j.bodies:
                v = j.axes[j.bodies.index(body)]
                return (float(v[0]), float(v[1]))
        return None

    def alpha_column(self, cam: Cam) -> int | None:
        name = f"{cam.name}.alpha"
        names = list(getattr(self.result, "coordinate_names", []))
        return names.index(name) if name in names else None

    def force_length(self, f: np.ndarray, kind: str) -> np.ndarray:
        """Arrow vectors (n, 2) for forces f (n, 2): the largest force of the kind over the
        run is ARROW_FRACTION of the picture long."""
        if kind not in self._fmax:
            group = self.reactions if kind == "reaction" else self.items
            mags = [e.magnitude() for e in group if hasattr(e, "magnitude")]
            self._fmax[kind] = max(mags, default=0.0)
        fmax = self._fmax[kind]
        if not fmax > 0.0:
            return np.zeros_like(f)
        return f * (ARROW_FRACTION * self.scale / fmax)

    def _stems(self) -> None:
        """A cam follower with no shape of its own (all its points coincide) gets a stem
        along its slide axis, pointing away from the cam."""
        for e in self.items:
            cam = e.item
            if not isinstance(e, CamDrawer) or e.slot:
                continue
            bc, bf = cam.bodies
            if bf == GROUND or len(convex_hull(np.array(self.attach[bf]))) != 1:
                continue
            v = np.array(self.slide_axis(bf) or (0.0, 0.0))
            if not v.any():
                continue
            v = v / np.hypot(*v)
            gv = self.full.turn(bf, v)[0]
            away = self.full.place(bf, cam.follower[:2])[0] - self.full.place(bc, (0, 0))[0]
            if float(gv @ away) < 0.0:
                v = -v
            f = np.array(cam.follower[:2], dtype=float)
            stem = 0.35 * self.scale + (cam.follower[2] if cam.follower_kind == "roller"
                                        else 0.0)
            self.attach[bf].append(tuple(f + stem * v))

    def _reaction_drawers(self) -> list[Element]:
        reaction = getattr(self.result, "reaction", None)
        if reaction is None or not hasattr(self.result, "lam"):
            raise ModelError("reaction forces need a result with multipliers (inverse "
                             "dynamics, dynamics or a kinematic run of a model with masses)",
                             "forces")
        return [ReactionDrawer(j, self, reaction(j.name)) for j in self.model.joints]

    def elements(self) -> list[Element]:
        """Every drawer, in drawing order."""
        return [*self.links, *self.items, *self.traces, *self.reactions]

    def limits(self, margin: float = 0.08) -> tuple[tuple[float, float], tuple[float, float]]:
        """x and y limits holding everything over the whole run."""
        pts = [self.full.place(b, s) for b, ss in self.attach.items() for s in ss]
        for e in self.elements():
            pts += e.extent()
        for j in self.model.joints:
            for body, s in zip(j.bodies, getattr(j, "points", ())):
                if body == GROUND:
                    pts.append(np.array([s], dtype=float))
        allp = np.vstack(pts)
        allp = allp[np.all(np.isfinite(allp), axis=1)]
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = margin * max(float((hi - lo).max()), 1e-300)
        return (lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad)

    def fit(self, ax: "Axes") -> None:
        """Make the axes' data limits hold everything over the run (the aspect stays free
        to adjust them)."""
        (x0, x1), (y0, y1) = self.limits(margin=0.03)
        ax.update_datalim([(x0, y0), (x1, y1)])
        ax.autoscale_view()

    # ------------------------------------------------------------------ drawing
    def _recorder(self, ax: "Axes") -> Recorder | None:
        """A large scene's elements draw on a Recorder (:mod:`.batch`), a small one's on the
        Axes."""
        return Recorder(ax) if len(self.elements()) >= BATCH_MIN else None

    def draw_fixed(self, ax: "Axes") -> None:
        """The parts on ground and the traced paths (once)."""
        rec = self._recorder(ax)
        for e in self.elements():
            e.fixed(rec if rec is not None and e.batchable else ax)
        if rec is not None:
            place(ax, rec.artists, LEGEND_MAX)

    def make(self, ax: "Axes", look: Look) -> Callable[[int], None]:
        """Artists of one copy of the moving mechanism, and a function moving it to a
        row."""
        elements = self.elements()
        rec = self._recorder(ax)
        # the artists are made at made-up places (a body's outline in its own frame): they
        # must not stretch the data limits (fit() sets them from the whole run)
        lim, ignore = ax.dataLim.frozen(), ax.ignore_existing_data_limits
        ups = [u for e in elements
               if (u := e.make(rec if rec is not None and e.batchable else ax, look))
               is not None]
        copy = None if rec is None else place(ax, rec.artists, LEGEND_MAX)
        ax.dataLim.set(lim)
        ax.ignore_existing_data_limits = ignore

        def update(k: int) -> None:
            for u in ups:
                u(k)
            if copy is not None:
                copy()
        return update

    def dress(self, ax: "Axes", length_unit: str, title: str | None) -> None:
        """Labels, equal aspect, grid."""
        ax.set_aspect("equal", adjustable="datalim")
        unit = f" [{length_unit}]" if length_unit else ""
        ax.set_xlabel(f"x{unit}")
        ax.set_ylabel(f"y{unit}")
        ax.grid(True, lw=0.4, alpha=0.4)
        if title:
            ax.set_title(title)


__all__ = ["Scene", "Look", "TraceDrawer"]

"""Many artists of one style drawn as one.

matplotlib's cost is per artist, not per point: about 0.7 ms to put a line on an Axes and
0.2 ms to draw it. A chain of a thousand links has thousands of pins, bars and
centre-of-mass marks, so its picture took a minute. In a large scene the elements draw
their parts on ground and their moving artists on a :class:`Recorder` instead of the Axes;
:func:`place` then puts one artist per look on the Axes (a Line2D whose members are joined
by NaN, a PolyCollection of the polygons) and returns the function that copies the
members' positions into them after each update. Small scenes keep one artist per part
(BATCH_MIN).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

#: scenes with at least this many elements (bodies, joints, forces, traces) draw their moving
#: artists batched; smaller ones one artist per element, as matplotlib draws them
BATCH_MIN = 60

_NAN = np.full(1, np.nan)


class Mark:
    """A line or marker recorded for a batch: its data and the keywords of ``ax.plot``
    that style it (a Line2D costs 0.17 ms to make; the batch makes one per look)."""

    def __init__(self, x: Any, y: Any, style: dict[str, Any]) -> None:
        self.x, self.y, self.style = x, y, style

    def set_data(self, x: Any, y: Any) -> None:
        self.x, self.y = x, y

    def key(self) -> tuple[Any, ...]:
        """The look: marks with equal keys are drawn as one line."""
        return ("mark",) + tuple(sorted((k, repr(v)) for k, v in self.style.items()))


class ArrowMark:
    """An arrow recorded for a batch: its tail and head (none drawn while they coincide) and
    its look; drawn with the others of its look as one quiver."""

    def __init__(self, colour: Any, z: float, width: float) -> None:
        self.colour, self.z, self.width = colour, z, width
        self.tail = self.head = np.zeros(2)

    def set(self, tail: np.ndarray, head: np.ndarray) -> None:
        self.tail, self.head = tail, head

    def key(self) -> tuple[Any, ...]:
        return ("arrow", repr(self.colour), self.z, self.width)


class Recorder:
    """Stands in for the Axes while elements make their artists: ``plot(x, y, **style)``
    gives :class:`Mark` s, ``fill(x, y, **style)`` and ``add_patch`` keep the patches
    without putting them on the Axes (their style and data are set as usual); anything else
    is the Axes' own."""

    def __init__(self, ax: "Axes") -> None:
        self.ax = ax
        self.artists: list[Any] = []

    def plot(self, *args: Any, **kw: Any) -> list[Any]:
        if len(args) != 2:
            return self.ax.plot(*args, **kw)        # a format string: the Axes draws it
        mark = Mark(args[0], args[1], kw)
        self.artists.append(mark)
        return [mark]

    def fill(self, x: Any, y: Any, **kw: Any) -> list[Any]:
        from matplotlib.patches import Polygon

        patch = Polygon(np.column_stack([x, y]), closed=True, **kw)
        self.artists.append(patch)
        return [patch]

    def add_patch(self, patch: Any) -> Any:
        self.artists.append(patch)
        return patch

    def arrow(self, colour: Any, z: float, width: float) -> ArrowMark:
        """An arrow of this look (width in points), moved by its ``set(tail, head)``."""
        mark = ArrowMark(colour, z, width)
        self.artists.append(mark)
        return mark

    def __getattr__(self, name: str) -> Any:
        return getattr(self.ax, name)


def _rgba(c: Any) -> tuple[float, ...]:
    from matplotlib.colors import to_rgba

    return tuple(np.asarray(to_rgba(c), dtype=float).ravel()[:4])


def _polygon_key(a: Any) -> tuple[Any, ...]:
    """Everything of a Polygon's look: polygons with equal keys draw as one collection."""
    return ("polygon", _rgba(a.get_facecolor()), _rgba(a.get_edgecolor()), a.get_linewidth(),
            a.get_linestyle(), a.get_zorder(), a.get_alpha(), a.get_hatch(), a.get_fill())


def _labelled(a: Any) -> bool:
    if isinstance(a, ArrowMark):
        return False
    label = a.style.get("label") if isinstance(a, Mark) else a.get_label()
    return bool(label) and not str(label).startswith("_")


def _key(a: Any) -> tuple[Any, ...] | None:
    """The look of an artist that can join others (None: it stays alone)."""
    from matplotlib.patches import Polygon

    if isinstance(a, Mark):
        return a.key() + ((id(a),) if _labelled(a) else ())   # a legend entry stays alone
    if isinstance(a, ArrowMark):
        return a.key()
    if type(a) is Polygon and a.get_visible() and not _labelled(a):
        return _polygon_key(a)
    return None


def _joined_polygons(members: list[Any]) -> Any:
    from matplotlib.collections import PolyCollection

    p = members[0]
    return PolyCollection([m.get_xy() for m in members], closed=True,
                          facecolors=[p.get_facecolor()], edgecolors=[p.get_edgecolor()],
                          linewidths=[p.get_linewidth()], linestyles=[p.get_linestyle()],
                          zorder=p.get_zorder(), alpha=p.get_alpha(), hatch=p.get_hatch())


def _copy_line(line: Any, members: list[Mark]) -> None:
    """The marks' points joined by NaN (a break in a line, no marker) into one line."""
    if len(members) == 1:
        line.set_data(members[0].x, members[0].y)
        return
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    for m in members:
        x, y = np.asarray(m.x, dtype=float).ravel(), np.asarray(m.y, dtype=float).ravel()
        if len(x):
            xs += [x, _NAN]
            ys += [y, _NAN]
    line.set_data(np.concatenate(xs) if xs else [], np.concatenate(ys) if ys else [])


#: a batched arrow's head, in shaft widths (FancyArrowPatch's "-|>" at mutation scale 11 on a
#: 1.3 pt shaft: a head 4.4 pt long and wide, with its 1.3 pt outline about 5.7 pt)
HEAD = 4.4


def _put_arrows(ax: "Axes", members: list[ArrowMark]) -> Callable[[], None]:
    """One quiver for arrows of one look (tails and vectors in data units, widths in
    points); the function copying their tails and heads into it."""
    from matplotlib.quiver import Quiver

    m = members[0]
    zero = np.zeros(len(members))
    q = Quiver(ax, zero, zero, zero, zero, angles="xy", scale_units="xy", scale=1.0,
               units="inches", width=m.width / 72.0, headwidth=HEAD, headlength=HEAD,
               headaxislength=0.9 * HEAD, minlength=0.0, pivot="tail", color=m.colour,
               zorder=m.z)
    ax.add_collection(q, autolim=False)

    def copy() -> None:
        tails = np.array([a.tail for a in members], dtype=float)
        uv = np.array([a.head for a in members], dtype=float) - tails
        q.set_offsets(tails)
        q.set_UVC(uv[:, 0], uv[:, 1])
    return copy


def place(ax: "Axes", artists: list[Any], legend_max: int) -> Callable[[], None]:
    """Put recorded artists on the Axes, those of one look as one artist, in the order of
    their first member; the function returned copies the members' data into the joined
    artists (call it after each update).

    Labelled artists stay alone (they are legend entries) unless there are more than
    legend_max of them, when the legend is left out anyway and their labels are dropped.
    """
    labelled = [a for a in artists if _labelled(a)]
    if len(labelled) > legend_max:
        for a in labelled:
            if isinstance(a, Mark):
                a.style.pop("label")
            else:
                a.set_label(None)
    groups: dict[Any, list[Any]] = {}
    order: list[tuple[Any, Any]] = []
    for a in artists:
        k = _key(a)
        if k is None:
            order.append((None, a))
        elif k in groups:
            groups[k].append(a)
        else:
            groups[k] = [a]
            order.append((k, None))
    copies = [c for k, a in order if (c := _put(ax, groups[k] if k else [a])) is not None]

    def copy() -> None:
        for c in copies:
            c()
    return copy


def _put(ax: "Axes", members: list[Any]) -> Callable[[], None] | None:
    """One artist on the Axes for members of one look; the function copying their data
    into it (None for an artist that is its own)."""
    from matplotlib.lines import Line2D

    if isinstance(members[0], ArrowMark):
        return _put_arrows(ax, members)
    if isinstance(members[0], Mark):
        line = Line2D([], [], **members[0].style)
        _copy_line(line, members)
        ax.add_line(line)                       # the data limits grow as with ax.plot
        return lambda: _copy_line(line, members)
    if len(members) == 1:
        ax.add_patch(members[0])            # (the recorder keeps only patches besides marks)
        return None
    coll = _joined_polygons(members)
    ax.add_collection(coll)                     # the data limits grow as with add_patch
    return lambda: coll.set_verts([m.get_xy() for m in members])


__all__ = ["BATCH_MIN", "ArrowMark", "Mark", "Recorder", "place"]

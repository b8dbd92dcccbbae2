"""The mechanism picture: bodies at a few snapshots, traced paths, ground, guides, cams."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..description.joints import Cam, Revolute, Translational
from ..errors import ModelError
from ..validate import GROUND
from .canvas import (GROUND_COLOUR, PALETTE, STOP_COLOUR, import_matplotlib, new_figure,
                     shade)
from .contacts import contact_extent, draw_contacts
from .geometry import (Motion, Poses, TracePoint, body_axis, body_points, check_trace,
                       convex_hull, profile_points, slide_axis, snapshot_rows)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

_NPROFILE = 361  # points along a drawn cam profile


def plot_mechanism(result: Motion, times: Sequence[float] | None = None,
                   trace: Sequence[TracePoint] | None = None, ax: "Axes | None" = None,
                   title: str | None = None) -> "Axes":
    """Draw the mechanism at a few times, with the paths of traced points.

    Each body is drawn as the polygon (or line) through its attachment points in its own
    frame (origin, joint points, traced points), placed at each snapshot; earlier snapshots
    are lighter. Ground pivots are hatched triangles, translational guides a line along the
    axis, cam profiles the core's profile curve, roller followers circles, flat followers a
    face segment.

    Parameters
    ----------
    result : KinematicsResult
        The result to draw; it must carry its model (``result.model``). An incomplete result
        (``result.complete`` false, e.g. the ``.results`` of a
        :class:`~mbd2d.SingularConfigurationError`) has its last configuration drawn in red
        and labelled.
    times : sequence of float, optional
        Snapshot times; the nearest output rows are drawn. Default: six rows evenly spaced
        over the run.
    trace : sequence of (str, (float, float)), optional
        Points ``(body_name, (sx, sy))`` fixed in bodies whose global paths over the whole
        run are drawn (e.g. a coupler point).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new figure is made.
    title : str, optional
        Axes title; by default the model name and the time span.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ModelError
        (a ValueError) If the result has no rows or no model, a time is outside the run, or a
        trace entry names no body.
    """
    model = getattr(result, "model", None)
    if model is None:
        raise ModelError("the result carries no model (result.model is None); plot_mechanism "
                         "needs the joints to draw the bodies", "plot_mechanism")
    if len(result.t) == 0:
        raise ModelError("the result has no rows to draw", "plot_mechanism")
    tr = check_trace(result, trace)
    if ax is None:
        ax = new_figure((8.0, 6.5)).add_subplot()
    else:
        import_matplotlib()

    n = len(result.t)
    rows = snapshot_rows(result, times)
    snap = Poses(result, rows)
    full = Poses(result, np.arange(n))
    m = len(rows)
    stopped = not result.complete
    colours = {b.name: PALETTE[i % len(PALETTE)] for i, b in enumerate(model.bodies)}
    local = body_points(model, tr)
    cams = [j for j in model.joints if isinstance(j, Cam)]
    profiles = {c.name: profile_points(c, np.linspace(0.0, 2 * np.pi, _NPROFILE))
                for c in cams}

    # length scale: extent of everything that moves or is fixed, over the run
    extent = [full.place(b, s) for b, ss in local.items() for s in ss]
    for c in cams:
        pr = profiles[c.name]
        for k in np.unique(np.linspace(0, n - 1, 24).astype(int)):
            extent.append(full.place_many(c.bodies[0], pr, k))
    for j in model.joints:
        for body, s in zip(j.bodies, getattr(j, "points", ())):
            if body == GROUND:
                extent.append(np.array([s], dtype=float))
    extent += contact_extent(model, full, n)
    allp = np.vstack(extent)
    scale = float(max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1e-9))

    # a cam follower with no shape of its own (all its points coincide) gets a stem along
    # its slide axis, pointing away from the cam
    for c in cams:
        bc, bf = c.bodies
        if bf == GROUND or len(convex_hull(np.array(local[bf]))) != 1:
            continue
        v = np.array(slide_axis(model, bf) or (0.0, 0.0))
        if not v.any():
            continue
        v = v / np.hypot(*v)
        gv = full.turn(bf, v)[0]
        away = full.place(bf, c.follower[:2])[0] - full.place(bc, (0.0, 0.0))[0]
        if float(gv @ away) < 0.0:
            v = -v
        f = np.array(c.follower[:2], dtype=float)
        stem = 0.35 * scale + (c.follower[2] if c.follower_kind == "roller" else 0.0)
        local[bf].append(tuple(f + stem * v))

    def shade_of(body: str, k: int) -> Any:
        if stopped and k == m - 1:
            return STOP_COLOUR
        f = 1.0 if m == 1 else 0.25 + 0.75 * k / (m - 1)
        return shade(colours[body], f)

    last_normal = m - 2 if stopped else m - 1  # the snapshot that carries the labels

    def z(k: int) -> float:
        return 2.0 + k / max(m, 1)

    # ---- translational guides (a line along the axis of body i covering the slide)
    for j in model.joints:
        if not isinstance(j, Translational):
            continue
        bi, bj = j.bodies
        pi_, pj = full.place(bi, j.points[0]), full.place(bj, j.points[1])
        u = full.turn(bi, j.axes[0])
        u /= np.linalg.norm(u, axis=1)[:, None]
        s = np.einsum("ij,ij->i", pj - pi_, u)
        lo, hi = s.min() - 0.15 * scale, s.max() + 0.15 * scale
        if bi == GROUND:
            nrm = np.array([-u[0, 1], u[0, 0]])
            for side in (1.0, -1.0):
                off = side * 0.045 * scale * nrm
                a, b = pi_[0] + lo * u[0] + off, pi_[0] + hi * u[0] + off
                ax.plot([a[0], b[0]], [a[1], b[1]], color=GROUND_COLOUR, lw=1.8,
                        solid_capstyle="butt", zorder=1.0)
                _hatch_line(ax, a, b, scale, side * nrm)
        else:
            ps, us = snap.place(bi, j.points[0]), snap.turn(bi, j.axes[0])
            us /= np.linalg.norm(us, axis=1)[:, None]
            for k in range(m):
                a, b = ps[k] + lo * us[k], ps[k] + hi * us[k]
                ax.plot([a[0], b[0]], [a[1], b[1]], color=shade_of(bi, k), lw=1.2, ls="--",
                        zorder=z(k) - 0.5)

    # ---- traced paths over the whole run
    for i, (body, s) in enumerate(tr):
        path = result.point(body, s)
        ax.plot(path[:, 0], path[:, 1], color="k", lw=1.0, ls=(0, (4, 2)) if i else "-",
                alpha=0.8, zorder=1.5, label=f"path of {body} ({s[0]:g}, {s[1]:g})")

    # ---- bodies at the snapshots
    cam_bodies = {c.bodies[0] for c in cams}
    for body in [b.name for b in model.bodies]:
        hull = convex_hull(np.array(local[body]))
        axis = body_axis(model, body)
        for k in range(m):
            col = shade_of(body, k)
            label = body if k == last_normal else None
            if len(hull) >= 3:
                g = snap.place_many(body, hull, k)
                ax.fill(g[:, 0], g[:, 1], color=col, alpha=0.3 if k >= last_normal else 0.1,
                        lw=0, zorder=z(k))
                g = np.vstack([g, g[:1]])
                ax.plot(g[:, 0], g[:, 1], color=col, lw=2.0, zorder=z(k), label=label)
            elif len(hull) == 2:
                g = snap.place_many(body, hull, k)
                ax.plot(g[:, 0], g[:, 1], color=col, lw=3.5, solid_capstyle="round",
                        zorder=z(k), label=label)
            elif body not in cam_bodies:
                # a body with a single attachment point (a slider): a small block
                w, h = 0.10 * scale, 0.06 * scale
                blk = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
                c, sn = np.cos(axis), np.sin(axis)
                blk = blk @ np.array([[c, sn], [-sn, c]]) + hull[0]
                g = snap.place_many(body, blk, k)
                ax.fill(g[:, 0], g[:, 1], facecolor=shade(col, 0.45), edgecolor=col, lw=1.5,
                        zorder=z(k), label=label)
            o = snap.place(body, (0.0, 0.0))[k]
            ax.plot(*o, marker="+", ms=5, color=col, zorder=z(k) + 0.01)

    # ---- cams and followers
    shaped = {b for b in local if len(convex_hull(np.array(local[b]))) > 1}  # labelled above
    for c in cams:
        bc, bf = c.bodies
        pr = profiles[c.name]
        fpt = snap.place(bf, c.follower[:2])
        for k in range(m):
            col = shade_of(bc, k) if bc != GROUND else GROUND_COLOUR
            g = snap.place_many(bc, pr, k)
            ax.fill(g[:, 0], g[:, 1], color=col, alpha=0.25 if k >= last_normal else 0.07,
                    lw=0, zorder=z(k) - 0.2)
            lab = bc if (bc != GROUND and k == last_normal and bc not in shaped) else None
            ax.plot(g[:, 0], g[:, 1], color=col, lw=1.8, zorder=z(k) - 0.1, label=lab)
            fcol = shade_of(bf, k) if bf != GROUND else GROUND_COLOUR
            if c.follower_kind == "roller":
                r = c.follower[2]
                a = np.linspace(0.0, 2 * np.pi, 73)
                ax.plot(fpt[k, 0] + r * np.cos(a), fpt[k, 1] + r * np.sin(a), color=fcol,
                        lw=1.8, zorder=z(k) + 0.1)
            elif c.follower_kind == "flat":
                nrm = snap.turn(bf, c.follower[2:])[k]
                nrm /= np.linalg.norm(nrm)
                tan = np.array([-nrm[1], nrm[0]])
                half = 0.35 * scale
                a, b = fpt[k] - half * tan, fpt[k] + half * tan
                ax.plot([a[0], b[0]], [a[1], b[1]], color=fcol, lw=3.0,
                        solid_capstyle="butt", zorder=z(k) + 0.1)
            else:
                ax.plot(*fpt[k], marker="o", ms=4, color=fcol, zorder=z(k) + 0.1)
        ai = _alpha_column(result, c)
        if ai is not None:
            cp = np.vstack([snap.place_many(bc, profile_points(c, result.q[[r], ai]), k)
                            for k, r in enumerate(rows)])
            ax.plot(cp[:, 0], cp[:, 1], ls="none", marker="o", ms=3.5, mfc="k", mec="k",
                    zorder=z(m) + 0.2)

    # ---- contacts (bold while touching)
    draw_contacts(ax, model, snap, rows, result, shade_of, z, scale)

    # ---- joints: pins, ground pivots
    for j in model.joints:
        if not isinstance(j, Revolute):
            continue
        on_ground = GROUND in j.bodies
        for k in range(m):
            body = j.bodies[1] if j.bodies[0] == GROUND else j.bodies[0]
            s = j.points[j.bodies.index(body)]
            p = snap.place(body, s)[k]
            ax.plot(*p, marker="o", ms=5.5, mfc="white", mec=shade_of(body, k), mew=1.4,
                    zorder=z(k) + 0.3)
        if on_ground:
            g = np.asarray(j.points[j.bodies.index(GROUND)], dtype=float)
            _ground_pivot(ax, g, scale)

    # ---- traced points at the snapshots
    for body, s in tr:
        p = snap.place(body, s)
        for k in range(m):
            ax.plot(*p[k], marker="o", ms=4, color=shade_of(body, k), zorder=z(k) + 0.3)

    # ---- where an incomplete run stopped
    if stopped:
        t_last = result.t[-1]
        ax.plot([], [], color=STOP_COLOUR, lw=3,
                label=f"last configuration, t = {t_last:.6g} s (run stopped)")
        pts = [snap.place(b, s)[m - 1] for b, ss in local.items() for s in ss]
        top = max(pts, key=lambda p: p[1])
        ax.annotate(f"last configuration:\nrun stopped after t = {t_last:.6g} s",
                    xy=top, xytext=(0, 28), textcoords="offset points", ha="center",
                    va="bottom", color=STOP_COLOUR, fontsize=9,
                    arrowprops={"arrowstyle": "->", "color": STOP_COLOUR}, zorder=10)

    if title is None:
        span = f"t = {result.t[0]:.4g} .. {result.t[-1]:.4g} s"
        title = f"{model.name}: {m} snapshot{'s' if m > 1 else ''}, {span}"
    ax.set_title(title)
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.08)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.grid(True, lw=0.4, alpha=0.4)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    return ax


def _alpha_column(result: Motion, cam: Cam) -> int | None:
    name = f"{cam.name}.alpha"
    names = list(getattr(result, "coordinate_names", []))
    return names.index(name) if name in names else None


def _hatch_line(ax: "Axes", a: np.ndarray, b: np.ndarray, scale: float,
                nrm: np.ndarray) -> None:
    """Short hatch ticks on the nrm side of a fixed guide from a to b."""
    d = b - a
    length = float(np.hypot(*d))
    if length == 0.0:
        return
    u = d / length
    h = 0.025 * scale
    for s in np.arange(h, length + 1e-12, 2 * h):
        p = a + s * u
        q = p + h * nrm - h * u
        ax.plot([p[0], q[0]], [p[1], q[1]], color=GROUND_COLOUR, lw=0.8, zorder=0.9)


def _ground_pivot(ax: "Axes", g: np.ndarray, scale: float) -> None:
    """A hatched triangle under a ground pivot at g."""
    d = 0.035 * scale
    tri = np.array([g, g + [-d, -1.6 * d], g + [d, -1.6 * d]])
    ax.fill(tri[:, 0], tri[:, 1], facecolor="0.85", edgecolor=GROUND_COLOUR, lw=1.2,
            zorder=1.2)
    y0 = g[1] - 1.6 * d
    ax.plot([g[0] - 1.5 * d, g[0] + 1.5 * d], [y0, y0], color=GROUND_COLOUR, lw=1.5,
            zorder=1.2)
    for x in np.linspace(g[0] - 1.3 * d, g[0] + 1.5 * d, 5):
        ax.plot([x, x - 0.6 * d], [y0, y0 - 0.6 * d], color=GROUND_COLOUR, lw=0.8,
                zorder=1.2)

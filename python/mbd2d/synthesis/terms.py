"""Constraints and extra objective terms of a synthesis (the ``constraints=[...]`` list).

A term either rejects a candidate (a defect, with its reason) or adds penalty residuals
(weight * violation, zero while satisfied) with their exact derivatives:

- :class:`Grashof`: the four-bar type asked for (crank-rocker, double-crank, double-rocker,
  Grashof, non-Grashof) from the link lengths s + l <= p + q; a violation rejects.
- :class:`LinkRatio`: longest / shortest link <= max_ratio (penalty).
- :class:`TransmissionAngle`: the angle at a joint between the two links it joins stays
  within [min_deg, 180 - min_deg] over the input range (penalty on the worst deficit).
- :class:`PeakEffort`: the peak |effort| of a driver over the input range from inverse
  dynamics (a penalty above ``limit``, or a term to minimise when no limit is given);
  derivatives from the effort sensitivities.
- :class:`MeasureBound`: a mechanism measure (velocity ratio, mechanical advantage,
  dead-centre distance, transmission angle: a table's measure spec) within [min, max] over
  the input range (penalty on the worst excess); values and exact derivatives from the core.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import MbdError, ModelError
from ..binding.pack import pack
from ..results.measures import (measure, measure_tables, measures_and_derivatives,
                                parse_measure)
from ..validate import number
from .fourbar import loop_lengths
from .tasks import Rows, body_point

FOURBAR = ("O2", "A", "B", "O4")
GRASHOF_KINDS = ("crank-rocker", "double-crank", "double-rocker", "grashof", "non-grashof")


class Term:
    """Base class: no defect, no residual."""

    #: the term needs the input-range run with sensitivities ('kinematics'), inverse
    #: dynamics with sensitivities ('inverse'), or nothing
    needs: str | None = None

    def check(self, model: Any) -> None:
        """Refuse a term that does not fit the starting model (a ModelError), before any
        candidate runs."""

    def defects(self, ctx: Any) -> list[str]:
        return []

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(0), np.zeros((0, len(ctx.pnames)))

    def value(self, ctx: Any) -> float | None:
        """The quantity the term watches, for the report."""
        return None

    @property
    def label(self) -> str:
        """The term's name in the report (``SynthesisResult.terms``)."""
        return type(self).__name__


@dataclass
class Grashof(Term):
    """The Grashof type of a four-bar loop (joints O2, A, B, O4 by default: crank O2-A,
    coupler A-B, rocker B-O4, ground O4-O2). ``kind``: 'crank-rocker' (the crank is the
    shortest link and s + l <= p + q: it turns fully), 'double-crank' (the ground is the
    shortest), 'double-rocker' (the coupler is), 'grashof' (any of them), 'non-grashof'."""

    kind: str = "crank-rocker"
    joints: Sequence[str] = FOURBAR
    margin: float = 1e-3
    weight: float = 100.0

    def __post_init__(self) -> None:
        if self.kind not in GRASHOF_KINDS:
            raise ModelError(f"Grashof kind must be one of {', '.join(GRASHOF_KINDS)}, got "
                             f"{self.kind!r}", "constraints")

    def defects(self, ctx: Any) -> list[str]:
        lengths, _ = loop_lengths(ctx.model, self.joints, [])
        return grashof_defects(lengths, self.kind)

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        """While solving, the Grashof inequalities are penalties: weight * (g + margin *
        longest link) for each g <= 0 that is not met with that margin (s + l - p - q, and
        the asked-for link minus the shortest other one)."""
        lengths, d = loop_lengths(ctx.model, self.joints, ctx.pnames)
        g, dg = grashof_inequalities(lengths, d, self.kind)
        pad = self.margin * lengths.max()
        dpad = self.margin * d[int(np.argmax(lengths))]
        r = np.maximum(0.0, g + pad)
        active = (g + pad > 0)[:, None]
        return self.weight * r, self.weight * np.where(active, dg + dpad[None, :], 0.0)

    def value(self, ctx: Any) -> float:
        lengths, _ = loop_lengths(ctx.model, self.joints, [])
        s = np.sort(lengths)
        return float(s[0] + s[3] - s[1] - s[2])


def grashof_inequalities(lengths: np.ndarray, d: np.ndarray, kind: str
                         ) -> tuple[np.ndarray, np.ndarray]:
    """The Grashof conditions as g <= 0 with dg/dp: s + l - p - q <= 0 (or >= 0 for
    non-Grashof), and for a named type the asked-for link no longer than each other one."""
    order = np.argsort(lengths)
    sign = np.array([1.0, -1.0, -1.0, 1.0])
    g = [float(sign @ lengths[order])]
    dg = [sign @ d[order]]
    if kind == "non-grashof":
        return -np.array(g), -np.array(dg)
    which = {"crank-rocker": 1, "double-crank": 0, "double-rocker": 2}.get(kind)
    if which is not None:
        for k in range(4):
            if k != which:
                g.append(float(lengths[which] - lengths[k]))
                dg.append(d[which] - d[k])
    return np.array(g), np.array(dg)


def grashof_defects(lengths: np.ndarray, kind: str) -> list[str]:
    """Reasons why links (ground, crank, coupler, rocker) are not of the Grashof kind."""
    s = np.sort(lengths)
    excess = s[0] + s[3] - s[1] - s[2]
    tol = 1e-12 * s[3]
    if kind == "non-grashof":
        return [] if excess > tol else [f"Grashof defect: s + l - p - q = {excess:.3g} <= 0 "
                                        "(asked for a non-Grashof linkage)"]
    if excess > tol:
        return [f"Grashof defect: s + l - p - q = {excess:.3g} > 0 (not a Grashof linkage; "
                f"asked for {kind})"]
    which = {"crank-rocker": 1, "double-crank": 0, "double-rocker": 2}.get(kind)
    if which is not None and lengths[which] > s[0] * (1 + 1e-12):
        names = ("ground", "crank", "coupler", "rocker")
        return [f"Grashof defect: the shortest link is the {names[int(np.argmin(lengths))]}, "
                f"not the {names[which]} (asked for {kind})"]
    return []


@dataclass
class LinkRatio(Term):
    """Longest / shortest link of a four-bar loop at most ``max_ratio`` (penalty weight *
    excess)."""

    max_ratio: float = 10.0
    joints: Sequence[str] = FOURBAR
    weight: float = 1.0

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        lengths, d = loop_lengths(ctx.model, self.joints, ctx.pnames)
        i, j = int(np.argmax(lengths)), int(np.argmin(lengths))
        ratio = lengths[i] / lengths[j]
        if ratio <= self.max_ratio:
            return np.zeros(1), np.zeros((1, len(ctx.pnames)))
        dr = (d[i] * lengths[j] - d[j] * lengths[i]) / lengths[j]**2
        return np.array([self.weight * (ratio - self.max_ratio)]), self.weight * dr[None, :]

    def value(self, ctx: Any) -> float:
        lengths, _ = loop_lengths(ctx.model, self.joints, [])
        return float(lengths.max() / lengths.min())


def joint_position(model: Any, rows: Rows, joint: str, pnames: Sequence[str]
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Global position of a joint (its point on its first moving body, or on ground) at the
    rows: P (n, 2) and dP/dp (n, 2, np)."""
    table = {j.name: j for j in model.joints}
    if joint not in table or not hasattr(table[joint], "points"):
        raise ModelError(f"{joint!r} is not a joint with points", "constraints")
    j = table[joint]
    side = 0 if j.bodies[0] == "ground" else (1 if j.bodies[1] == "ground" else 0)
    s = j.points[side]
    n = len(rows.q)
    col = {name: k for k, name in enumerate(pnames)}
    if j.bodies[side] == "ground":
        p = np.tile(np.array(s, float), (n, 1))
        dp = np.zeros((n, 2, len(pnames)))
        for c in range(2):
            k = col.get(f"joint.{joint}.points.{side}.{c}")
            if k is not None:
                dp[:, c, k] = 1.0
        return p, dp
    p, dp, ds, _ = body_point(rows, j.bodies[side], s)
    assert dp is not None
    for c in range(2):
        k = col.get(f"joint.{joint}.points.{side}.{c}")
        if k is not None:
            dp[:, :, k] += ds[:, :, c]
    return p, dp


@dataclass
class TransmissionAngle(Term):
    """The angle at joint ``joints[1]`` between the lines to ``joints[0]`` and
    ``joints[2]`` (for a four-bar: the coupler-rocker angle at B) stays within
    [min_deg, 180 - min_deg] over the input range; penalty weight * worst deficit (radians
    times ``scale``, a length, default 1)."""

    min_deg: float = 40.0
    joints: Sequence[str] = ("A", "B", "O4")
    weight: float = 1.0
    needs = "kinematics"

    def _angles(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        rows = ctx.range_rows()
        pa, da = joint_position(ctx.model, rows, self.joints[0], ctx.pnames)
        pb, db = joint_position(ctx.model, rows, self.joints[1], ctx.pnames)
        pc, dc = joint_position(ctx.model, rows, self.joints[2], ctx.pnames)
        u, v = pa - pb, pc - pb
        du, dv = da - db, dc - db
        cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        dot = np.einsum("ij,ij->i", u, v)
        mu = np.arctan2(np.abs(cross), dot)                 # in [0, pi]
        dcross = (du[:, 0] * v[:, 1, None] + u[:, 0, None] * dv[:, 1]
                  - du[:, 1] * v[:, 0, None] - u[:, 1, None] * dv[:, 0])
        ddot = np.einsum("ijk,ij->ik", du, v) + np.einsum("ij,ijk->ik", u, dv)
        sgn = np.sign(cross)[:, None]
        r2 = (cross**2 + dot**2)[:, None]
        dmu = (dot[:, None] * sgn * dcross - np.abs(cross)[:, None] * ddot) / r2
        # the deviation from the best angle: min(mu, pi - mu)
        flip = mu > math.pi / 2
        mu_eff = np.where(flip, math.pi - mu, mu)
        dmu_eff = np.where(flip[:, None], -dmu, dmu)
        return mu_eff, dmu_eff

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        mu, dmu = self._angles(ctx)
        k = int(np.argmin(mu))
        deficit = math.radians(self.min_deg) - mu[k]
        if deficit <= 0:
            return np.zeros(1), np.zeros((1, len(ctx.pnames)))
        return np.array([self.weight * deficit]), -self.weight * dmu[k][None, :]

    def value(self, ctx: Any) -> float:
        return float(np.degrees(self._angles(ctx)[0].min()))


@dataclass
class PeakEffort(Term):
    """Peak |effort| of a driver over the input range (inverse dynamics; the model needs
    masses): with ``limit``, a penalty weight * (peak - limit) above it; without, the term
    weight * peak joins the objective."""

    driver: str = "motor"
    limit: float | None = None
    weight: float = 1.0
    needs = "inverse"

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        res = ctx.inverse_run()
        e = res.effort(self.driver)
        de = res.effort_dp(self.driver)
        k = int(np.argmax(np.abs(e)))
        peak = abs(e[k])
        grad = np.sign(e[k]) * de[k]
        if self.limit is None:
            return np.array([self.weight * peak]), self.weight * grad[None, :]
        if peak <= self.limit:
            return np.zeros(1), np.zeros((1, len(ctx.pnames)))
        return np.array([self.weight * (peak - self.limit)]), self.weight * grad[None, :]

    def value(self, ctx: Any) -> float:
        return float(np.abs(ctx.inverse_run().effort(self.driver)).max())


@dataclass
class MeasureBound(Term):
    """A mechanism measure within [min, max] over the input range: ``measure`` is a table's
    measure spec (``velocity_ratio:INPUT:OUTPUT[:VIA]``,
    ``mechanical_advantage:INPUT:OUTPUT[:VIA]``, ``dead_centre_distance``,
    ``transmission_angle:JOINT[:OUTPUT]`` in radians), its absolute value with ``absolute``
    (the default: a ratio's sign says only which way the output turns). Penalty weight *
    worst excess over the input range, with the measure's exact design derivatives from the
    core (:func:`mbd2d.results.measures.measure_derivatives`). While solving, rows where the
    measure is infinite (a ratio at its pole) are left out of the worst excess; in the
    screening and the final check an infinite excess rejects the candidate."""

    measure: str = "dead_centre_distance"
    min: float | None = None
    max: float | None = None
    absolute: bool = True
    weight: float = 1.0
    needs = "kinematics"

    def __post_init__(self) -> None:
        parse_measure(self.measure)
        if self.min is None and self.max is None:
            raise ModelError(f"the bound on {self.measure!r} needs min or max", "constraints")
        for key in ("min", "max"):
            v = getattr(self, key)
            if v is not None:
                setattr(self, key, number(v, key, "constraints"))
        if self.min is not None and self.max is not None and self.min > self.max:
            raise ModelError(f"the bound on {self.measure!r} has min {self.min} > max "
                             f"{self.max}", "constraints")
        if not isinstance(self.absolute, bool):
            raise ModelError(f"absolute must be true or false, got {self.absolute!r}",
                             "constraints")
        self.weight = number(self.weight, "weight", "constraints")
        if self.weight < 0:
            raise ModelError(f"weight must be >= 0, got {self.weight}", "constraints")

    def check(self, model: Any) -> None:
        """The measure's joints, drivers and coordinates are the model's (else the
        ModelError its spec raises on a result of this model)."""
        measure_tables(model, pack(model), [self.measure])

    def _excess(self, ctx: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The excess over the bounds at each row (> 0 violated), its derivatives, the
        (absolute) values and the times."""
        res = ctx.range_run()
        if ctx.pnames:
            v, d = measures_and_derivatives(res, [self.measure])
            v, d = v[:, 0], d[:, 0, :]
        else:
            v, d = measure(res, self.measure), np.zeros((len(res.t), 0))
        if self.absolute:
            d = np.sign(v)[:, None] * d
            v = np.abs(v)
        ex = np.full(len(v), -np.inf)
        dex = np.zeros_like(d)
        for bound, sign in ((self.min, -1.0), (self.max, 1.0)):
            if bound is None:
                continue
            e = sign * (v - bound)
            more = e > ex
            ex = np.where(more, e, ex)
            dex = np.where(more[:, None], sign * d, dex)
        return ex, dex, v, np.asarray(res.t)

    def defects(self, ctx: Any) -> list[str]:
        try:
            ex, _, _, t = self._excess(ctx)
        except MbdError:          # the candidate's own runs report why it fails
            return []
        bad = np.flatnonzero(np.isinf(ex) & (ex > 0))
        if not len(bad):
            return []
        return [f"{self.measure} is infinite at t = {t[bad[0]]:.6g} (bounded by max = "
                f"{self.max:.6g})"]

    def residuals(self, ctx: Any) -> tuple[np.ndarray, np.ndarray]:
        ex, dex, _, _ = self._excess(ctx)
        fin = np.isfinite(ex)
        if not fin.any() or ex[fin].max() <= 0:
            return np.zeros(1), np.zeros((1, len(ctx.pnames)))
        k = int(np.flatnonzero(fin)[np.argmax(ex[fin])])
        grad = np.where(np.isfinite(dex[k]), dex[k], 0.0)     # (no derivative: no slope)
        return np.array([self.weight * ex[k]]), self.weight * grad[None, :]

    @property
    def label(self) -> str:
        """``MeasureBound:SPEC`` (a design may bound several measures)."""
        return f"MeasureBound:{self.measure}"

    def value(self, ctx: Any) -> float:
        """The (absolute) measure where it comes nearest its bound, or beyond it."""
        ex, _, v, _ = self._excess(ctx)
        return float(v[int(np.argmax(np.where(np.isnan(ex), -np.inf, ex)))])


TERMS = {"grashof": Grashof, "link-ratio": LinkRatio, "transmission-angle": TransmissionAngle,
         "peak-effort": PeakEffort, "measure": MeasureBound}


def make_term(term_type: str, /, **keys: Any) -> Term:
    """A constraint by its task-file name and keys.

    Raises
    ------
    ModelError
        For an unknown kind or key.
    """
    if term_type not in TERMS:
        raise ModelError(f"unknown constraint {term_type!r}; known: {', '.join(TERMS)}",
                         "constraints")
    cls = TERMS[term_type]
    bad = set(keys) - set(cls.__dataclass_fields__)
    if bad:
        raise ModelError(f"unknown key(s) {sorted(bad)} of constraint {term_type!r}",
                         "constraints")
    try:
        return cls(**keys)
    except TypeError as exc:
        raise ModelError(f"constraint {term_type!r}: {exc}", "constraints") from None


__all__ = ["Term", "Grashof", "LinkRatio", "TransmissionAngle", "PeakEffort", "MeasureBound",
           "make_term",
           "grashof_defects", "joint_position", "TERMS"]

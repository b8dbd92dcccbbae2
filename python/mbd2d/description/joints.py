"""Joints: the constraint base class and every joint kind, each able to pack itself into the
flat table.

Every constraint class knows its kind code (``fortran/mbd_constraints.f90``), how many rows it
adds, what each row stands for, and its raw parameters. The numerics live in Fortran. Drivers
(:mod:`mbd2d.description.drivers`) are constraints too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, ClassVar, Mapping, Sequence

from ..errors import ModelError
from ..validate import as_list, nonzero_vector, only_keys, pairs, positive, table, vector
from .friction import Friction

PROFILE_KINDS = {"circle": 1, "spline": 2, "fourier": 3}
FOLLOWER_KINDS = {"point": 1, "roller": 2, "flat": 3}
COORDINATES = {"x": 1, "y": 2, "theta": 3}
PRESSURE_ANGLE = math.radians(20.0)   #: default gear pressure angle (radians)

BodyIndex = Callable[[str], int]

#: The words that end row labels (``NAME.WORD``), each with one meaning for every joint and
#: driver that uses it. A row's multiplier is the reaction along what the word names.
ROW_WORDS = {
    "x": "global x: two points coincide (revolute, weld, point or roller cam, point-on-curve), "
         "or a body's x is fixed or driven",
    "y": "global y, likewise",
    "theta": "a body's absolute angle is fixed or driven",
    "angle": "a relative angle theta_j - theta_i (translational, weld, relative-angle driver)",
    "normal": "a point's distance from a line or face along its normal (translational, "
              "point-on-line, revolute-translational, flat-faced cam, rolling disc)",
    "tangent": "a flat follower's face lies along the cam profile's tangent",
    "distance": "the distance between two points",
    "mesh": "the pitch circles of a gear pair roll on each other",
    "no_slip": "a pinion or disc rolls along its line without slip",
    "slide": "the slide along a translational joint (relative-distance driver)",
}


@dataclass
class Constraint:
    """Common part of joints and drivers: a name and two bodies ('ground' allowed)."""

    name: str
    bodies: tuple[str, str]

    type: ClassVar[str] = "constraint"
    kind: ClassVar[int] = 0
    labels: ClassVar[tuple[str, ...]] = ("",)
    #: row (0-based) whose constant is taken from the q0 estimates when ``phase`` is None
    phase_row: ClassVar[int | None] = None
    is_driver: ClassVar[bool] = False

    @property
    def nrow(self) -> int:
        """Number of equations."""
        return len(self.labels)

    def describe(self) -> str:
        """How messages name this entry."""
        return f"joint '{self.name}' ({self.type})"

    def rows(self) -> list[str]:
        """A label per equation: NAME.WORD, the word from :data:`ROW_WORDS`."""
        return [f"{self.name}.{label}" for label in self.labels]

    def raw(self) -> list[float]:
        """Raw parameters of the flat table."""
        raise NotImplementedError

    def raw_in(self, constraints: Sequence["Constraint"],
               q0: Mapping[str, Sequence[float]]) -> list[float]:
        """Raw parameters given the rest of the model (its constraints and the q0 estimates
        by body name, ground included); most constraints need neither."""
        return self.raw()

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        """Sub-kinds a and b of the flat table."""
        return 0, 0

    def extra_names(self) -> list[str]:
        """Names of the extra coordinates the constraint adds."""
        return []


@dataclass
class Revolute(Constraint):
    """Revolute joint: the two points coincide; optional friction (friction circle of the
    pin radius, :mod:`mbd2d.description.friction`)."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    friction: Friction | None = None
    type: ClassVar[str] = "revolute"
    kind: ClassVar[int] = 1
    labels: ClassVar[tuple[str, ...]] = ("x", "y")

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1]]


@dataclass
class Translational(Constraint):
    """Translational joint: point j stays on the line of body i; the axes stay parallel;
    optional friction (normal load from the normal row's multiplier)."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    axes: tuple[tuple[float, float], tuple[float, float]] = ((1.0, 0.0), (1.0, 0.0))
    friction: Friction | None = None
    type: ClassVar[str] = "translational"
    kind: ClassVar[int] = 2
    labels: ClassVar[tuple[str, ...]] = ("normal", "angle")

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1], *self.axes[0], *self.axes[1]]


@dataclass
class Cam(Constraint):
    """Cam: a profile on body 1 touching a follower on body 2; adds the contact parameter
    alpha as a coordinate."""

    profile_kind: str = "circle"
    profile: tuple[float, ...] = ()
    follower_kind: str = "point"
    follower: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    type: ClassVar[str] = "cam"
    kind: ClassVar[int] = 3

    @property
    def labels(self) -> tuple[str, ...]:  # type: ignore[override]
        return ("normal", "tangent") if self.follower_kind == "flat" else ("x", "y")

    def raw(self) -> list[float]:
        return [*self.follower, *self.profile]

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        return PROFILE_KINDS[self.profile_kind], FOLLOWER_KINDS[self.follower_kind]

    def extra_names(self) -> list[str]:
        return [f"{self.name}.alpha"]


@dataclass
class PointOnCurve(Cam):
    """A point of body 2 on a closed curve of body 1 (a pin in a curved slot)."""

    type: ClassVar[str] = "point-on-curve"


@dataclass
class Distance(Constraint):
    """Distance (revolute-revolute composite): |P_j - P_i| = distance."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    distance: float = 1.0
    type: ClassVar[str] = "distance"
    kind: ClassVar[int] = 4
    labels: ClassVar[tuple[str, ...]] = ("distance",)

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1], self.distance]


@dataclass
class PointOnLine(Constraint):
    """A point of body 2 on a line of body 1 (at a signed offset from it)."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    axis: tuple[float, float] = (1.0, 0.0)
    offset: float = 0.0
    type: ClassVar[str] = "point-on-line"
    kind: ClassVar[int] = 5
    labels: ClassVar[tuple[str, ...]] = ("normal",)

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1], *self.axis, self.offset]


@dataclass
class PinInSlot(PointOnLine):
    """Revolute-translational composite: a pin of body 2 in a straight slot of body 1."""

    type: ClassVar[str] = "revolute-translational"


@dataclass
class Weld(Constraint):
    """Weld: the points coincide and the relative angle theta_j - theta_i is fixed."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    angle: float = 0.0
    type: ClassVar[str] = "weld"
    kind: ClassVar[int] = 6
    labels: ClassVar[tuple[str, ...]] = ("x", "y", "angle")

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1], self.angle]


@dataclass
class Gear(Constraint):
    """Gear pair on a common carrier: R_i (th_i - th_c) +/- R_j (th_j - th_c) = phase, with the
    tooth force at the pitch point, along the line of action (``pressure_angle``, radians), as
    its reaction (fortran/mbd_joint_gear.f90).

    The gear centres are ``centers`` (in each gear's frame) or, by default, the points of the
    revolute joints that pin the gears to the carrier (the body origin when there is none);
    where they sit in the carrier comes from those revolutes too, else from the q0 estimates.
    """

    radii: tuple[float, float] = (1.0, 1.0)
    internal: bool = False
    carrier: str = "ground"
    phase: float | None = None
    pressure_angle: float = PRESSURE_ANGLE
    centers: tuple[tuple[float, float], tuple[float, float]] | None = None
    type: ClassVar[str] = "gear"
    kind: ClassVar[int] = 7
    labels: ClassVar[tuple[str, ...]] = ("mesh",)

    def raw(self) -> list[float]:
        # the centres at the body origins, on the x axis of the carrier
        d = self.radii[1] - self.radii[0] if self.internal else sum(self.radii)
        return [*self.radii, self.phase or 0.0, self.pressure_angle, 0.0, 0.0, 0.0, 0.0,
                0.0, 0.0, d, 0.0]

    def raw_in(self, constraints: Sequence[Constraint],
               q0: Mapping[str, Sequence[float]]) -> list[float]:
        ci, ai = self._centre(0, constraints, q0)
        cj, aj = self._centre(1, constraints, q0)
        sgn = -1.0 if self.internal else 1.0
        tc = q0[self.carrier][2]
        phase = self.phase
        if phase is None:       # the teeth mesh as drawn
            phase = (self.radii[0] * (q0[self.bodies[0]][2] - tc)
                     + sgn * self.radii[1] * (q0[self.bodies[1]][2] - tc))
        return [*self.radii, phase, self.pressure_angle, *ci, *cj, *ai, *aj]

    def _centre(self, k: int, constraints: Sequence[Constraint],
                q0: Mapping[str, Sequence[float]]) -> tuple[tuple[float, float], ...]:
        """Centre of gear k in its own frame and in the carrier frame."""
        gear, carrier = self.bodies[k], self.carrier
        given = None if self.centers is None else self.centers[k]
        for c in constraints:
            if isinstance(c, Revolute) and set(c.bodies) == {gear, carrier}:
                g = c.bodies.index(gear)
                if given is None or tuple(given) == tuple(c.points[g]):
                    return c.points[g], c.points[1 - g]
        own = (0.0, 0.0) if given is None else given
        # as drawn: C = r_g + A_g c', then A_c^T (C - r_c)
        xg, yg, tg = q0[gear]
        xc, yc, tc = q0[carrier]
        cx = xg + math.cos(tg) * own[0] - math.sin(tg) * own[1] - xc
        cy = yg + math.sin(tg) * own[0] + math.cos(tg) * own[1] - yc
        return own, (math.cos(tc) * cx + math.sin(tc) * cy,
                     -math.sin(tc) * cx + math.cos(tc) * cy)

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        return body_index(self.carrier), 2 if self.internal else 1


@dataclass
class RackPinion(Constraint):
    """Rack and pinion: the pinion (body 1) rolls without slip along the rack line (body 2)."""

    center: tuple[float, float] = (0.0, 0.0)
    point: tuple[float, float] = (0.0, 0.0)
    axis: tuple[float, float] = (1.0, 0.0)
    radius: float = 1.0
    phase: float | None = None
    type: ClassVar[str] = "rack-pinion"
    kind: ClassVar[int] = 8
    labels: ClassVar[tuple[str, ...]] = ("no_slip",)
    phase_row: ClassVar[int | None] = 0

    def raw(self) -> list[float]:
        return [*self.center, *self.point, *self.axis, self.radius, self.phase or 0.0]


@dataclass
class RollingDisc(RackPinion):
    """A disc (body 1) rolling without slip on a line (body 2): contact and no slip."""

    type: ClassVar[str] = "rolling-disc"
    kind: ClassVar[int] = 9
    labels: ClassVar[tuple[str, ...]] = ("no_slip", "normal")


@dataclass
class Absolute(Constraint):
    """Absolute constraint: x, y or theta of a body is fixed."""

    coordinate: str = "x"
    value: float = 0.0
    type: ClassVar[str] = "absolute"
    kind: ClassVar[int] = 10

    @property
    def labels(self) -> tuple[str, ...]:  # type: ignore[override]
        return (self.coordinate,)

    def raw(self) -> list[float]:
        return [self.value]

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        return COORDINATES[self.coordinate], 0


def parse_profile(spec: Any, entry: str, key: str = "profile") -> tuple[str, tuple[float, ...]]:
    """A closed profile curve: ``{circle = ...}``, ``{spline = ...}`` or ``{fourier = ...}``."""
    spec = table(spec, key, entry)
    if len(spec) != 1 or next(iter(spec)) not in PROFILE_KINDS:
        raise ModelError(f"{key} must be one of {{circle = ...}}, {{spline = ...}}, "
                         f"{{fourier = ...}}, got keys {sorted(map(str, spec))}", entry)
    kind, body = next(iter(spec.items()))
    body = table(body, f"{key}.{kind}", entry)
    if kind == "circle":
        only_keys(body, {"center", "radius"}, f"{entry} {key}.circle", ["center", "radius"])
        c = vector(body["center"], 2, f"{key}.circle.center", entry)
        r = positive(body["radius"], f"{key}.circle.radius", entry)
        return kind, (*c, r)
    if kind == "spline":
        only_keys(body, {"points"}, f"{entry} {key}.spline", ["points"])
        pts = as_list(body["points"])
        if isinstance(pts, (str, bytes)) or not isinstance(pts, Sequence) or len(pts) < 4:
            raise ModelError(f"{key}.spline.points must be a list of at least 4 [x, y] points "
                             "around the closed curve", entry)
        pp = pairs(pts, len(pts), f"{key}.spline.points", entry)
        return kind, (float(len(pp)), *[v for p in pp for v in p])
    only_keys(body, {"center", "a", "b"}, f"{entry} {key}.fourier", ["a"])
    c = vector(body.get("center", [0.0, 0.0]), 2, f"{key}.fourier.center", entry)
    a = as_list(body["a"])
    if isinstance(a, (str, bytes)) or not isinstance(a, Sequence) or len(a) < 1:
        raise ModelError(f"{key}.fourier.a must be a list [a0, a1, ...]", entry)
    av = vector(a, len(a), f"{key}.fourier.a", entry)
    k = len(av) - 1
    b = as_list(body.get("b", [0.0] * k))
    if isinstance(b, (str, bytes)) or not isinstance(b, Sequence):
        raise ModelError(f"{key}.fourier.b must be a list [b1, ..., bK]", entry)
    bv = vector(b, len(b), f"{key}.fourier.b", entry)
    if len(bv) == k + 1:
        if bv[0] != 0.0:
            raise ModelError(f"{key}.fourier.b has a b0 term; sin(0) = 0, so give [b1, ...]",
                             entry)
        bv = bv[1:]
    if len(bv) > k:
        k = len(bv)
        av = av + (0.0,) * (k + 1 - len(av))
    bv = bv + (0.0,) * (k - len(bv))
    if not av[0] > 0.0:
        raise ModelError(f"{key}.fourier.a[0] (the mean radius) must be positive", entry)
    coeffs = [v for i in range(1, k + 1) for v in (av[i], bv[i - 1])]
    return "fourier", (*c, float(k), av[0], *coeffs)


def encoded_profile_problem(kind: str, p: Sequence[float]) -> str:
    """What is wrong with the encoding parse_profile gives (circle (cx, cy, r); spline (n,
    x1, y1, ..., xn, yn), n >= 4; fourier (cx, cy, k, a0, a1, b1, ..., ak, bk)), "" if
    nothing (the numbers themselves checked elsewhere)."""
    n = len(p)
    if kind == "circle":
        return "" if n == 3 else "of a circle must be (center x, center y, radius)"
    if kind == "spline":
        ok = n >= 9 and float(p[0]) == (n - 1) // 2 and n % 2 == 1
        return "" if ok else "of a spline must be (n, x1, y1, ..., xn, yn), n >= 4"
    ok = n >= 4 and float(p[2]) == (n - 4) // 2 and n % 2 == 0
    return "" if ok else "of a Fourier curve must be (cx, cy, k, a0, a1, b1, ..., ak, bk)"


def parse_follower(spec: Any, entry: str) -> tuple[str, tuple[float, float, float, float]]:
    """A follower: ``{point = [x, y]}``, ``{roller = ...}`` or ``{flat = ...}``."""
    spec = table(spec, "follower", entry)
    if len(spec) != 1 or next(iter(spec)) not in FOLLOWER_KINDS:
        raise ModelError(f"follower must be one of {{point = [x, y]}}, {{roller = ...}}, "
                         f"{{flat = ...}}, got keys {sorted(map(str, spec))}", entry)
    kind, body = next(iter(spec.items()))
    if kind == "point":
        p = vector(body, 2, "follower.point", entry)
        return kind, (p[0], p[1], 0.0, 0.0)
    body = table(body, f"follower.{kind}", entry)
    if kind == "roller":
        only_keys(body, {"center", "radius"}, entry + " follower.roller", ["center", "radius"])
        c = vector(body["center"], 2, "follower.roller.center", entry)
        return kind, (c[0], c[1], positive(body["radius"], "follower.roller.radius", entry), 0.0)
    only_keys(body, {"point", "normal"}, entry + " follower.flat", ["point", "normal"])
    p = vector(body["point"], 2, "follower.flat.point", entry)
    n = nonzero_vector(body["normal"], "follower.flat.normal", entry)
    return kind, (p[0], p[1], n[0], n[1])


def joint_keys() -> Mapping[str, tuple[set[str], set[str]]]:
    """TOML keys of each joint type: (allowed, required)."""
    return {
        "revolute": ({"bodies", "points", "friction", "pin_radius"}, {"bodies", "points"}),
        "translational": ({"bodies", "points", "axes", "friction"},
                          {"bodies", "points", "axes"}),
        "cam": ({"bodies", "profile", "follower"}, {"bodies", "profile", "follower"}),
        "point-on-curve": ({"bodies", "curve", "point"}, {"bodies", "curve", "point"}),
        "distance": ({"bodies", "points", "distance"}, {"bodies", "points", "distance"}),
        "point-on-line": ({"bodies", "points", "axis", "offset"}, {"bodies", "points", "axis"}),
        "revolute-translational": ({"bodies", "points", "axis", "offset"},
                                   {"bodies", "points", "axis"}),
        "weld": ({"bodies", "points", "angle"}, {"bodies", "points"}),
        "gear": ({"bodies", "radii", "internal", "carrier", "phase", "pressure_angle",
                  "centers"}, {"bodies", "radii"}),
        "rack-pinion": ({"bodies", "center", "point", "axis", "radius", "phase"},
                        {"bodies", "center", "point", "axis", "radius"}),
        "rolling-disc": ({"bodies", "center", "point", "axis", "radius", "phase"},
                         {"bodies", "center", "point", "axis", "radius"}),
        "absolute": ({"body", "coordinate", "value"}, {"body", "coordinate"}),
    }

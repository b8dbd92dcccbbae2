"""The model: bodies, joints, drivers, and the builder API.

A model is built either in code::

    m = Model("four-bar")
    m.add_body("crank", q0=[0.75, 1.3, 1.047])
    m.add_revolute(["ground", "crank"], [[0, 0], [-1.5, 0]], name="O2")
    ...
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [1.047, 1.0]})

or from TOML with :func:`mbd2d.load`, which calls the same methods.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from .errors import ModelError
from .functions import TimeFunction, as_function
from .validate import (GROUND, as_list, check_name, choice, nonzero_vector, only_keys, pairs,
                       positive, table, vector)

if TYPE_CHECKING:  # pragma: no cover
    from .results import KinematicsResult

# kind codes of the flat table (mbd_constraints.f90)
REVOLUTE, TRANSLATIONAL, CAM = 1, 2, 3
DRV_ABS, DRV_REL_ANGLE, DRV_REL_DIST = 101, 102, 103
PROFILE_KINDS = {"circle": 1, "spline": 2, "fourier": 3}
FOLLOWER_KINDS = {"point": 1, "roller": 2, "flat": 3}
COORDINATES = {"x": 1, "y": 2, "theta": 3}


@dataclass
class Body:
    """A moving rigid body; its origin is its centre of mass.

    Parameters
    ----------
    name : str
        Unique name.
    q0 : tuple of float
        Rough estimate of (x, y, theta); assembly refines it.
    mass, inertia : float or None
        Mass and moment of inertia about the centre of mass (dynamics only).
    """

    name: str
    q0: tuple[float, float, float]
    mass: float | None = None
    inertia: float | None = None


@dataclass
class Constraint:
    """Common part of joints and drivers."""

    name: str
    bodies: tuple[str, str]

    type = "constraint"
    nrow = 1

    def describe(self) -> str:
        """How messages name this entry."""
        return f"{self.type} '{self.name}'"

    def rows(self) -> list[str]:
        """What each of its equations stands for."""
        return [f"{self.name}"] * self.nrow


@dataclass
class Revolute(Constraint):
    """Revolute joint: the two points coincide (2 equations)."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    type = "revolute"
    nrow = 2

    def pack(self) -> tuple[int, int, int, list[float]]:
        """Kind, sub-kinds and raw parameters of the flat table."""
        return REVOLUTE, 0, 0, [*self.points[0], *self.points[1]]

    def rows(self) -> list[str]:
        return [f"{self.name}.x", f"{self.name}.y"]


@dataclass
class Translational(Constraint):
    """Translational joint: point j stays on the line of body i; axes stay parallel."""

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    axes: tuple[tuple[float, float], tuple[float, float]] = ((1.0, 0.0), (1.0, 0.0))
    type = "translational"
    nrow = 2

    def pack(self) -> tuple[int, int, int, list[float]]:
        """Kind, sub-kinds and raw parameters of the flat table."""
        return TRANSLATIONAL, 0, 0, [*self.points[0], *self.points[1],
                                     *self.axes[0], *self.axes[1]]

    def rows(self) -> list[str]:
        return [f"{self.name}.normal", f"{self.name}.angle"]


@dataclass
class Cam(Constraint):
    """Cam profile on body 1 in contact with a follower on body 2 (2 equations, 1 extra
    coordinate: the contact parameter alpha)."""

    profile_kind: str = "circle"
    profile: tuple[float, ...] = ()
    follower_kind: str = "point"
    follower: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    type = "cam"
    nrow = 2

    def pack(self) -> tuple[int, int, int, list[float]]:
        """Kind, sub-kinds and raw parameters of the flat table."""
        return (CAM, PROFILE_KINDS[self.profile_kind], FOLLOWER_KINDS[self.follower_kind],
                [*self.follower, *self.profile])

    def rows(self) -> list[str]:
        if self.follower_kind == "flat":
            return [f"{self.name}.on_face", f"{self.name}.tangent"]
        return [f"{self.name}.x", f"{self.name}.y"]


@dataclass
class Driver(Constraint):
    """A driving constraint g(q) - f(t) = 0."""

    f: TimeFunction = TimeFunction()
    driver_type: str = "absolute"
    coordinate: str = "theta"
    joint: str | None = None
    type = "driver"

    def describe(self) -> str:
        return f"driver '{self.name}'"


class Model:
    """A planar multibody model.

    Parameters
    ----------
    name : str
        Model name (used in plots and exported files).
    gravity : sequence of float
        Gravity vector (dynamics only).

    Examples
    --------
    >>> m = Model("pendulum")
    >>> _ = m.add_body("bar", q0=[0.5, 0.0, 0.0])
    >>> _ = m.add_revolute(["ground", "bar"], [[0, 0], [-0.5, 0]])
    >>> _ = m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0.0, 1.0]})
    >>> m.counts()
    (3, 3)
    """

    def __init__(self, name: str = "model", gravity: Sequence[float] = (0.0, -9.81)) -> None:
        self.name = str(name)
        self.gravity = vector(gravity, 2, "gravity", "[model]")
        self.bodies: list[Body] = []
        self.joints: list[Constraint] = []
        self.drivers: list[Driver] = []

    # ------------------------------------------------------------------ lookups
    def body_index(self, name: str, entry: str, allow_ground: bool = True) -> int:
        """1-based index of a body, 0 for ground."""
        if name == GROUND and allow_ground:
            return 0
        for i, b in enumerate(self.bodies):
            if b.name == name:
                return i + 1
        known = ", ".join(b.name for b in self.bodies) or "(none yet)"
        hint = " (ground is not allowed here)" if name == GROUND else ""
        raise ModelError(f"unknown body {name!r}{hint}; bodies are: ground, {known}", entry)

    def body(self, name: str) -> Body:
        """The body called name."""
        return self.bodies[self.body_index(name, f"body {name!r}", allow_ground=False) - 1]

    @property
    def constraints(self) -> list[Constraint]:
        """Joints then drivers, the order of the rows of Phi."""
        return [*self.joints, *self.drivers]

    def _names(self) -> set[str]:
        return {b.name for b in self.bodies} | {c.name for c in self.constraints}

    def _new_name(self, name: str | None, stem: str, entry: str) -> str:
        if name is None:
            k = len(self.constraints) + 1
            name = f"{stem}{k}"
            while name in self._names():
                k += 1
                name = f"{stem}{k}"
            return name
        check_name(name, entry)
        if name == GROUND or name in self._names():
            raise ModelError(f"duplicate name {name!r}: every body, joint and driver needs its "
                             "own name ('ground' is reserved)", entry)
        return name

    def _two_bodies(self, bodies: Any, entry: str) -> tuple[str, str]:
        bodies = as_list(bodies)
        if isinstance(bodies, (str, bytes)) or not isinstance(bodies, Sequence) \
                or len(bodies) != 2:
            raise ModelError(f"bodies must be a list of two names, got {bodies!r}", entry)
        for b in bodies:
            if not isinstance(b, str):
                raise ModelError(f"bodies must be names (strings), got {b!r}", entry)
            self.body_index(b, entry)
        if bodies[0] == bodies[1]:
            raise ModelError(f"a body cannot be joined to itself ({bodies[0]!r} twice)", entry)
        return (bodies[0], bodies[1])

    # ------------------------------------------------------------------ builder
    def add_body(self, name: str, q0: Sequence[float], mass: float | None = None,
                 inertia: float | None = None) -> Body:
        """Add a moving body.

        Parameters
        ----------
        name : str
            Unique name (not 'ground').
        q0 : sequence of 3 float
            Rough estimate of x, y, theta of the centre of mass.
        mass, inertia : float, optional
            Needed only for dynamics.

        Returns
        -------
        Body

        Raises
        ------
        ModelError
            On a duplicate or invalid name, or a malformed q0.
        """
        entry = f"body {name!r}" if isinstance(name, str) else f"body #{len(self.bodies) + 1}"
        check_name(name, entry)
        if name == GROUND or name in self._names():
            raise ModelError(f"duplicate name {name!r}: every body, joint and driver needs its "
                             "own name ('ground' is reserved)", entry)
        q = vector(q0, 3, "q0", entry)
        m = None if mass is None else positive(mass, "mass", entry)
        j = None if inertia is None else positive(inertia, "inertia", entry)
        b = Body(name, q, m, j)  # type: ignore[arg-type]
        self.bodies.append(b)
        return b

    def add_revolute(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                     name: str | None = None) -> Revolute:
        """Add a revolute joint: points[0] on bodies[0] coincides with points[1] on bodies[1].

        Points are in each body's frame (a ground point is global).
        """
        entry = self._entry("revolute", name)
        name = self._new_name(name, "revolute", entry)
        entry = f"joint {name!r} (revolute)"
        j = Revolute(name, self._two_bodies(bodies, entry), pairs(points, 2, "points", entry))
        self.joints.append(j)
        return j

    def add_translational(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                          axes: Sequence[Sequence[float]],
                          name: str | None = None) -> Translational:
        """Add a translational joint.

        The point on bodies[1] slides along the line through points[0] with direction
        axes[0] fixed in bodies[0]; axes[1] (in bodies[1]) stays parallel to axes[0].
        """
        entry = self._entry("translational", name)
        name = self._new_name(name, "translational", entry)
        entry = f"joint {name!r} (translational)"
        bb = self._two_bodies(bodies, entry)
        pts = pairs(points, 2, "points", entry)
        axes = as_list(axes)
        if isinstance(axes, (str, bytes)) or not isinstance(axes, Sequence) or len(axes) != 2:
            raise ModelError(f"axes must be a list of two [x, y] directions, got {axes!r}", entry)
        ax = (nonzero_vector(axes[0], "axes[0]", entry), nonzero_vector(axes[1], "axes[1]", entry))
        j = Translational(name, bb, pts, ax)
        self.joints.append(j)
        return j

    def add_cam(self, bodies: Sequence[str], profile: Mapping[str, Any],
                follower: Mapping[str, Any], name: str | None = None) -> Cam:
        """Add a cam: a profile on bodies[0] touching a follower on bodies[1].

        Parameters
        ----------
        bodies : [cam, follower]
        profile : mapping
            ``{circle = {center, radius}}``, ``{spline = {points = [[x, y], ...]}}`` or
            ``{fourier = {center, a = [a0, a1, ...], b = [b1, ...]}}`` (polar
            r(alpha) = a0 + sum a_k cos k alpha + b_k sin k alpha), in the cam's frame.
        follower : mapping
            ``{point = [x, y]}``, ``{roller = {center, radius}}`` or
            ``{flat = {point, normal}}`` (normal pointing toward the cam), in the follower's frame.
        """
        entry = self._entry("cam", name)
        name = self._new_name(name, "cam", entry)
        entry = f"joint {name!r} (cam)"
        bb = self._two_bodies(bodies, entry)
        pkind, pparams = _profile(profile, entry)
        fkind, fparams = _follower(follower, entry)
        j = Cam(name, bb, pkind, pparams, fkind, fparams)
        self.joints.append(j)
        return j

    def add_joint(self, type: str, **kw: Any) -> Constraint:
        """Add a joint by type name with the TOML keys as keyword arguments."""
        builders = {"revolute": (self.add_revolute, {"bodies", "points", "name"}),
                    "translational": (self.add_translational,
                                      {"bodies", "points", "axes", "name"}),
                    "cam": (self.add_cam, {"bodies", "profile", "follower", "name"})}
        entry = self._entry(str(type), kw.get("name"))
        if not isinstance(type, str) or type not in builders:
            raise ModelError(f"unknown joint type {type!r}; known: {sorted(builders)}", entry)
        fn, allowed = builders[type]
        only_keys(kw, allowed, entry, required=[k for k in allowed if k != "name"])
        return fn(**kw)

    def add_driver(self, type: str, f: Any, name: str | None = None, body: str | None = None,
                   coordinate: str | None = None, bodies: Sequence[str] | None = None,
                   joint: str | None = None) -> Driver:
        """Add a driving constraint g(q) = f(t).

        Parameters
        ----------
        type : {'absolute', 'relative-angle', 'relative-distance'}
            absolute: ``coordinate`` ('x', 'y', 'theta') of ``body``;
            relative-angle: theta_j - theta_i of ``bodies = [i, j]``;
            relative-distance: the slide along the translational ``joint``.
        f : number, mapping or TimeFunction
            ``{poly = [c0, c1, ...], harmonic = [{amplitude, omega, phase}]}``.
        """
        entry = self._entry("driver", name)
        name = self._new_name(name, "driver", entry)
        entry = f"driver {name!r}"
        fun = as_function(f, entry)
        if type == "absolute":
            if body is None or coordinate is None or bodies is not None or joint is not None:
                raise ModelError("an absolute driver needs 'body' and 'coordinate' (and not "
                                 "'bodies' or 'joint')", entry)
            if not isinstance(body, str):
                raise ModelError(f"body must be a name, got {body!r}", entry)
            self.body_index(body, entry, allow_ground=False)
            choice(coordinate, COORDINATES, "coordinate", entry)
            d = Driver(name, (body, GROUND), fun, "absolute", coordinate)
        elif type == "relative-angle":
            if bodies is None or body is not None or coordinate is not None or joint is not None:
                raise ModelError("a relative-angle driver needs 'bodies' = [i, j] (theta_j - "
                                 "theta_i = f(t)) and no 'body', 'coordinate' or 'joint'", entry)
            d = Driver(name, self._two_bodies(bodies, entry), fun, "relative-angle")
        elif type == "relative-distance":
            if joint is None or body is not None or bodies is not None or coordinate is not None:
                raise ModelError("a relative-distance driver needs 'joint' (a translational "
                                 "joint) and no 'body', 'bodies' or 'coordinate'", entry)
            target = next((j for j in self.joints if j.name == joint), None)
            if target is None:
                raise ModelError(f"unknown joint {joint!r}; joints are: "
                                 f"{', '.join(j.name for j in self.joints) or '(none)'}", entry)
            if not isinstance(target, Translational):
                raise ModelError(f"joint {joint!r} is a {target.type} joint; a "
                                 "relative-distance driver needs a translational joint", entry)
            d = Driver(name, target.bodies, fun, "relative-distance", joint=joint)
        else:
            raise ModelError(f"unknown driver type {type!r}; use 'absolute', 'relative-angle' "
                             "or 'relative-distance'", entry)
        self.drivers.append(d)
        return d

    def _entry(self, kind: str, name: Any) -> str:
        """How messages name an entry being added (before its name is settled)."""
        if kind == "driver":
            return f"driver {name!r}" if isinstance(name, str) \
                else f"driver #{len(self.drivers) + 1}"
        return f"joint {name!r} ({kind})" if isinstance(name, str) \
            else f"joint #{len(self.joints) + 1} ({kind})"

    # ------------------------------------------------------------------ sizes
    def counts(self) -> tuple[int, int]:
        """(number of equations, number of coordinates)."""
        from .pack import pack
        p = pack(self)
        return p.neq, p.nq

    @property
    def coordinate_names(self) -> list[str]:
        """Names of the entries of q: NAME.x, NAME.y, NAME.theta per body, then extras."""
        from .pack import pack
        return pack(self).coordinate_names

    def constraint_rows(self) -> list[str]:
        """A label for each row of Phi: the joint or driver name and the equation."""
        return [r for c in self.constraints for r in c.rows()]

    # ------------------------------------------------------------------ analyses
    def kinematics(self, t_end: float, steps: int, t0: float = 0.0, tol: float | None = None,
                   maxit: int | None = None) -> "KinematicsResult":
        """Kinematic analysis at steps + 1 uniform times from t0 to t_end.

        The whole time loop runs in the Fortran core. Assembly refines the q0 estimates at t0.

        Parameters
        ----------
        t_end : float
            Final time.
        steps : int
            Number of intervals; the result has steps + 1 rows.
        t0 : float
            Start time.
        tol : float, optional
            Newton tolerance on ||Phi||_inf relative to the model's length scale
            (default 1e-12).
        maxit : int, optional
            Newton iterations per step (default 25).

        Returns
        -------
        KinematicsResult

        Raises
        ------
        ModelError
            If the model is malformed or not kinematically determined.
        SingularConfigurationError
            At a dead centre; carries the results up to it (``err.results``).
        AssemblyError, ConvergenceError, SingularJacobianError
            On other numerical failures.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=10)
        >>> res.q.shape[0]
        11
        """
        from .analysis import run_kinematics
        return run_kinematics(self, t_end=t_end, steps=steps, t0=t0, tol=tol, maxit=maxit)

    def phi(self, q: Any, t: float = 0.0) -> np.ndarray:
        """Phi(q, t), computed by the core."""
        from .analysis import evaluate
        return evaluate(self, q, None, t)[0]

    def jacobian(self, q: Any, t: float = 0.0) -> np.ndarray:
        """J = Phi_q(q, t), computed by the core."""
        from .analysis import evaluate
        return evaluate(self, q, None, t)[1]

    def nu(self, q: Any, t: float = 0.0) -> np.ndarray:
        """nu = -Phi_t(q, t), computed by the core."""
        from .analysis import evaluate
        return evaluate(self, q, None, t)[2]

    def gamma(self, q: Any, qd: Any, t: float = 0.0) -> np.ndarray:
        """gamma(q, q_dot, t), the right-hand side of J q_ddot = gamma, computed by the core."""
        from .analysis import evaluate
        return evaluate(self, q, qd, t)[3]

    def export(self, path: str, t_end: float, steps: int, t0: float = 0.0,
               tol: float | None = None, maxit: int | None = None) -> None:
        """Write a plain-text model file for the standalone ``mbd2d-solve``."""
        from .mbdfile import export
        export(self, path, t_end=t_end, steps=steps, t0=t0, tol=tol, maxit=maxit)

    def __repr__(self) -> str:
        return (f"Model({self.name!r}: {len(self.bodies)} bodies, {len(self.joints)} joints, "
                f"{len(self.drivers)} drivers)")


def _profile(spec: Any, entry: str) -> tuple[str, tuple[float, ...]]:
    spec = table(spec, "profile", entry)
    if len(spec) != 1 or next(iter(spec)) not in PROFILE_KINDS:
        raise ModelError(f"profile must be one of {{circle = ...}}, {{spline = ...}}, "
                         f"{{fourier = ...}}, got keys {sorted(spec)}", entry)
    kind, body = next(iter(spec.items()))
    body = table(body, f"profile.{kind}", entry)
    if kind == "circle":
        only_keys(body, {"center", "radius"}, entry + " profile.circle", ["center", "radius"])
        c = vector(body["center"], 2, "profile.circle.center", entry)
        r = positive(body["radius"], "profile.circle.radius", entry)
        return kind, (*c, r)
    if kind == "spline":
        only_keys(body, {"points"}, entry + " profile.spline", ["points"])
        pts = as_list(body["points"])
        if isinstance(pts, (str, bytes)) or not isinstance(pts, Sequence) or len(pts) < 4:
            raise ModelError("profile.spline.points must be a list of at least 4 [x, y] points "
                             "around the closed profile", entry)
        pp = pairs(pts, len(pts), "profile.spline.points", entry)
        flat = [v for p in pp for v in p]
        return kind, (float(len(pp)), *flat)
    only_keys(body, {"center", "a", "b"}, entry + " profile.fourier", ["a"])
    c = vector(body.get("center", [0.0, 0.0]), 2, "profile.fourier.center", entry)
    a = as_list(body["a"])
    if isinstance(a, (str, bytes)) or not isinstance(a, Sequence) or len(a) < 1:
        raise ModelError("profile.fourier.a must be a list [a0, a1, ...]", entry)
    av = vector(a, len(a), "profile.fourier.a", entry)
    k = len(av) - 1
    b = as_list(body.get("b", [0.0] * k))
    if isinstance(b, (str, bytes)) or not isinstance(b, Sequence):
        raise ModelError("profile.fourier.b must be a list [b1, ..., bK]", entry)
    bv = vector(b, len(b), "profile.fourier.b", entry)
    if len(bv) == k + 1:
        if bv[0] != 0.0:
            raise ModelError("profile.fourier.b has a b0 term; sin(0) = 0, so give [b1, ...]",
                             entry)
        bv = bv[1:]
    if len(bv) > k:
        k = len(bv)
        av = av + (0.0,) * (k + 1 - len(av))
    bv = bv + (0.0,) * (k - len(bv))
    if not av[0] > 0.0:
        raise ModelError("profile.fourier.a[0] (the mean radius) must be positive", entry)
    coeffs = [v for i in range(1, k + 1) for v in (av[i], bv[i - 1])]
    return "fourier", (*c, float(k), av[0], *coeffs)


def _follower(spec: Any, entry: str) -> tuple[str, tuple[float, float, float, float]]:
    spec = table(spec, "follower", entry)
    if len(spec) != 1 or next(iter(spec)) not in FOLLOWER_KINDS:
        raise ModelError(f"follower must be one of {{point = [x, y]}}, {{roller = ...}}, "
                         f"{{flat = ...}}, got keys {sorted(spec)}", entry)
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


__all__ = ["Model", "Body", "Revolute", "Translational", "Cam", "Driver"]

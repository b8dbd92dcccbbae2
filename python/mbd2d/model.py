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

from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from .errors import ModelError
from .forces import FORCE_KEYS, Force, PointForce, RotationalSpring, Spring, Torque
from .functions import as_function
from .joints import (COORDINATES, Absolute, AbsoluteDriver, Body, Cam, Constraint, Distance,
                     Driver, Gear, PinInSlot, PointOnCurve, PointOnLine, RackPinion,
                     RelativeAngleDriver, RelativeDistanceDriver, Revolute, RollingDisc,
                     Translational, Weld, joint_keys, parse_follower, parse_profile)
from .validate import (GROUND, as_list, check_name, choice, nonzero_vector, number, only_keys,
                       pairs, positive, vector)

if TYPE_CHECKING:  # pragma: no cover
    from .analysis import DofReport
    from .results import DynamicsResult, KinematicsResult, StaticsResult

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
        self.forces: list[Force] = []

    # ------------------------------------------------------------------ lookups
    def body_index(self, name: str, entry: str, allow_ground: bool = True) -> int:
        """1-based index of a body, 0 for ground."""
        if name == GROUND and allow_ground:
            return 0
        cache: dict[str, int] = self.__dict__.setdefault("_body_cache", {})
        i = cache.get(name, 0)
        if not (0 < i <= len(self.bodies) and self.bodies[i - 1].name == name):
            cache.clear()      # bodies were added or changed: rebuild (O(n) per change)
            cache.update((b.name, k + 1) for k, b in reversed(list(enumerate(self.bodies))))
            i = cache.get(name, 0)
        if i:
            return i
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
        # entries are appended: only the new ones are added to the cached set (a shorter
        # list rebuilds it), so building a large model stays linear
        lists = (self.bodies, self.joints, self.drivers, self.forces)
        key = tuple(len(x) for x in lists)
        old, names = self.__dict__.get("_names_cache", ((0, 0, 0, 0), set()))
        if any(k < o for k, o in zip(key, old)):
            old, names = (0, 0, 0, 0), set()
        if key != old:
            for x, o in zip(lists, old):
                names.update(e.name for e in x[o:])
            self.__dict__["_names_cache"] = (key, names)
        return names

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
                 inertia: float | None = None, v0: Sequence[float] | None = None) -> Body:
        """Add a moving body.

        Parameters
        ----------
        name : str
            Unique name (not 'ground').
        q0 : sequence of 3 float
            Rough estimate of x, y, theta of the centre of mass.
        mass, inertia : float, optional
            Needed only for dynamics (mass >= 0, 0 for a massless link; inertia about the
            centre of mass, >= 0, 0 for a point mass).
        v0 : sequence of 3 float, optional
            Initial velocity estimate (dynamics); made consistent with the constraints.

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
        m = None if mass is None else number(mass, "mass", entry)
        if m is not None and m < 0.0:
            raise ModelError(f"mass must be >= 0, got {mass!r}", entry)
        j = None if inertia is None else number(inertia, "inertia", entry)
        if j is not None and j < 0.0:
            raise ModelError(f"inertia must be >= 0, got {inertia!r}", entry)
        v = (0.0, 0.0, 0.0) if v0 is None else vector(v0, 3, "v0", entry)
        b = Body(name, q, m, j, v)  # type: ignore[arg-type]
        self.bodies.append(b)
        return b

    def _add(self, joint: Constraint) -> Constraint:
        self.joints.append(joint)
        return joint

    def _start(self, kind: str, name: str | None) -> tuple[str, str]:
        """Settle the name of a new joint; return (name, entry for messages)."""
        entry = self._entry(kind, name)
        name = self._new_name(name, kind.replace("-", "_"), entry)
        return name, f"joint '{name}' ({kind})"

    def add_revolute(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                     name: str | None = None) -> Revolute:
        """Revolute joint: points[0] on bodies[0] coincides with points[1] on bodies[1].

        Points are in each body's frame (a ground point is global).
        """
        name, entry = self._start("revolute", name)
        return self._add(Revolute(name, self._two_bodies(bodies, entry),
                                  pairs(points, 2, "points", entry)))  # type: ignore[return-value]

    def add_translational(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                          axes: Sequence[Sequence[float]],
                          name: str | None = None) -> Translational:
        """Translational joint: the point on bodies[1] slides along the line through points[0]
        with direction axes[0] (in bodies[0]); axes[1] (in bodies[1]) stays parallel to it."""
        name, entry = self._start("translational", name)
        bb = self._two_bodies(bodies, entry)
        pts = pairs(points, 2, "points", entry)
        axes = as_list(axes)
        if isinstance(axes, (str, bytes)) or not isinstance(axes, Sequence) or len(axes) != 2:
            raise ModelError(f"axes must be a list of two [x, y] directions, got {axes!r}", entry)
        ax = (nonzero_vector(axes[0], "axes[0]", entry), nonzero_vector(axes[1], "axes[1]", entry))
        return self._add(Translational(name, bb, pts, ax))  # type: ignore[return-value]

    def add_cam(self, bodies: Sequence[str], profile: Mapping[str, Any],
                follower: Mapping[str, Any], name: str | None = None) -> Cam:
        """Cam: a profile on bodies[0] touching a follower on bodies[1].

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
        name, entry = self._start("cam", name)
        bb = self._two_bodies(bodies, entry)
        pkind, pparams = parse_profile(profile, entry)
        fkind, fparams = parse_follower(follower, entry)
        return self._add(Cam(name, bb, pkind, pparams, fkind, fparams))  # type: ignore

    def add_point_on_curve(self, bodies: Sequence[str], curve: Mapping[str, Any],
                           point: Sequence[float], name: str | None = None) -> PointOnCurve:
        """A point of bodies[1] on a closed curve of bodies[0] (a pin in a curved slot); the
        curve takes the cam profile forms. Adds the curve parameter alpha as a coordinate."""
        name, entry = self._start("point-on-curve", name)
        bb = self._two_bodies(bodies, entry)
        pkind, pparams = parse_profile(curve, entry, key="curve")
        p = vector(point, 2, "point", entry)
        return self._add(PointOnCurve(name, bb, pkind, pparams, "point",  # type: ignore
                                      (p[0], p[1], 0.0, 0.0)))

    def add_distance(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                     distance: float, name: str | None = None) -> Distance:
        """Distance constraint (revolute-revolute composite): the points stay ``distance``
        apart."""
        name, entry = self._start("distance", name)
        return self._add(Distance(name, self._two_bodies(bodies, entry),  # type: ignore
                                  pairs(points, 2, "points", entry),
                                  positive(distance, "distance", entry)))

    def add_point_on_line(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                          axis: Sequence[float], offset: float = 0.0,
                          name: str | None = None) -> PointOnLine:
        """The point points[1] of bodies[1] stays on the line through points[0] with direction
        ``axis`` fixed in bodies[0] (at a signed normal ``offset``)."""
        return self._line_joint(PointOnLine, "point-on-line", bodies, points, axis, offset, name)

    def add_pin_in_slot(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                        axis: Sequence[float], offset: float = 0.0,
                        name: str | None = None) -> PinInSlot:
        """Revolute-translational composite: the pin points[1] of bodies[1] runs in the straight
        slot of bodies[0] through points[0] along ``axis``."""
        return self._line_joint(PinInSlot, "revolute-translational", bodies, points, axis,
                                offset, name)

    def _line_joint(self, cls: Any, kind: str, bodies: Any, points: Any, axis: Any,
                    offset: Any, name: str | None) -> Any:
        name, entry = self._start(kind, name)
        return self._add(cls(name, self._two_bodies(bodies, entry),
                             pairs(points, 2, "points", entry),
                             nonzero_vector(axis, "axis", entry), number(offset, "offset", entry)))

    def add_weld(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                 angle: float = 0.0, name: str | None = None) -> Weld:
        """Weld: the points coincide and theta_j - theta_i = ``angle``."""
        name, entry = self._start("weld", name)
        return self._add(Weld(name, self._two_bodies(bodies, entry),  # type: ignore
                              pairs(points, 2, "points", entry), number(angle, "angle", entry)))

    def add_gear(self, bodies: Sequence[str], radii: Sequence[float], internal: bool = False,
                 carrier: str = "ground", phase: float | None = None,
                 name: str | None = None) -> Gear:
        """Gear pair whose centres are held by ``carrier`` (ground by default):
        R_i (theta_i - theta_c) + R_j (theta_j - theta_c) = phase (external), with a minus for
        an internal pair (bodies[1] is the ring). The phase defaults to its value at the q0
        estimates."""
        name, entry = self._start("gear", name)
        bb = self._two_bodies(bodies, entry)
        r = vector(radii, 2, "radii", entry)
        for i in range(2):
            positive(r[i], f"radii[{i}]", entry)
        if not isinstance(internal, bool):
            raise ModelError(f"internal must be true or false, got {internal!r}", entry)
        if internal and not r[1] > r[0]:
            raise ModelError("an internal pair needs the ring (second body) larger than the "
                             "pinion", entry)
        if not isinstance(carrier, str):
            raise ModelError(f"carrier must be a body name, got {carrier!r}", entry)
        self.body_index(carrier, entry)
        if carrier in bb:
            raise ModelError(f"the carrier {carrier!r} cannot be one of the gears", entry)
        ph = None if phase is None else number(phase, "phase", entry)
        return self._add(Gear(name, bb, (r[0], r[1]), internal, carrier, ph))  # type: ignore

    def add_rack_pinion(self, bodies: Sequence[str], center: Sequence[float],
                        point: Sequence[float], axis: Sequence[float], radius: float,
                        phase: float | None = None, name: str | None = None) -> RackPinion:
        """Rack and pinion: the pinion bodies[0] (pitch circle at ``center``, ``radius``) rolls
        without slip along the rack line of bodies[1] (through ``point`` along ``axis``). The
        centre distance is held by the other joints. The phase defaults to its q0 value."""
        return self._rolling(RackPinion, "rack-pinion", bodies, center, point, axis, radius,
                             phase, name)

    def add_rolling_disc(self, bodies: Sequence[str], center: Sequence[float],
                         point: Sequence[float], axis: Sequence[float], radius: float,
                         phase: float | None = None, name: str | None = None) -> RollingDisc:
        """A disc bodies[0] (centre ``center``, ``radius``) rolling without slip on the line of
        bodies[1] through ``point`` along ``axis``: contact and no slip (2 equations)."""
        return self._rolling(RollingDisc, "rolling-disc", bodies, center, point, axis, radius,
                             phase, name)

    def _rolling(self, cls: Any, kind: str, bodies: Any, center: Any, point: Any, axis: Any,
                 radius: Any, phase: Any, name: str | None) -> Any:
        name, entry = self._start(kind, name)
        return self._add(cls(name, self._two_bodies(bodies, entry),
                             vector(center, 2, "center", entry), vector(point, 2, "point", entry),
                             nonzero_vector(axis, "axis", entry),
                             positive(radius, "radius", entry),
                             None if phase is None else number(phase, "phase", entry)))

    def add_absolute(self, body: str, coordinate: str, value: float | None = None,
                     name: str | None = None) -> Absolute:
        """Absolute constraint: fix x, y or theta of a body (at ``value``, by default its q0
        estimate)."""
        name, entry = self._start("absolute", name)
        if not isinstance(body, str):
            raise ModelError(f"body must be a name, got {body!r}", entry)
        b = self.bodies[self.body_index(body, entry, allow_ground=False) - 1]
        choice(coordinate, COORDINATES, "coordinate", entry)
        v = b.q0[COORDINATES[coordinate] - 1] if value is None else number(value, "value", entry)
        return self._add(Absolute(name, (body, GROUND), coordinate, v))  # type: ignore

    def add_joint(self, type: str, **kw: Any) -> Constraint:
        """Add a joint by its TOML type name, with the TOML keys as keyword arguments."""
        builders = {"revolute": self.add_revolute, "translational": self.add_translational,
                    "cam": self.add_cam, "point-on-curve": self.add_point_on_curve,
                    "distance": self.add_distance, "point-on-line": self.add_point_on_line,
                    "revolute-translational": self.add_pin_in_slot, "weld": self.add_weld,
                    "gear": self.add_gear, "rack-pinion": self.add_rack_pinion,
                    "rolling-disc": self.add_rolling_disc, "absolute": self.add_absolute}
        entry = self._entry(str(type), kw.get("name"))
        if not isinstance(type, str) or type not in builders:
            raise ModelError(f"unknown joint type {type!r}; known: {', '.join(builders)}", entry)
        allowed, required = joint_keys()[type]
        only_keys(kw, allowed | {"name"}, entry, required=sorted(required))
        return builders[type](**kw)

    # ------------------------------------------------------------------ forces
    def _force_start(self, kind: str, name: str | None) -> tuple[str, str]:
        entry = f"force {name!r} ({kind})" if isinstance(name, str) \
            else f"force #{len(self.forces) + 1} ({kind})"
        name = self._new_name(name, kind.replace("-", "_"), entry)
        return name, f"force '{name}' ({kind})"

    def add_spring(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                   stiffness: float = 0.0, damping: float = 0.0, length0: float = 0.0,
                   f: Any = 0.0, name: str | None = None) -> Spring:
        """Translational spring-damper-actuator between two points: tension
        stiffness (L - length0) + damping L_dot - f(t) (a positive f pushes apart)."""
        name, entry = self._force_start("spring", name)
        fs = Spring(name, self._two_bodies(bodies, entry), pairs(points, 2, "points", entry),
                    _nonneg(stiffness, "stiffness", entry), _nonneg(damping, "damping", entry),
                    _nonneg(length0, "length0", entry), as_function(f, entry))
        self.forces.append(fs)
        return fs

    def add_torque(self, body: str, f: Any, name: str | None = None) -> Torque:
        """A torque f(t) on a body (counterclockwise positive; reaction on ground)."""
        name, entry = self._force_start("torque", name)
        if not isinstance(body, str):
            raise ModelError(f"body must be a name, got {body!r}", entry)
        self.body_index(body, entry, allow_ground=False)
        fs = Torque(name, (body, GROUND), as_function(f, entry))
        self.forces.append(fs)
        return fs

    def add_point_force(self, body: str, point: Sequence[float], fx: Any = 0.0, fy: Any = 0.0,
                        name: str | None = None) -> PointForce:
        """A force (fx(t), fy(t)) in global components at a point of a body."""
        name, entry = self._force_start("point", name)
        if not isinstance(body, str):
            raise ModelError(f"body must be a name, got {body!r}", entry)
        self.body_index(body, entry, allow_ground=False)
        fs = PointForce(name, (body, GROUND), vector(point, 2, "point", entry),  # type: ignore
                        as_function(fx, entry, "fx"), as_function(fy, entry, "fy"))
        self.forces.append(fs)
        return fs

    def add_rotational_spring(self, bodies: Sequence[str], stiffness: float = 0.0,
                              damping: float = 0.0, angle0: float = 0.0, f: Any = 0.0,
                              name: str | None = None) -> RotationalSpring:
        """Rotational spring-damper between two bodies: on bodies[1] the torque
        -stiffness (a - angle0) - damping a_dot + f(t), a = theta_j - theta_i."""
        name, entry = self._force_start("rotational-spring", name)
        fs = RotationalSpring(name, self._two_bodies(bodies, entry),
                              _nonneg(stiffness, "stiffness", entry),
                              _nonneg(damping, "damping", entry),
                              number(angle0, "angle0", entry), as_function(f, entry))
        self.forces.append(fs)
        return fs

    def add_force(self, type: str, **kw: Any) -> Force:
        """Add a force element by its TOML type name, with the TOML keys as arguments."""
        builders = {"spring": self.add_spring, "torque": self.add_torque,
                    "point": self.add_point_force, "rotational-spring": self.add_rotational_spring}
        name = kw.get("name")
        entry = f"force {name!r} ({type})" if isinstance(name, str) \
            else f"force #{len(self.forces) + 1} ({type})"
        if not isinstance(type, str) or type not in builders:
            raise ModelError(f"unknown force type {type!r}; known: {', '.join(builders)}", entry)
        allowed, required = FORCE_KEYS[type]
        only_keys(kw, allowed | {"name"}, entry, required=sorted(required))
        return builders[type](**kw)

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
        entry = f"driver '{name}'"
        fun = as_function(f, entry)
        d: Driver
        if type == "absolute":
            if body is None or coordinate is None or bodies is not None or joint is not None:
                raise ModelError("an absolute driver needs 'body' and 'coordinate' (and not "
                                 "'bodies' or 'joint')", entry)
            if not isinstance(body, str):
                raise ModelError(f"body must be a name, got {body!r}", entry)
            self.body_index(body, entry, allow_ground=False)
            choice(coordinate, COORDINATES, "coordinate", entry)
            d = AbsoluteDriver(name, (body, GROUND), fun, coordinate)
        elif type == "relative-angle":
            if bodies is None or body is not None or coordinate is not None or joint is not None:
                raise ModelError("a relative-angle driver needs 'bodies' = [i, j] (theta_j - "
                                 "theta_i = f(t)) and no 'body', 'coordinate' or 'joint'", entry)
            d = RelativeAngleDriver(name, self._two_bodies(bodies, entry), fun)
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
            d = RelativeDistanceDriver(name, target.bodies, fun, joint)
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
        """A label for each row of Phi: ``NAME.equation`` (for example ``O2.x``,
        ``guide.angle``, ``motor.crank.theta``)."""
        return [r for c in self.constraints for r in c.rows()]

    # ------------------------------------------------------------------ analyses
    def kinematics(self, t_end: float, steps: int, t0: float = 0.0, tol: float | None = None,
                   maxit: int | None = None, every: int = 1,
                   solver: str = "auto") -> "KinematicsResult":
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
        every : int, optional
            Keep every k-th output row (and the last): memory stays flat on long runs. The
            step size is still (t_end - t0) / steps.
        solver : {"auto", "dense", "banded"}, optional
            Linear solver of the Newton loop: dense LU, or band LU (dgbtrf) of J after a
            reverse Cuthill-McKee ordering. "auto" picks the band for square J with at least
            60 coordinates whose band is at most a quarter of them wide
            (``res.stats["solver"]`` says which ran).

        Returns
        -------
        KinematicsResult
            When every body has a mass and an inertia (and ``maxit`` is not given), a
            DynamicsResult with the inverse dynamics too (see :meth:`inverse_dynamics`).

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
        if self.has_masses() and maxit is None:
            from .dynamics import run_inverse
            return run_inverse(self, t_end=t_end, steps=steps, t0=t0, tol=tol, every=every,
                               solver=solver)
        return run_kinematics(self, t_end=t_end, steps=steps, t0=t0, tol=tol, maxit=maxit,
                              every=every, solver=solver)

    def analyze_dof(self, t: float = 0.0, tol: float | None = None) -> "DofReport":
        """Degrees of freedom and redundant constraints at the configuration assembled from
        the q0 estimates at time t.

        Returns
        -------
        DofReport
            Coordinates, equations, rank of J, degrees of freedom, mobility of the joints
            alone, and the redundant equations by name (``print(report)`` for a summary).

        Raises
        ------
        InconsistentConstraintsError
            If redundant constraints contradict each other.
        AssemblyError
            If no configuration satisfies the constraints near q0.

        Examples
        --------
        >>> import mbd2d
        >>> print(mbd2d.load("examples/door_two_hinges.toml").analyze_dof().redundant_rows)
        ['upper.x', 'upper.y']
        """
        from .analysis import analyze_dof
        return analyze_dof(self, t=t, tol=tol)

    def has_masses(self) -> bool:
        """Every body has a mass and an inertia (dynamics and inverse dynamics can run)."""
        return bool(self.bodies) and all(b.mass is not None and b.inertia is not None
                                         for b in self.bodies)

    def inverse_dynamics(self, t_end: float, steps: int, t0: float = 0.0,
                         tol: float | None = None, every: int = 1,
                         solver: str = "auto") -> "DynamicsResult":
        """Kinematics of the driven model plus, at every output time, the multipliers lambda
        (J^T lambda = Q - M q_ddot), the joint reactions (``res.reaction(name)``), the driver
        efforts (``res.effort(name)``) and the energies. ``every`` and ``solver`` as in
        :meth:`kinematics` (the multipliers are computed at the kept outputs only).

        Raises
        ------
        ModelError
            If a body has no mass or inertia, or the model is not kinematically determined.
        SingularConfigurationError, AssemblyError, ConvergenceError
            As :meth:`kinematics`.
        """
        from .dynamics import run_inverse
        return run_inverse(self, t_end=t_end, steps=steps, t0=t0, tol=tol, every=every,
                           solver=solver)

    def dynamics(self, t_end: float, steps: int, method: str | None = None,
                 rtol: float | None = None, atol: float | None = None, h: float | None = None,
                 rho_inf: float | None = None, alpha: float | None = None,
                 beta: float | None = None, t0: float = 0.0,
                 every: int = 1, max_steps: int | None = None) -> "DynamicsResult":
        """Forward dynamics of M q_ddot + J^T lambda = Q, Phi = 0 from the assembled q0 and
        v0 (projected onto J q_dot = nu), outputs at steps + 1 uniform times (every
        every-th of them kept).

        Parameters
        ----------
        t_end, steps, t0 : float, int, float
            Output times t0 + k (t_end - t0)/steps.
        method : {'dopri5', 'generalized-alpha', 'baumgarte-rk4', 'partitioned'}
            dopri5 (default): index 1, Dormand-Prince 5(4), error-controlled, with projection
            onto the position and velocity constraints after each step;
            generalized-alpha: implicit index 3, error-controlled or fixed step h; the choice
            for stiff models;
            baumgarte-rk4: index 1 with Baumgarte stabilization, fixed step h;
            partitioned: coordinate partitioning (Wehage-Haug), Dormand-Prince on the
            independent coordinates.
        rtol, atol : float, optional
            Error tolerances of the adaptive methods (defaults 1e-6, 1e-8).
        h : float, optional
            Fixed step (generalized-alpha, baumgarte-rk4).
        rho_inf : float, optional
            Generalized-alpha spectral radius at infinite frequency, in [0, 1] (default 0.8).
        alpha, beta : float, optional
            Baumgarte coefficients (default 10, 10).
        every : int, optional
            Output decimation (default 1): of the output times k = 0 .. steps only those with
            k % every == 0, and always the last (k = steps), are stored and returned, so
            memory grows as steps / every. The integration (its time grid and, for fixed
            steps, h) is the same as with every = 1, and so are the rows kept.
        max_steps : int, optional
            Limit on the integrator's steps, accepted and rejected (default 10_000_000). It
            ends a run whose steps collapse; a long run at a tight tolerance (or a fixed h
            that needs more steps) raises it. When it is reached the run stops with an
            IntegrationError that says so, the results up to then kept.

        Returns
        -------
        DynamicsResult

        Raises
        ------
        ModelError
            If a body has no mass or inertia, or a setting is invalid (every or max_steps not
            a whole number >= 1).
        IntegrationError
            When the method fails (blow-up, step-size underflow, the step limit max_steps);
            carries the partial results.

        Examples
        --------
        >>> res = model.dynamics(10.0, 100_000, method="generalized-alpha", h=1e-4,
        ...                      every=100)   # doctest: +SKIP
        >>> res.t.shape                        # doctest: +SKIP
        (1001,)
        """
        from .dynamics import run_dynamics
        return run_dynamics(self, t_end=t_end, steps=steps, method=method, rtol=rtol,
                            atol=atol, h=h, rho_inf=rho_inf, alpha=alpha, beta=beta, t0=t0,
                            every=every, max_steps=max_steps)

    def statics(self, t: float = 0.0) -> "StaticsResult":
        """Static equilibrium under gravity, springs and loads (drivers held at t), with the
        multipliers, reactions (``res.reaction(name)``) and stability.

        Raises
        ------
        ConvergenceError
            If no equilibrium is found near the q0 estimates.
        SingularJacobianError
            If the equilibrium is not unique (a free motion without stiffness).
        """
        from .dynamics import run_statics
        return run_statics(self, t=t)

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
        forces = f", {len(self.forces)} forces" if self.forces else ""
        return (f"Model({self.name!r}: {len(self.bodies)} bodies, {len(self.joints)} joints, "
                f"{len(self.drivers)} drivers{forces})")


def _nonneg(x: Any, what: str, entry: str) -> float:
    v = number(x, what, entry)
    if v < 0.0:
        raise ModelError(f"{what} must be >= 0, got {x!r}", entry)
    return v


__all__ = ["Model"]

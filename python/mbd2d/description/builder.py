"""The model description: bodies, joints, drivers and forces, and the builder that checks
each entry as it is added.

A model is built either in code::

    m = mbd2d.Model("four-bar")
    m.add_body("crank", q0=[0.75, 1.3, 1.047])
    m.add_revolute(["ground", "crank"], [[0, 0], [-1.5, 0]], name="O2")
    ...
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [1.047, 1.0]})

or from TOML with :func:`mbd2d.load`, which calls the same methods. This class describes the
model only; :class:`mbd2d.Model` adds the analyses on top of it.
"""
from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

from ..errors import ModelError
from ..validate import (GROUND, as_list, check_name, choice, nonnegative, nonzero_vector, number,
                        only_keys, pairs, positive, vector)
from .bodies import Body
from .entries import reading
from .contacts import CONTACT_KEYS, CONTACT_TYPES, Contact, contact_geometry, parse_law
from .drivers import AbsoluteDriver, Driver, RelativeAngleDriver, RelativeDistanceDriver
from .forces import FORCE_KEYS, Force, PointForce, RotationalSpring, Spring, Torque
from .friction import NO_FRICTION, parse_friction
from .functions import as_function
from .joints import (COORDINATES, PRESSURE_ANGLE, Absolute, Cam, Constraint, Distance, Gear,
                     PinInSlot, PointOnCurve, PointOnLine, RackPinion, Revolute, RollingDisc,
                     Translational, Weld, joint_keys, parse_follower, parse_profile)
from .parameters import parameter_list
from .parameters import with_params as _with_params


class ModelDescription:
    """A planar multibody model: what it is made of, without the analyses.

    Parameters
    ----------
    name : str
        Model name (used in plots and exported files).
    gravity : sequence of float
        Gravity vector (dynamics only).

    Examples
    --------
    >>> m = ModelDescription("pendulum")
    >>> _ = m.add_body("bar", q0=[0.5, 0.0, 0.0])
    >>> _ = m.add_revolute(["ground", "bar"], [[0, 0], [-0.5, 0]])
    >>> _ = m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0.0, 1.0]})
    >>> m.constraint_rows()
    ['joint1.x', 'joint1.y', 'driver1.theta']
    """

    def __init__(self, name: str = "model", gravity: Sequence[float] = (0.0, -9.81)) -> None:
        if not isinstance(name, str):
            raise ModelError(f"name must be a string, got {name!r}", "[model]")
        self.name = name
        self.gravity = vector(gravity, 2, "gravity", "[model]")
        self.bodies: list[Body] = []
        self.joints: list[Constraint] = []
        self.drivers: list[Driver] = []
        self.forces: list[Force] = []
        self.contacts: list[Contact] = []

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
        lists = (self.bodies, self.joints, self.drivers, self.forces, self.contacts)
        key = tuple(len(x) for x in lists)
        old, names = self.__dict__.get("_names_cache", ((0, 0, 0, 0, 0), set()))
        if any(k < o for k, o in zip(key, old)):
            old, names = (0, 0, 0, 0, 0), set()
        if key != old:
            for x, o in zip(lists, old):
                names.update(e.name for e in x[o:])
            self.__dict__["_names_cache"] = (key, names)
        return names

    def _new_name(self, name: str | None, section: str, entry: str) -> str:
        """The name of a new joint, driver or force (``section``): the one given, checked,
        or the automatic ``joint<k>``, ``driver<k>``, ``force<k>`` where k counts the
        entries of that section, this one included (the k-th ``[[joint]]`` of a file)."""
        if name is None:
            k = len({"joint": self.joints, "driver": self.drivers, "force": self.forces,
                     "contact": self.contacts}[section])
            name = f"{section}{k + 1}"
            if name == GROUND or name in self._names():
                raise ModelError(f"this {section} has no name, and its automatic name {name!r} "
                                 f"(the {section}s are numbered {section}1, {section}2, ... "
                                 "in the order they are added) is already used by another "
                                 f"entry; give this {section} a name", entry)
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
        name = self._new_name(name, "joint", entry)
        return name, f"joint '{name}' ({kind})"

    def add_revolute(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                     name: str | None = None, friction: Mapping[str, Any] | None = None,
                     pin_radius: float | None = None) -> Revolute:
        """Revolute joint: points[0] on bodies[0] coincides with points[1] on bodies[1].

        Points are in each body's frame (a ground point is global). ``friction``:
        ``{mu, mu_static, model, threshold, pin_radius}`` (see
        :mod:`mbd2d.description.friction`): a friction moment mu N pin_radius against the
        relative rotation, N the magnitude of the pin force (the friction circle);
        ``pin_radius`` may be given here instead of in the table.
        """
        name, entry = self._start("revolute", name)
        bb = self._two_bodies(bodies, entry)
        pts = pairs(points, 2, "points", entry)
        fr = None
        if friction is not None:
            fr = parse_friction(friction, entry, revolute=True, pin_radius=pin_radius)
        elif pin_radius is not None:
            raise ModelError("pin_radius is the radius of the friction circle: give it with "
                             "friction = { mu = ... }", entry)
        return self._add(Revolute(name, bb, pts, fr))  # type: ignore[return-value]

    def add_translational(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                          axes: Sequence[Sequence[float]], name: str | None = None,
                          friction: Mapping[str, Any] | None = None) -> Translational:
        """Translational joint: the point on bodies[1] slides along the line through points[0]
        with direction axes[0] (in bodies[0]); axes[1] (in bodies[1]) stays parallel to it.
        ``friction``: ``{mu, mu_static, model, threshold}``, a force mu N along the axis
        against the slide, N the normal reaction (the moment reaction is not a load here)."""
        name, entry = self._start("translational", name)
        bb = self._two_bodies(bodies, entry)
        pts = pairs(points, 2, "points", entry)
        axes = as_list(axes)
        if isinstance(axes, (str, bytes)) or not isinstance(axes, Sequence) or len(axes) != 2:
            raise ModelError(f"axes must be a list of two [x, y] directions, got {axes!r}", entry)
        ax = (nonzero_vector(axes[0], "axes[0]", entry), nonzero_vector(axes[1], "axes[1]", entry))
        fr = None if friction is None else parse_friction(friction, entry)
        return self._add(Translational(name, bb, pts, ax, fr))  # type: ignore[return-value]

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
                 pressure_angle: float = PRESSURE_ANGLE,
                 centers: Sequence[Sequence[float]] | None = None,
                 name: str | None = None) -> Gear:
        """Gear pair whose centres are held by ``carrier`` (ground by default):
        R_i (theta_i - theta_c) + R_j (theta_j - theta_c) = phase (external), with a minus for
        an internal pair (bodies[1] is the ring). The phase defaults to its value at the q0
        estimates. The reaction is the tooth force at the pitch point along the line of
        action, ``pressure_angle`` (radians, default 20 degrees) from the common tangent; a
        positive angle is the flank that separates the gears while the mesh turns bodies[0]
        clockwise (its multiplier positive), a negative one the other flank. ``centers``:
        the gear centres in each gear's frame (default: the points of the revolutes that pin
        the gears to the carrier, else the body origins)."""
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
        pa = number(pressure_angle, "pressure_angle", entry)
        if not abs(pa) < math.pi / 2:
            raise ModelError(f"pressure_angle is in radians, between -pi/2 and pi/2 (20 "
                             f"degrees = 0.349), got {pressure_angle!r}", entry)
        cc = None if centers is None else pairs(centers, 2, "centers", entry)
        return self._add(Gear(name, bb, (r[0], r[1]), internal, carrier, ph, pa,  # type: ignore
                              cc))

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
        name = self._new_name(name, "force", entry)
        return name, f"force '{name}' ({kind})"

    def add_spring(self, bodies: Sequence[str], points: Sequence[Sequence[float]],
                   stiffness: float = 0.0, damping: float = 0.0, length0: float = 0.0,
                   f: Any = 0.0, name: str | None = None) -> Spring:
        """Translational spring-damper-actuator between two points: tension
        stiffness (L - length0) + damping L_dot - f(t) (a positive f pushes apart)."""
        name, entry = self._force_start("spring", name)
        fs = Spring(name, self._two_bodies(bodies, entry), pairs(points, 2, "points", entry),
                    nonnegative(stiffness, "stiffness", entry), nonnegative(damping, "damping", entry),
                    nonnegative(length0, "length0", entry), as_function(f, entry))
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
                              nonnegative(stiffness, "stiffness", entry),
                              nonnegative(damping, "damping", entry),
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

    # ------------------------------------------------------------------ contacts
    def add_contact(self, type: str, bodies: Sequence[str], law: Mapping[str, Any],
                    circle: Any = None, line: Mapping[str, Any] | None = None,
                    profile: Mapping[str, Any] | None = None,
                    follower: Mapping[str, Any] | None = None,
                    friction: Mapping[str, Any] | None = None,
                    name: str | None = None) -> Contact:
        """A penalty contact between a surface of bodies[0] and one of bodies[1] (dynamics).

        Parameters
        ----------
        type : {'circle-line', 'circle-circle', 'circle-in-circle', 'follower-profile'}
            circle-line: ``circle`` {center, radius} on bodies[0] against ``line`` {point,
            normal} on bodies[1], the solid on the side opposite the normal;
            circle-circle: ``circle`` = [{...}, {...}], the outer surfaces of two circles;
            circle-in-circle: ``circle`` = [pin, hole], a pin of bodies[0] in a larger hole
            of bodies[1] (a revolute joint with clearance);
            follower-profile: the cam ``profile`` on bodies[0] and the ``follower`` on
            bodies[1], in the forms of :meth:`add_cam`; the follower can lift off.
        law : mapping
            ``{model, stiffness, exponent, restitution}``: model 'linear' (spring-dashpot),
            'hertz' (elastic), 'hunt-crossley', 'lankarani-nikravesh' or 'flores' (Fn = k
            delta**exponent with hysteresis damping from the restitution); exponent default
            1.5 (1 for linear), restitution default 1.
        friction : mapping, optional
            ``{mu, mu_static, threshold}``: regularized Coulomb friction at the contact point.

        Returns
        -------
        Contact
        """
        entry = f"contact {name!r} ({type})" if isinstance(name, str) \
            else f"contact #{len(self.contacts) + 1} ({type})"
        if not isinstance(type, str) or type not in CONTACT_TYPES:
            raise ModelError(f"unknown contact type {type!r}; known: "
                             f"{', '.join(CONTACT_TYPES)}", entry)
        name = self._new_name(name, "contact", entry)
        entry = f"contact '{name}' ({type})"
        bb = self._two_bodies(bodies, entry)
        given = {"circle": circle, "line": line, "profile": profile, "follower": follower}
        allowed, required = CONTACT_KEYS[type]
        for key, value in given.items():
            if value is not None and key not in allowed:
                raise ModelError(f"a {type} contact has no '{key}'; its keys: "
                                 f"{sorted(allowed)}", entry)
            if value is None and key in required:
                raise ModelError(f"missing key '{key}'", entry)
        geom, pkind, fkind = contact_geometry(type, entry, **given)
        lw = parse_law(law, entry)
        fr = NO_FRICTION if friction is None else parse_friction(friction, entry, joint=False)
        c = Contact(name, type, bb, geom, lw, fr, pkind, fkind)
        self.contacts.append(c)
        return c

    def force_elements(self) -> list[tuple[str, str, Any]]:
        """The force elements in the core's order: (name, what, entry) for the forces, the
        contacts, then the friction of each joint that has one (``what`` is 'force',
        'contact' or 'friction'; a friction is named by its joint)."""
        out: list[tuple[str, str, Any]] = [(f.name, "force", f) for f in self.forces]
        out += [(c.name, "contact", c) for c in self.contacts]
        out += [(j.name, "friction", j) for j in self.joints
                if getattr(j, "friction", None) is not None]
        return out

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
        if not isinstance(type, str) or \
                type not in ("absolute", "relative-angle", "relative-distance"):
            raise ModelError(f"unknown driver type {type!r}; use 'absolute', 'relative-angle' "
                             "or 'relative-distance'", entry)
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
        else:                                               # relative-distance
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
        self.drivers.append(d)
        return d

    def _entry(self, kind: str, name: Any) -> str:
        """How messages name an entry being added (before its name is settled)."""
        if kind == "driver":
            return f"driver {name!r}" if isinstance(name, str) \
                else f"driver #{len(self.drivers) + 1}"
        return f"joint {name!r} ({kind})" if isinstance(name, str) \
            else f"joint #{len(self.joints) + 1} ({kind})"

    # ------------------------------------------------------------------ names
    @property
    def coordinate_names(self) -> list[str]:
        """Names of the entries of q: NAME.x, NAME.y, NAME.theta per body, then the extra
        coordinates of cams and curves (NAME.alpha), in the order of the constraints."""
        names = [f"{b.name}.{s}" for b in self.bodies for s in ("x", "y", "theta")]
        return names + [n for c in self.constraints for n in c.extra_names()]

    def constraint_rows(self) -> list[str]:
        """A label for each row of Phi: ``NAME.EQUATION``, the joint's or driver's name and
        the equation's word from :data:`~mbd2d.description.joints.ROW_WORDS` (for example
        ``O2.x``, ``guide.angle``, ``motor.theta``)."""
        return [r for c in self.constraints for r in c.rows()]

    # ------------------------------------------------------------------ design parameters
    def parameters(self) -> dict[str, float | None]:
        """Every design parameter by name, with its value.

        A name is the entry's path in the model file: ``joint.A.points.1.0`` (x of joint
        A's point on its second body), ``joint.guide.axes.0.1``, ``body.crank.mass``,
        ``force.s1.stiffness``, ``driver.motor.f.poly.1``, ``model.gravity.1`` (see
        :mod:`mbd2d.description.parameters`). A gear or rolling phase left open has the value
        None here (:meth:`mbd2d.Model.parameters` gives the value taken from q0).

        Examples
        --------
        >>> import mbd2d
        >>> mbd2d.load("examples/fourbar_grashof.toml").parameters()["joint.A.points.1.0"]
        -1.75
        """
        with reading(self):
            return {p.name: p.value for p in parameter_list(self)}

    def with_params(self, values: Mapping[str, Any]) -> "ModelDescription":
        """A new model with the named parameters set to the given values; this model is
        left unchanged.

        Raises
        ------
        ModelError
            For an unknown name (the message names it and suggests the closest names) or a
            value that is not a finite number.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> m.with_params({"joint.B.points.0.0": 1.8}).parameters()["joint.B.points.0.0"]
        1.8
        """
        with reading(self):
            return _with_params(self, values)

    def has_masses(self) -> bool:
        """Every body has a mass and an inertia (dynamics and inverse dynamics can run)."""
        return bool(self.bodies) and all(b.mass is not None and b.inertia is not None
                                         for b in self.bodies)

    def __repr__(self) -> str:
        forces = f", {len(self.forces)} forces" if self.forces else ""
        forces += f", {len(self.contacts)} contacts" if self.contacts else ""
        return (f"{type(self).__name__}({self.name!r}: {len(self.bodies)} bodies, "
                f"{len(self.joints)} joints, "
                f"{len(self.drivers)} drivers{forces})")


__all__ = ["ModelDescription"]

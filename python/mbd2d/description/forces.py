"""Force elements: springs, torques, point forces and rotational springs.

Each packs itself into the force table the core reads (``fortran/mbd_forces.f90``)::

    [[force]]
    type = "spring"            # between two points; positive actuator force pushes apart
    bodies = ["ground", "b3"]
    points = [[0.014, 0.072], [0.01, -0.02]]
    stiffness = 4530.0
    damping = 0.0
    length0 = 0.07785
    f = { poly = [0.0] }

    [[force]]
    type = "torque"            # on a body, reaction on ground
    body = "b1"
    f = { poly = [0.033] }

    [[force]]
    type = "point"             # at a body point, global components
    body = "b2"
    point = [0.1, 0.0]
    fx = { poly = [0.0] }
    fy = { poly = [-5.0] }

    [[force]]
    type = "rotational-spring" # between two bodies
    bodies = ["ground", "b1"]
    stiffness = 10.0
    damping = 0.1
    angle0 = 0.0
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from .functions import TimeFunction


@dataclass
class Force:
    """Common part of the force elements."""

    name: str
    bodies: tuple[str, str]
    type: ClassVar[str] = "force"
    kind: ClassVar[int] = 0

    def describe(self) -> str:
        """How messages name this entry."""
        return f"force '{self.name}' ({self.type})"

    def raw(self) -> list[float]:
        """Raw parameters of the force table."""
        raise NotImplementedError


@dataclass
class Spring(Force):
    """Translational spring-damper-actuator between two points.

    Tension T = stiffness (L - length0) + damping L_dot - f(t) pulls the points together.
    """

    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    stiffness: float = 0.0
    damping: float = 0.0
    length0: float = 0.0
    f: TimeFunction = field(default_factory=TimeFunction)
    type: ClassVar[str] = "spring"
    kind: ClassVar[int] = 1

    def raw(self) -> list[float]:
        return [*self.points[0], *self.points[1], self.stiffness, self.damping, self.length0,
                *self.f.encode()]


@dataclass
class Torque(Force):
    """A torque f(t) on a body (reaction on ground)."""

    f: TimeFunction = field(default_factory=TimeFunction)
    type: ClassVar[str] = "torque"
    kind: ClassVar[int] = 2

    def raw(self) -> list[float]:
        return self.f.encode()


@dataclass
class PointForce(Force):
    """A force (fx(t), fy(t)) in global components at a body point."""

    point: tuple[float, float] = (0.0, 0.0)
    fx: TimeFunction = field(default_factory=TimeFunction)
    fy: TimeFunction = field(default_factory=TimeFunction)
    type: ClassVar[str] = "point"
    kind: ClassVar[int] = 3

    def raw(self) -> list[float]:
        return [*self.point, *self.fx.encode(), *self.fy.encode()]


@dataclass
class RotationalSpring(Force):
    """Rotational spring-damper between two bodies: on body j the torque
    -stiffness (a - angle0) - damping a_dot + f(t), a = theta_j - theta_i; the opposite on i."""

    stiffness: float = 0.0
    damping: float = 0.0
    angle0: float = 0.0
    f: TimeFunction = field(default_factory=TimeFunction)
    type: ClassVar[str] = "rotational-spring"
    kind: ClassVar[int] = 4

    def raw(self) -> list[float]:
        return [self.stiffness, self.damping, self.angle0, *self.f.encode()]


FORCE_KEYS = {
    "spring": ({"bodies", "points", "stiffness", "damping", "length0", "f"},
               {"bodies", "points"}),
    "torque": ({"body", "f"}, {"body", "f"}),
    "point": ({"body", "point", "fx", "fy"}, {"body"}),
    "rotational-spring": ({"bodies", "stiffness", "damping", "angle0", "f"}, {"bodies"}),
}

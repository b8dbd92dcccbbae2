"""Drivers: driving constraints g(q) - f(t) = 0, rows of Phi after the joints."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, ClassVar

from .functions import TimeFunction
from .joints import COORDINATES, BodyIndex, Constraint


@dataclass
class Driver(Constraint):
    """A driving constraint g(q) - f(t) = 0."""

    f: TimeFunction = TimeFunction()
    is_driver: ClassVar[bool] = True

    def describe(self) -> str:
        return f"driver '{self.name}'"

    def raw(self) -> list[float]:
        return self.f.encode()


@dataclass
class AbsoluteDriver(Driver):
    """x, y or theta of a body = f(t)."""

    coordinate: str = "theta"
    type: ClassVar[str] = "absolute"
    kind: ClassVar[int] = 101

    @property
    def labels(self) -> tuple[str, ...]:  # type: ignore[override]
        return (self.coordinate,)

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        return COORDINATES[self.coordinate], 0


@dataclass
class RelativeAngleDriver(Driver):
    """theta_j - theta_i = f(t)."""

    type: ClassVar[str] = "relative-angle"
    kind: ClassVar[int] = 102
    labels: ClassVar[tuple[str, ...]] = ("angle",)


@dataclass
class RelativeDistanceDriver(Driver):
    """The slide along a translational joint = f(t)."""

    joint: str = ""
    type: ClassVar[str] = "relative-distance"
    kind: ClassVar[int] = 103
    labels: ClassVar[tuple[str, ...]] = ("slide",)

    def subkinds(self, body_index: BodyIndex, joint_index: Callable[[str], int]) -> tuple[int, int]:
        return joint_index(self.joint), 0

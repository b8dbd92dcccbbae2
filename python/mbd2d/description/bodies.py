"""Bodies: moving rigid bodies of a model (ground is implicit)."""
from __future__ import annotations

from dataclasses import dataclass


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
    v0: tuple[float, float, float] = (0.0, 0.0, 0.0)

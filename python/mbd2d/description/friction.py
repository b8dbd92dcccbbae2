"""Coulomb friction on joints and contacts (``fortran/mbd_contact.f90``)::

    friction = { mu = 0.3, mu_static = 0.4, model = "stick-slip", threshold = 1e-4,
                 pin_radius = 0.01 }

``model``: ``"regularized"`` (default; a smooth Coulomb curve, mu_static at the threshold
velocity, mu above twice it) or ``"stick-slip"`` (exact Coulomb with sticking, joints only);
``threshold``: the velocity of the regularized curve (default 1e-4 of the model's length
scale per second); ``pin_radius``: the radius of a revolute's friction circle.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..errors import ModelError
from ..validate import choice, number, only_keys, positive, table

FRICTION_MODELS = {"regularized": 0, "stick-slip": 1}
FRICTION_KIND = 9          #: force kind of a joint's friction (mbd_forces FRC_FRICTION)


@dataclass(frozen=True)
class Friction:
    """Coulomb friction: kinetic mu, static mu_static, the model and its threshold velocity
    (0: the default, 1e-4 of the model's length scale per second), and for a revolute the
    pin radius."""

    mu: float
    mu_static: float
    model: str = "regularized"
    threshold: float = 0.0
    pin_radius: float | None = None

    def raw(self) -> list[float]:
        """[mu, mu_s, model code, threshold, pin radius] (the joint friction element)."""
        return [self.mu, self.mu_static, float(FRICTION_MODELS[self.model]), self.threshold,
                self.pin_radius or 0.0]


NO_FRICTION = Friction(0.0, 0.0)


def parse_friction(spec: Any, entry: str, revolute: bool = False,
                   pin_radius: Any = None, joint: bool = True) -> Friction:
    """``{mu, mu_static, model, threshold, pin_radius}``; ``pin_radius`` may also come from
    the joint (revolute only). ``joint``: on a joint (else on a contact: no pin radius,
    regularized only)."""
    spec = table(spec, "friction", entry)
    allowed = {"mu", "mu_static", "model", "threshold"}
    if revolute:
        allowed.add("pin_radius")
    only_keys(spec, allowed, f"{entry} friction", required=["mu"])
    mu = number(spec["mu"], "friction.mu", entry)
    mus = number(spec.get("mu_static", mu), "friction.mu_static", entry)
    if mu < 0.0 or mus < 0.0:
        raise ModelError("friction coefficients must be >= 0", entry)
    model = choice(spec.get("model", "regularized"), FRICTION_MODELS, "friction.model", entry)
    if not joint and model != "regularized":
        raise ModelError("contact friction is the regularized Coulomb law (stick-slip is "
                         "for revolute and translational joints)", entry)
    if model == "stick-slip" and mus < mu:
        raise ModelError(f"stick-slip friction needs mu_static >= mu, got {mus!r} < {mu!r}",
                         entry)
    vth = spec.get("threshold")
    vt = 0.0 if vth is None else positive(vth, "friction.threshold", entry)
    rp = None
    if revolute:
        given = spec.get("pin_radius")
        if given is not None and pin_radius is not None:
            raise ModelError("give pin_radius once (in the friction table or on the joint)",
                             entry)
        given = pin_radius if given is None else given
        if given is None:
            raise ModelError("revolute friction needs pin_radius, the radius of the pin "
                             "(friction circle): friction = { mu = ..., pin_radius = ... }",
                             entry)
        rp = positive(given, "pin_radius", entry)
    return Friction(mu, mus, model, vt, rp)


__all__ = ["FRICTION_MODELS", "FRICTION_KIND", "Friction", "NO_FRICTION", "parse_friction"]

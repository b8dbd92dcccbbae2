"""Contacts and friction: penalty contacts between body surfaces, and Coulomb friction on
contacts and on revolute and translational joints (``fortran/mbd_contact.f90``)::

    [[contact]]
    name = "ball-floor"
    type = "circle-line"                 # circle on body 1 against a line on body 2
    bodies = ["ball", "ground"]
    circle = { center = [0.0, 0.0], radius = 0.1 }
    line = { point = [0.0, 0.0], normal = [0.0, 1.0] }   # solid opposite the normal
    law = { model = "hunt-crossley", stiffness = 1e7, exponent = 1.5, restitution = 0.8 }
    friction = { mu = 0.3 }

Types: ``circle-line``; ``circle-circle`` (two outer surfaces, ``circle = [{...}, {...}]``,
one per body); ``circle-in-circle`` (a pin of body 1 in a hole of body 2: the revolute joint
with clearance, ``circle = [pin, hole]``); ``follower-profile`` (the cam joint's ``profile``
on body 1 and ``follower`` on body 2, in the cam joint's forms, so that the follower can lift
off). Laws: ``linear``, ``hertz``, ``hunt-crossley``, ``lankarani-nikravesh``, ``flores``.

Joint friction: ``friction = { mu, mu_static, model, threshold, pin_radius }`` on a revolute
(``pin_radius``, the radius of the friction circle, also as a joint key) or a translational
joint; ``model`` is ``"regularized"`` (default) or ``"stick-slip"``.

Contacts and joint frictions are packed as force elements after the ``[[force]]`` entries
(contacts first, then the frictions in joint order).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Mapping, Sequence

from ..errors import ModelError
from ..validate import as_list, choice, nonzero_vector, number, only_keys, positive, table, vector
from .friction import NO_FRICTION, Friction
from .joints import parse_follower, parse_profile

LAWS = {"linear": 1, "hertz": 2, "hunt-crossley": 3, "lankarani-nikravesh": 4, "flores": 5}
CONTACT_TYPES = {"circle-line": 5, "circle-circle": 6, "circle-in-circle": 7,
                 "follower-profile": 8}
DEFAULT_EXPONENT = 1.5     #: Hertz's exponent (circular contact), for the nonlinear laws

#: TOML keys of each contact type: (allowed, required)
CONTACT_KEYS = {
    "circle-line": ({"bodies", "circle", "line", "law", "friction"},
                    {"bodies", "circle", "line", "law"}),
    "circle-circle": ({"bodies", "circle", "law", "friction"}, {"bodies", "circle", "law"}),
    "circle-in-circle": ({"bodies", "circle", "law", "friction"}, {"bodies", "circle", "law"}),
    "follower-profile": ({"bodies", "profile", "follower", "law", "friction"},
                         {"bodies", "profile", "follower", "law"}),
}


@dataclass(frozen=True)
class ContactLaw:
    """Normal force law: model, stiffness k (Fn = k delta**exponent), exponent, restitution."""

    model: str
    stiffness: float
    exponent: float
    restitution: float

    def raw(self) -> list[float]:
        return [float(LAWS[self.model]), self.stiffness, self.exponent, self.restitution]




@dataclass
class Contact:
    """A penalty contact between a surface of bodies[0] and one of bodies[1]."""

    name: str
    type: str
    bodies: tuple[str, str]
    geometry: tuple[float, ...]
    law: ContactLaw
    friction: Friction = NO_FRICTION
    profile_kind: str | None = None
    follower_kind: str | None = None
    section: ClassVar[str] = "contact"

    @property
    def kind(self) -> int:
        """Force kind of the core (mbd_forces)."""
        return CONTACT_TYPES[self.type]

    def describe(self) -> str:
        """How messages name this entry."""
        return f"contact '{self.name}' ({self.type})"

    def raw(self) -> list[float]:
        """[law, k, n, e, mu, mu_s, threshold, geometry...] (mbd_contact)."""
        f = self.friction
        return [*self.law.raw(), f.mu, f.mu_static, f.threshold, *self.geometry]


def parse_law(spec: Any, entry: str) -> ContactLaw:
    """``{model, stiffness, exponent, restitution}``."""
    spec = table(spec, "law", entry)
    only_keys(spec, {"model", "stiffness", "exponent", "restitution"}, f"{entry} law",
              required=["model", "stiffness"])
    model = choice(spec["model"], LAWS, "law.model", entry)
    k = positive(spec["stiffness"], "law.stiffness", entry)
    default_n = 1.0 if model == "linear" else DEFAULT_EXPONENT
    n = number(spec.get("exponent", default_n), "law.exponent", entry)
    if model == "linear" and n != 1.0:
        raise ModelError("the linear law has exponent 1 (for Fn = k delta**n use hertz, "
                         "hunt-crossley, lankarani-nikravesh or flores)", entry)
    if not 1.0 <= n <= 3.0:
        raise ModelError(f"law.exponent must be from 1 to 3 (Hertz: 1.5), got {n!r}", entry)
    e = number(spec.get("restitution", 1.0), "law.restitution", entry)
    if not 0.0 < e <= 1.0:
        raise ModelError(f"law.restitution must be in (0, 1], got {e!r}", entry)
    if model == "hertz" and e != 1.0:
        raise ModelError("the hertz law is elastic (restitution 1); for e < 1 use "
                         "hunt-crossley, lankarani-nikravesh, flores or linear", entry)
    return ContactLaw(model, k, n, e)


def _circle(spec: Any, what: str, entry: str) -> tuple[float, float, float]:
    spec = table(spec, what, entry)
    only_keys(spec, {"center", "radius"}, f"{entry} {what}", required=["center", "radius"])
    c = vector(spec["center"], 2, f"{what}.center", entry)
    return (c[0], c[1], positive(spec["radius"], f"{what}.radius", entry))


def _circles(spec: Any, entry: str) -> tuple[float, ...]:
    spec = as_list(spec)
    if isinstance(spec, Mapping) or isinstance(spec, (str, bytes)) \
            or not isinstance(spec, Sequence) or len(spec) != 2:
        raise ModelError("circle must be a list of two circles [{center, radius}, {center, "
                         "radius}], one on each body", entry)
    return (*_circle(spec[0], "circle[0]", entry), *_circle(spec[1], "circle[1]", entry))


def contact_geometry(type: str, entry: str, circle: Any = None, line: Any = None,
                     profile: Any = None, follower: Any = None
                     ) -> tuple[tuple[float, ...], str | None, str | None]:
    """The raw geometry of a contact type from its keys (and the profile and follower kinds
    of a follower-profile contact)."""
    if type == "circle-line":
        c = _circle(circle, "circle", entry)
        spec = table(line, "line", entry)
        only_keys(spec, {"point", "normal"}, f"{entry} line", required=["point", "normal"])
        p = vector(spec["point"], 2, "line.point", entry)
        n = nonzero_vector(spec["normal"], "line.normal", entry)
        return (*c, *p, *n), None, None
    if type in ("circle-circle", "circle-in-circle"):
        g = _circles(circle, entry)
        if type == "circle-in-circle" and not g[5] > g[2]:
            raise ModelError("circle-in-circle: the hole (circle[1], on the second body) must "
                             "be larger than the pin (circle[0])", entry)
        return g, None, None
    pkind, pparams = parse_profile(profile, entry)
    fkind, fparams = parse_follower(follower, entry)
    fcode = {"point": 1.0, "roller": 2.0, "flat": 3.0}[fkind]
    pcode = {"circle": 1.0, "spline": 2.0, "fourier": 3.0}[pkind]
    return (fcode, *fparams, pcode, *pparams), pkind, fkind


__all__ = ["LAWS", "CONTACT_TYPES", "CONTACT_KEYS", "ContactLaw", "Contact", "parse_law",
           "contact_geometry"]

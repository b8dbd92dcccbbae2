"""Design parameters by name: every numeric entry of a model that a designer may vary.

A name is the entry's path in the model file, entries addressed by their ``name`` and list
positions by index (0-based)::

    joint.A.points.1.0          x of joint A's point on its second body
    joint.guide.axes.0.1        y of the axis of the translational joint 'guide' on body i
    joint.cam.profile.spline.points.3.1   a cam profile's spline point
    body.crank.mass             body.crank.inertia
    force.s1.stiffness          force.s1.f.poly.0
    driver.motor.f.poly.1       driver.motor.f.harmonic.0.omega    driver.lift.f.step.0.t1
    model.gravity.1
    contact.floor.law.stiffness    contact.floor.circle.radius    contact.floor.friction.mu
    joint.A.friction.mu            joint.A.friction.pin_radius

Builder-made models get the same names (their entries have names too). Each parameter knows
where its value enters the flat tables the core reads (a constraint's or a force's raw
parameters, the masses, gravity), so the core can differentiate with respect to it.
"""
from __future__ import annotations

import copy
import dataclasses
import difflib
from dataclasses import dataclass
from typing import Any, Iterable, Iterator, Mapping

from ..errors import ModelError
from ..validate import number
from .functions import TimeFunction

#: where a parameter enters the core's tables
TABLES = ("constraint", "mass", "gravity", "force")


@dataclass(frozen=True)
class Parameter:
    """One design parameter.

    Attributes
    ----------
    name : str
        Its path, e.g. ``joint.A.points.1.0``.
    section : {'joint', 'driver', 'body', 'force', 'contact', 'model'}
        The kind of entry that holds it.
    index : int
        The entry's position in its list (``model.joints``, ``model.drivers``,
        ``model.bodies``, ``model.forces``, ``model.contacts``; 0 for the model).
    field : str
        The entry's attribute that holds it.
    path : tuple
        Position inside that attribute (tuple indices, attribute names of a function).
    table : {'constraint', 'mass', 'gravity', 'force'}
        The core table it enters.
    element : int
        The element of that table: the constraint (joints then drivers), the force element
        (forces, then contacts, then the joints' frictions), or the body; 0 for gravity.
    raw : int
        Its position in the element's raw parameters (mass 0, inertia 1; gravity 0, 1).
    value : float or None
        Its value (None for a gear or rolling phase left to the q0 estimates).
    """

    name: str
    section: str
    index: int
    field: str
    path: tuple[Any, ...]
    table: str
    element: int
    raw: int
    value: float | None


# ------------------------------------------------------------------ one entry's parameters
# Each helper yields (suffix, field, path, raw): the name after the entry's prefix, where the
# value sits in the entry, and its position in the entry's raw() list.

def _pairs(key: str, raw0: int, n: int = 2) -> Iterator[tuple[str, str, tuple, int]]:
    for i in range(n):
        for j in range(2):
            yield f"{key}.{i}.{j}", key, (i, j), raw0 + 2 * i + j


def _vec(key: str, raw0: int, field: str | None = None,
         at: int = 0) -> Iterator[tuple[str, str, tuple, int]]:
    for j in range(2):
        yield f"{key}.{j}", field or key, (at + j,) if field else (j,), raw0 + j


def _function(key: str, f: TimeFunction, raw0: int) -> Iterator[tuple[str, str, tuple, int]]:
    """A function of time: poly.k, harmonic.h.(amplitude | omega | phase),
    step.s.(t0 | t1 | h) (a step's law is not a number) and table.y.k (the table's values;
    its times are not parameters)."""
    for k in range(len(f.poly)):
        yield f"{key}.poly.{k}", key, ("poly", k), raw0 + 1 + k
    base = raw0 + len(f.poly) + 2
    for h in range(len(f.harmonic)):
        for a, attr in enumerate(("amplitude", "omega", "phase")):
            yield f"{key}.harmonic.{h}.{attr}", key, ("harmonic", h, attr), base + 3 * h + a
    base += 3 * len(f.harmonic) + 1            # (after ns: law, t0, t1, h per step)
    for s in range(len(f.step)):
        for a, attr in enumerate(("t0", "t1", "h")):
            yield f"{key}.step.{s}.{attr}", key, ("step", s, attr), base + 4 * s + 1 + a
    base += 4 * len(f.step) + 1                # (after nt and the times: the values)
    if f.table is not None:
        n = len(f.table.t)
        for k in range(n):
            yield f"{key}.table.y.{k}", key, ("table", "y", k), base + n + k


def _profile(key: str, kind: str, prof: tuple[float, ...]) -> Iterator[tuple[str, str, tuple,
                                                                             int]]:
    """A closed profile (raw: after the follower's 4 entries)."""
    pre = f"{key}.{kind}"
    if kind == "circle":
        yield from _vec(f"{pre}.center", 4, "profile", 0)
        yield f"{pre}.radius", "profile", (2,), 6
    elif kind == "spline":
        for i in range(int(prof[0])):
            for j in range(2):
                yield f"{pre}.points.{i}.{j}", "profile", (1 + 2 * i + j,), 5 + 2 * i + j
    else:   # fourier: (cx, cy, K, a0, a1, b1, ..., aK, bK)
        yield from _vec(f"{pre}.center", 4, "profile", 0)
        yield f"{pre}.a.0", "profile", (3,), 7
        for k in range(int(prof[2])):
            yield f"{pre}.a.{k + 1}", "profile", (4 + 2 * k,), 8 + 2 * k
            yield f"{pre}.b.{k}", "profile", (5 + 2 * k,), 9 + 2 * k


def _follower(kind: str, curve: bool) -> Iterator[tuple[str, str, tuple, int]]:
    if curve:                       # point-on-curve: the point is the follower
        yield from _vec("point", 0, "follower", 0)
    elif kind == "point":
        yield from _vec("follower.point", 0, "follower", 0)
    elif kind == "roller":
        yield from _vec("follower.roller.center", 0, "follower", 0)
        yield "follower.roller.radius", "follower", (2,), 2
    else:
        yield from _vec("follower.flat.point", 0, "follower", 0)
        yield from _vec("follower.flat.normal", 2, "follower", 2)


def _constraint(c: Any) -> Iterator[tuple[str, str, tuple, int]]:
    """The parameters of a joint or driver, by its TOML keys."""
    t = c.type
    if hasattr(c, "f"):                                     # drivers
        yield from _function("f", c.f, 0)
    elif t in ("cam", "point-on-curve"):
        yield from _follower(c.follower_kind, t == "point-on-curve")
        yield from _profile("curve" if t == "point-on-curve" else "profile", c.profile_kind,
                            c.profile)
    elif t == "revolute":
        yield from _pairs("points", 0)
    elif t == "translational":
        yield from _pairs("points", 0)
        yield from _pairs("axes", 4)
    elif t == "distance":
        yield from _pairs("points", 0)
        yield "distance", "distance", (), 4
    elif t in ("point-on-line", "revolute-translational"):
        yield from _pairs("points", 0)
        yield from _vec("axis", 4)
        yield "offset", "offset", (), 6
    elif t == "weld":
        yield from _pairs("points", 0)
        yield "angle", "angle", (), 4
    elif t == "gear":
        yield from _vec("radii", 0)
        yield "phase", "phase", (), 2
        yield "pressure_angle", "pressure_angle", (), 3
        if c.centers is not None:
            yield from _pairs("centers", 4)
    elif t in ("rack-pinion", "rolling-disc"):
        yield from _vec("center", 0)
        yield from _vec("point", 2)
        yield from _vec("axis", 4)
        yield "radius", "radius", (), 6
        yield "phase", "phase", (), 7
    elif t == "absolute":
        yield "value", "value", (), 0


def _force(f: Any) -> Iterator[tuple[str, str, tuple, int]]:
    """The parameters of a force element, by its TOML keys."""
    t = f.type
    if t == "spring":
        yield from _pairs("points", 0)
        for k, key in enumerate(("stiffness", "damping", "length0")):
            yield key, key, (), 4 + k
        yield from _function("f", f.f, 7)
    elif t == "torque":
        yield from _function("f", f.f, 0)
    elif t == "point":
        yield from _vec("point", 0)
        yield from _function("fx", f.fx, 2)
        yield from _function("fy", f.fy, 2 + len(f.fx.encode()))
    elif t == "rotational-spring":
        for k, key in enumerate(("stiffness", "damping", "angle0")):
            yield key, key, (), k
        yield from _function("f", f.f, 3)


def _contact(c: Any) -> Iterator[tuple[str, str, tuple, int]]:
    """The parameters of a contact, by its TOML keys (raw: law code, k, n, e, mu, mu_s,
    threshold, then the geometry); a law's fixed numbers (the linear law's exponent, the
    elastic hertz law's restitution) are not parameters."""
    yield "law.stiffness", "law", ("stiffness",), 1
    if c.law.model != "linear":
        yield "law.exponent", "law", ("exponent",), 2
    if c.law.model != "hertz":
        yield "law.restitution", "law", ("restitution",), 3
    for k, key in enumerate(("mu", "mu_static", "threshold")):
        yield f"friction.{key}", "friction", (key,), 4 + k
    if c.type == "circle-line":
        keys = ["circle.center.0", "circle.center.1", "circle.radius", "line.point.0",
                "line.point.1", "line.normal.0", "line.normal.1"]
    elif c.type in ("circle-circle", "circle-in-circle"):
        keys = [f"circle.{j}.{key}" for j in range(2)
                for key in ("center.0", "center.1", "radius")]
    else:       # follower-profile: (follower code, its 4 numbers, profile code, the profile)
        for suffix, _, path, _ in _follower(c.follower_kind, False):
            yield suffix, "geometry", (1 + path[0],), 8 + path[0]
        for suffix, _, path, _ in _profile("profile", c.profile_kind, c.geometry[6:]):
            yield suffix, "geometry", (6 + path[0],), 13 + path[0]
        return
    for i, key in enumerate(keys):
        yield key, "geometry", (i,), 7 + i


def _joint_friction(c: Any) -> Iterator[tuple[str, str, tuple, int]]:
    """The parameters of a joint's friction (raw: mu, mu_s, model code, threshold, pin
    radius; the pin radius a revolute's only)."""
    keys = [("mu", 0), ("mu_static", 1), ("threshold", 3)]
    if c.type == "revolute":
        keys.append(("pin_radius", 4))
    for key, raw in keys:
        yield f"friction.{key}", "friction", (key,), raw


# ------------------------------------------------------------------ values in an entry

def _get(obj: Any, field: str, path: tuple) -> Any:
    v = getattr(obj, field)
    for step in path:
        v = getattr(v, step) if isinstance(step, str) else v[step]
    return v


def _replaced(v: Any, path: tuple, value: float) -> Any:
    """v with the element at path replaced (tuples and frozen dataclasses rebuilt)."""
    if not path:
        return value
    step, rest = path[0], path[1:]
    if isinstance(step, str):
        return dataclasses.replace(v, **{step: _replaced(getattr(v, step), rest, value)})
    items = list(v)
    items[step] = _replaced(items[step], rest, value)
    return tuple(items)


# ------------------------------------------------------------------ the model's parameters

def parameter_list(model: Any) -> list[Parameter]:
    """Every design parameter of a model, in table order (joints, drivers, bodies, forces,
    contacts, the joints' frictions, gravity)."""
    out: list[Parameter] = []
    nj = len(model.joints)
    for sec, entries, offset in (("joint", model.joints, 0), ("driver", model.drivers, nj)):
        for i, c in enumerate(entries):
            for suffix, field, path, raw in _constraint(c):
                out.append(Parameter(f"{sec}.{c.name}.{suffix}", sec, i, field, path,
                                     "constraint", offset + i, raw, _float(_get(c, field, path))))
    for i, b in enumerate(model.bodies):
        for raw, key in enumerate(("mass", "inertia")):
            if getattr(b, key) is not None:
                out.append(Parameter(f"body.{b.name}.{key}", "body", i, key, (), "mass", i, raw,
                                     float(getattr(b, key))))
    for i, f in enumerate(model.forces):
        for suffix, field, path, raw in _force(f):
            out.append(Parameter(f"force.{f.name}.{suffix}", "force", i, field, path, "force",
                                 i, raw, _float(_get(f, field, path))))
    element = len(model.forces)                   # the force elements' order (pack_dynamics)
    for i, c in enumerate(model.contacts):
        for suffix, field, path, raw in _contact(c):
            out.append(Parameter(f"contact.{c.name}.{suffix}", "contact", i, field, path,
                                 "force", element + i, raw, _float(_get(c, field, path))))
    element += len(model.contacts)
    for i, c in enumerate(model.joints):
        if getattr(c, "friction", None) is None:
            continue
        for suffix, field, path, raw in _joint_friction(c):
            out.append(Parameter(f"joint.{c.name}.{suffix}", "joint", i, field, path, "force",
                                 element, raw, _float(_get(c, field, path))))
        element += 1
    for j in range(2):
        out.append(Parameter(f"model.gravity.{j}", "model", 0, "gravity", (j,), "gravity", 0, j,
                             float(model.gravity[j])))
    return out


def _float(v: Any) -> float | None:
    return None if v is None else float(v)


def find(model: Any, names: Iterable[str], where: str = "parameters") -> list[Parameter]:
    """The parameters called names, in that order.

    Raises
    ------
    ModelError
        For an unknown name (naming it and the closest existing names) or a repeated one.
    """
    if isinstance(names, str):
        raise ModelError("parameter names must be a list of names, not one string", where)
    try:
        names = list(names)
    except TypeError:
        raise ModelError(f"parameter names must be a list of names, got {names!r}",
                         where) from None
    table = {p.name: p for p in parameter_list(model)}
    out = []
    for name in names:
        if not isinstance(name, str) or name not in table:
            close = difflib.get_close_matches(str(name), table, n=4, cutoff=0.5)
            hint = f"; did you mean {', '.join(close)}?" if close else \
                "; model.parameters() lists them all"
            raise ModelError(f"unknown parameter {name!r}{hint}", where)
        out.append(table[name])
    if len(set(p.name for p in out)) != len(out):
        raise ModelError("a parameter is named twice", where)
    return out


def with_params(model: Any, values: Mapping[str, Any]) -> Any:
    """A copy of the model with the named parameters set; the model itself is unchanged.

    Raises
    ------
    ModelError
        For an unknown name or a value that is not a finite number.
    """
    if not isinstance(values, Mapping):
        raise ModelError("with_params takes a mapping {name: value}", "with_params")
    params = find(model, list(values), "with_params")
    new = copy.deepcopy(model)
    for p in params:
        v = number(values[p.name], p.name, "with_params")
        if p.section == "model":
            new.gravity = _replaced(tuple(new.gravity), p.path, v)
            continue
        entries = {"joint": new.joints, "driver": new.drivers, "body": new.bodies,
                   "force": new.forces, "contact": new.contacts}[p.section]
        e = entries[p.index]
        entries[p.index] = dataclasses.replace(e, **{p.field: _replaced(getattr(e, p.field),
                                                                        p.path, v)})
    return new


def constraints_with(model: Any, params: Iterable[Parameter],
                     values: Iterable[float]) -> list[Any]:
    """The model's constraints (joints, then drivers) with the given joint and driver
    parameters set to values: a new list in which only the changed entries are new; the
    model is unchanged. Parameters of other sections are left out."""
    cons = list(model.constraints)
    nj = len(model.joints)
    for p, v in zip(params, values):
        if p.section not in ("joint", "driver") or p.table != "constraint":
            continue
        k = p.index + (nj if p.section == "driver" else 0)
        e = cons[k]
        cons[k] = dataclasses.replace(e, **{p.field: _replaced(getattr(e, p.field), p.path,
                                                               float(v))})
    return cons


__all__ = ["Parameter", "TABLES", "parameter_list", "find", "with_params", "constraints_with"]

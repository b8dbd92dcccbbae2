"""The TOML model format (a public contract; see README)::

    [model]            name, gravity
    [[body]]           name, q0, mass, inertia
    [[joint]]          name, type, bodies, points, axes, profile, follower
    [[driver]]         name, type, body, coordinate, bodies, joint, f
    [[force]]          name, type, bodies, body, points, point, stiffness, damping, length0,
                       angle0, f, fx, fy
    [[contact]]        name, type, bodies, circle, line, profile, follower, law, friction

Every key goes through the builder methods of
:class:`~mbd2d.description.builder.ModelDescription`, so a TOML model and a model built in code
are checked the same way. The functions here build any subclass of it (``cls``);
:func:`mbd2d.load` and :func:`mbd2d.loads` build the analysable :class:`mbd2d.Model`.
"""
from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any, Mapping, TypeVar

from ..errors import ModelError
from ..validate import only_keys, table
from .builder import ModelDescription
from .contacts import CONTACT_KEYS
from .entries import reading
from .functions import table_columns

M = TypeVar("M", bound=ModelDescription)

SECTIONS = {"model", "body", "joint", "driver", "force", "contact"}


def load(path: str | Path, cls: type[M] = ModelDescription) -> M:  # type: ignore[assignment]
    """Read a model from a TOML file.

    Parameters
    ----------
    path : str or Path
        The .toml file.
    cls : type
        The class to build (a subclass of ModelDescription).

    Returns
    -------
    cls instance

    Raises
    ------
    ModelError
        If the file is missing, is not valid TOML, or describes an invalid model; the message
        names the entry and the key.

    Examples
    --------
    >>> load("examples/fourbar_seed.toml")
    ModelDescription('seed-four-bar': 3 bodies, 4 joints, 1 drivers)
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"the model file must be a path (str or pathlib.Path), got {path!r}",
                         "load")
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise ModelError(f"cannot read the model file: {exc.strerror}", str(p)) from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"the model file is not UTF-8 text (byte {exc.start}); save it as "
                         "UTF-8", str(p)) from None
    return loads(text, source=str(p), cls=cls, base=p.parent)


def loads(text: str, source: str = "<string>",
          cls: type[M] = ModelDescription,  # type: ignore[assignment]
          base: str | Path | None = None) -> M:
    """Read a model from TOML text; see :func:`load`. ``base``: the directory that table
    files (``table = { file = "motion.csv" }``) are relative to (default: the current
    one)."""
    if not isinstance(text, str):
        raise ModelError(f"the model text must be a str (decode bytes first), got "
                         f"{type(text).__name__}", source if isinstance(source, str) else "loads")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"not valid TOML: {exc}", source) from None
    if base is not None and not isinstance(base, (str, os.PathLike)):
        raise ModelError(f"base must be a directory path, got {base!r}", "loads")
    _table_files(data, Path(base) if base is not None else Path.cwd())
    return from_dict(data, source, cls=cls)


def _table_files(data: Any, base: Path) -> None:
    """Replace each ``table = { file = ..., columns = [i, j] }`` of a driver's or force's
    function by the file's columns (t, y)."""
    for sec in ("driver", "force"):
        entries = data.get(sec) if isinstance(data, dict) else None
        for e in entries if isinstance(entries, list) else []:
            for key in ("f", "fx", "fy"):
                f = e.get(key) if isinstance(e, dict) else None
                tab = f.get("table") if isinstance(f, dict) else None
                if isinstance(tab, dict) and "file" in tab:
                    f["table"] = read_table(tab, base, f"[[{sec}]]{_named(e)}")


def read_table(spec: Mapping[str, Any], base: Path, entry: str) -> dict[str, list[float]]:
    """A TOML table ``{ file = ..., columns = [i, j] }``: the file's columns (t, y) (see
    :func:`mbd2d.description.functions.table_columns`)."""
    only_keys(spec, {"file", "columns"}, entry)
    name, cols = spec["file"], spec.get("columns", [0, 1])
    if not isinstance(name, str):
        raise ModelError(f"table.file must be a file name, got {name!r}", entry)
    t, y = table_columns(base / name, cols, entry)
    return {"t": t, "y": y}


def _entries(data: Mapping[str, Any], key: str, source: str) -> list[Mapping[str, Any]]:
    v = data.get(key, [])
    if isinstance(v, Mapping):
        raise ModelError(f"write [[{key}]] (an array of tables), not [{key}]", source)
    if not isinstance(v, list):
        raise ModelError(f"'{key}' must be an array of tables [[{key}]]", source)
    return v


def _named(entry: Any) -> str:
    """' NAME' for an entry with a string name, else ''."""
    name = entry.get("name") if isinstance(entry, Mapping) else None
    return f" {name!r}" if isinstance(name, str) else ""


def from_dict(data: Mapping[str, Any], source: str = "<dict>",
              cls: type[M] = ModelDescription) -> M:  # type: ignore[assignment]
    """Build a model of class ``cls`` from parsed TOML (nested dicts and lists)."""
    if not isinstance(data, Mapping):
        raise ModelError("a model must be a table", source)
    if any(not isinstance(k, str) for k in data):
        raise ModelError("section names must be strings", source)
    unknown = set(data) - SECTIONS
    if unknown:
        raise ModelError(f"unknown section(s) {sorted(unknown)}; sections are "
                         "[model], [[body]], [[joint]], [[driver]], [[force]], [[contact]]",
                         source)
    head = table(data.get("model", {}), "[model]", source)
    only_keys(head, {"name", "gravity"}, "[model]")
    name = head.get("name", Path(source).stem if source.endswith(".toml") else "model")
    if not isinstance(name, str):
        raise ModelError(f"name must be a string, got {name!r}", "[model]")
    if isinstance(head.get("gravity"), (str, bytes)):
        raise ModelError("gravity must be a list of 2 numbers", "[model]")
    model = cls(name, head.get("gravity", (0.0, -9.81)))
    for i, b in enumerate(_entries(data, "body", source)):
        entry = f"[[body]] #{i + 1}" + _named(b)
        b = table(b, "[[body]]", entry)
        only_keys(b, {"name", "q0", "mass", "inertia", "v0"}, entry, required=["name", "q0"])
        model.add_body(b["name"], b["q0"], b.get("mass"), b.get("inertia"), b.get("v0"))
    for i, j in enumerate(_entries(data, "joint", source)):
        entry = f"[[joint]] #{i + 1}" + _named(j)
        j = dict(table(j, "[[joint]]", entry))
        only_keys(j, set(j) | {"type"}, entry)        # string keys only
        if "type" not in j:
            raise ModelError("missing key 'type' (revolute, translational, cam, ...)", entry)
        model.add_joint(**j)
    for i, d in enumerate(_entries(data, "driver", source)):
        entry = f"[[driver]] #{i + 1}" + _named(d)
        d = dict(table(d, "[[driver]]", entry))
        only_keys(d, set(d), entry)
        only_keys(d, {"name", "type", "body", "coordinate", "bodies", "joint", "f"}, entry,
                  required=["type", "f"])
        model.add_driver(**d)
    for i, fe in enumerate(_entries(data, "force", source)):
        entry = f"[[force]] #{i + 1}" + _named(fe)
        fe = dict(table(fe, "[[force]]", entry))
        only_keys(fe, set(fe) | {"type"}, entry)
        if "type" not in fe:
            raise ModelError("missing key 'type' (spring, torque, point, rotational-spring)",
                             entry)
        model.add_force(**fe)
    for i, ce in enumerate(_entries(data, "contact", source)):
        entry = f"[[contact]] #{i + 1}" + _named(ce)
        ce = dict(table(ce, "[[contact]]", entry))
        only_keys(ce, set(ce) | {"type"}, entry)
        if "type" not in ce:
            raise ModelError("missing key 'type' (circle-line, circle-circle, "
                             "circle-in-circle, follower-profile)", entry)
        ctype = ce["type"]
        if isinstance(ctype, str) and ctype in CONTACT_KEYS:
            allowed, required = CONTACT_KEYS[ctype]
            only_keys(ce, allowed | {"name", "type"}, entry, required=sorted(required))
        model.add_contact(**ce)
    return model


# ------------------------------------------------------------------ writing

def _function_dict(f: Any) -> dict[str, Any]:
    """A TimeFunction as its TOML table."""
    out: dict[str, Any] = {"poly": [float(c) for c in f.poly]}
    if f.harmonic:
        out["harmonic"] = [{"amplitude": h.amplitude, "omega": h.omega, "phase": h.phase}
                           for h in f.harmonic]
    if f.step:
        out["step"] = [{"t0": st.t0, "t1": st.t1, "h": st.h, "law": st.law} for st in f.step]
    if f.table is not None:
        out["table"] = {"t": list(f.table.t), "y": list(f.table.y)}
    return out


def _profile_dict(kind: str, prof: tuple[float, ...]) -> dict[str, Any]:
    """A packed profile (see joints.parse_profile) as its TOML table."""
    if kind == "circle":
        return {"circle": {"center": [prof[0], prof[1]], "radius": prof[2]}}
    if kind == "spline":
        n = int(prof[0])
        return {"spline": {"points": [[prof[1 + 2 * i], prof[2 + 2 * i]] for i in range(n)]}}
    k = int(prof[2])
    a = [prof[3]] + [prof[4 + 2 * i] for i in range(k)]
    b = [prof[5 + 2 * i] for i in range(k)]
    return {"fourier": {"center": [prof[0], prof[1]], "a": a, "b": b}}


def _follower_dict(kind: str, f: tuple[float, ...]) -> dict[str, Any]:
    if kind == "point":
        return {"point": [f[0], f[1]]}
    if kind == "roller":
        return {"roller": {"center": [f[0], f[1]], "radius": f[2]}}
    return {"flat": {"point": [f[0], f[1]], "normal": [f[2], f[3]]}}


def _pairs(p: Any) -> list[list[float]]:
    return [[float(v) for v in xy] for xy in p]


def _joint_dict(c: Any) -> dict[str, Any]:
    """A joint as its [[joint]] table (the keys of :func:`joints.joint_keys`)."""
    t = c.type
    out: dict[str, Any] = {"name": c.name, "type": t}
    if t == "absolute":
        out.update(body=c.bodies[0], coordinate=c.coordinate, value=c.value)
        return out
    out["bodies"] = list(c.bodies)
    if t == "cam":
        out.update(profile=_profile_dict(c.profile_kind, c.profile),
                   follower=_follower_dict(c.follower_kind, c.follower))
    elif t == "point-on-curve":
        out.update(curve=_profile_dict(c.profile_kind, c.profile),
                   point=[c.follower[0], c.follower[1]])
    elif t in ("rack-pinion", "rolling-disc"):
        out.update(center=list(c.center), point=list(c.point), axis=list(c.axis),
                   radius=c.radius)
        if c.phase is not None:
            out["phase"] = c.phase
    elif t == "gear":
        out.update(radii=list(c.radii), internal=c.internal, carrier=c.carrier,
                   pressure_angle=c.pressure_angle)
        if c.phase is not None:
            out["phase"] = c.phase
        if c.centers is not None:
            out["centers"] = _pairs(c.centers)
    else:
        out["points"] = _pairs(c.points)
        if t == "translational":
            out["axes"] = _pairs(c.axes)
        elif t == "distance":
            out["distance"] = c.distance
        elif t in ("point-on-line", "revolute-translational"):
            out.update(axis=list(c.axis), offset=c.offset)
        elif t == "weld":
            out["angle"] = c.angle
    if getattr(c, "friction", None) is not None:
        out["friction"] = _friction_dict(c.friction)
    return out


def _friction_dict(f: Any, joint: bool = True) -> dict[str, Any]:
    """A joint's or a contact's friction as its TOML table (threshold 0: the default)."""
    out: dict[str, Any] = {"mu": f.mu, "mu_static": f.mu_static}
    if joint:
        out["model"] = f.model
    if f.threshold:
        out["threshold"] = f.threshold
    if joint and f.pin_radius is not None:
        out["pin_radius"] = f.pin_radius
    return out


def _contact_dict(c: Any) -> dict[str, Any]:
    """A contact as its [[contact]] table (keys of contacts.CONTACT_KEYS)."""
    g = c.geometry
    out: dict[str, Any] = {"name": c.name, "type": c.type, "bodies": list(c.bodies)}
    if c.type == "circle-line":
        out.update(circle={"center": [g[0], g[1]], "radius": g[2]},
                   line={"point": [g[3], g[4]], "normal": [g[5], g[6]]})
    elif c.type in ("circle-circle", "circle-in-circle"):
        out["circle"] = [{"center": [g[3 * j], g[3 * j + 1]], "radius": g[3 * j + 2]}
                         for j in range(2)]
    else:                       # (follower code, its 4 numbers, profile code, the profile)
        out.update(profile=_profile_dict(c.profile_kind, g[6:]),
                   follower=_follower_dict(c.follower_kind, g[1:5]))
    law: dict[str, Any] = {"model": c.law.model, "stiffness": c.law.stiffness}
    if c.law.model != "linear":
        law["exponent"] = c.law.exponent
    law["restitution"] = c.law.restitution
    out["law"] = law
    if c.friction.mu or c.friction.mu_static:
        out["friction"] = _friction_dict(c.friction, joint=False)
    return out


def _driver_dict(d: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"name": d.name, "type": d.type}
    if d.type == "absolute":
        out.update(body=d.bodies[0], coordinate=d.coordinate)
    elif d.type == "relative-angle":
        out["bodies"] = list(d.bodies)
    else:
        out["joint"] = d.joint
    out["f"] = _function_dict(d.f)
    return out


def _force_dict(f: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"name": f.name, "type": f.type}
    if f.type == "spring":
        out.update(bodies=list(f.bodies), points=_pairs(f.points), stiffness=f.stiffness,
                   damping=f.damping, length0=f.length0, f=_function_dict(f.f))
    elif f.type == "torque":
        out.update(body=f.bodies[0], f=_function_dict(f.f))
    elif f.type == "point":
        out.update(body=f.bodies[0], point=list(f.point), fx=_function_dict(f.fx),
                   fy=_function_dict(f.fy))
    else:
        out.update(bodies=list(f.bodies), stiffness=f.stiffness, damping=f.damping,
                   angle0=f.angle0, f=_function_dict(f.f))
    return out


def to_dict(model: ModelDescription) -> dict[str, Any]:
    """The model as parsed TOML (nested dicts and lists): :func:`from_dict` of it builds the
    same model (every parameter, q0 and v0 estimate, name and option).

    Examples
    --------
    >>> m = load("examples/fourbar_seed.toml")
    >>> from_dict(to_dict(m)).parameters() == m.parameters()
    True
    """
    bodies = []
    for b in model.bodies:
        e: dict[str, Any] = {"name": b.name, "q0": [float(v) for v in b.q0]}
        if b.mass is not None:
            e["mass"] = b.mass
        if b.inertia is not None:
            e["inertia"] = b.inertia
        if any(v != 0.0 for v in b.v0):
            e["v0"] = [float(v) for v in b.v0]
        bodies.append(e)
    out: dict[str, Any] = {"model": {"name": model.name,
                                     "gravity": [float(g) for g in model.gravity]},
                           "body": bodies, "joint": [_joint_dict(j) for j in model.joints],
                           "driver": [_driver_dict(d) for d in model.drivers]}
    if model.forces:
        out["force"] = [_force_dict(f) for f in model.forces]
    if model.contacts:
        out["contact"] = [_contact_dict(c) for c in model.contacts]
    return out


def _value(v: Any) -> str:
    """One TOML value (inline form)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    return "[" + ", ".join(_value(x) for x in v) + "]"


def dumps(model: ModelDescription, header: str = "") -> str:
    """The model as TOML text in the format :func:`loads` reads (numbers written exactly,
    with ``repr``), optionally after comment lines ``header``.

    Examples
    --------
    >>> text = dumps(load("examples/fourbar_grashof.toml"))
    >>> loads(text).parameters() == load("examples/fourbar_grashof.toml").parameters()
    True
    """
    with reading(model):
        return _dumps(model, header)


def _dumps(model: ModelDescription, header: str) -> str:
    data = to_dict(model)
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    lines += ["[model]"] + [f"{k} = {_value(v)}" for k, v in data["model"].items()]
    for section in ("body", "joint", "driver", "force", "contact"):
        for entry in data.get(section, []):
            lines += ["", f"[[{section}]]"] + [f"{k} = {_value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


def dump(model: ModelDescription, path: str | Path, header: str = "") -> None:
    """Write the model to a TOML file (see :func:`dumps`).

    Raises
    ------
    ModelError
        If the file cannot be written.
    """
    try:
        Path(path).write_text(dumps(model, header), encoding="utf-8")
    except OSError as exc:
        raise ModelError(f"cannot write the model file: {exc.strerror}", str(path)) from None

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
    return loads(text, source=str(p), cls=cls)


def loads(text: str, source: str = "<string>",
          cls: type[M] = ModelDescription) -> M:  # type: ignore[assignment]
    """Read a model from TOML text; see :func:`load`."""
    if not isinstance(text, str):
        raise ModelError(f"the model text must be a str (decode bytes first), got "
                         f"{type(text).__name__}", source if isinstance(source, str) else "loads")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"not valid TOML: {exc}", source) from None
    return from_dict(data, source, cls=cls)


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

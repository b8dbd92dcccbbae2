"""Entries changed after the builder checked them: the field that no longer has its form.

The builder and the TOML loader check every value as it enters the model. A field set later
(``m.bodies[0].q0 = ...``, ``joint.points = ...``) is not checked then; the code that reads
the entries (packing for the core, the parameter list, writing files) runs inside
:func:`reading`, which turns the error such a field causes into a :class:`ModelError` that
names the entry, the field and the form it takes. The checks follow each field's declared
type (``tuple[tuple[float, float], tuple[float, float]]``, ``float | None``, ...) and the
model's names (bodies, joints, kinds); nothing is checked while the entries are well formed.
"""
from __future__ import annotations

import dataclasses
import functools
from contextlib import contextmanager
from typing import Any, Callable, Iterator, TypeVar

from ..errors import MbdError, ModelError
from ..validate import GROUND, NAME_RE, is_number
from .contacts import CONTACT_TYPES
from .joints import COORDINATES, FOLLOWER_KINDS, PROFILE_KINDS, encoded_profile_problem

#: fields whose value is one of a table's keys (a contact's "type" field: joints, drivers and
#: forces have their type as a class constant, not a field)
KINDS = {"profile_kind": PROFILE_KINDS, "follower_kind": FOLLOWER_KINDS,
         "coordinate": COORDINATES, "type": CONTACT_TYPES}
#: the exceptions a malformed field raises where the entries are read
READ_ERRORS = (TypeError, ValueError, KeyError, AttributeError, IndexError)
F = TypeVar("F", bound=Callable[..., Any])


@contextmanager
def reading(model: Any) -> Iterator[None]:
    """Run code that reads the model's entries: an error from a field set to a value of
    the wrong form becomes the ModelError naming it (:func:`check_entries`); any other error
    passes unchanged."""
    try:
        yield
    except MbdError:                                    # (typed already; some are ValueErrors)
        raise
    except READ_ERRORS:
        problem = first_problem(model)
        if problem is None:
            raise
        raise problem from None


def reads_entries(fn: F) -> F:
    """fn(model, ...) run inside :func:`reading` (the front doors that take a model)."""
    @functools.wraps(fn)
    def wrapper(model: Any, *args: Any, **kwargs: Any) -> Any:
        with reading(model):
            return fn(model, *args, **kwargs)
    return wrapper  # type: ignore[return-value]


def check_entries(model: Any) -> None:
    """Check every entry's fields against their declared forms and the model's names.

    Raises
    ------
    ModelError
        Naming the entry, the field, the form it takes and the value it has.
    """
    problem = first_problem(model)
    if problem is not None:
        raise problem


def first_problem(model: Any) -> ModelError | None:
    """The ModelError of the first malformed field (None when every field has its form, or
    model is not a model description)."""
    if not all(hasattr(model, a) for a in ("bodies", "joints", "drivers", "forces", "gravity")):
        return None
    try:
        bodies = {b.name for b in model.bodies if isinstance(b.name, str)} | {GROUND}
        joints = {j.name for j in model.joints if isinstance(j.name, str)}
        entries = [("body", model.bodies), ("joint", model.joints), ("driver", model.drivers),
                   ("force", model.forces), ("contact", getattr(model, "contacts", []))]
    except (AttributeError, TypeError):
        return ModelError("the model's lists of entries were replaced by something else; "
                          "add entries with the builder's add_* methods", "model")
    problem = _vector(model.gravity, 2)
    if problem:
        return ModelError(f"gravity{_sep(problem)}{problem}, got {model.gravity!r}", "[model]")
    for section, items in entries:
        for e in items:
            if not dataclasses.is_dataclass(e):
                return ModelError(f"{e!r} is not an entry; add {section}s with the builder's "
                                  "add_* methods", "model")
            for name, text, v in _problems(e, bodies, joints):
                return ModelError(f"{name}{_sep(text)}{text}, got {v!r}; set it as the "
                                  "builder's add_* methods or the model file take it",
                                  _describe(section, e))
    return None


def _describe(section: str, e: Any) -> str:
    try:
        return str(e.describe())
    except Exception:                                   # (a malformed name or type)
        return f"{section} {getattr(e, 'name', '?')!r}"


def _problems(e: Any, bodies: set[str], joints: set[str]
              ) -> Iterator[tuple[str, str, Any]]:
    """(field, what is wrong, its value) for each malformed field of the dataclass e,
    nested dataclasses (friction, functions, contact laws) included."""
    for f in dataclasses.fields(e):
        v = getattr(e, f.name)
        text = _semantic(f.name, v, bodies, joints)
        if text is None:
            text = _form(str(f.type), v)
        if not text and f.name == "profile" and getattr(e, "profile_kind", None) in PROFILE_KINDS:
            text = encoded_profile_problem(e.profile_kind, v)   # (its layout, by its kind)
        if text:
            yield f.name, text, v
        elif dataclasses.is_dataclass(v) and not isinstance(v, type):
            for sub, t, x in _problems(v, bodies, joints):
                yield f"{f.name}.{sub}", t, x


def _sep(text: str) -> str:
    """No space before an index ("points[0][1] must be ...")."""
    return "" if text.startswith("[") else " "


def _semantic(name: str, v: Any, bodies: set[str], joints: set[str]) -> str | None:
    """The checks a field's name implies ("" when it passes; None: none by name)."""
    if name == "name":
        return "" if isinstance(v, str) and NAME_RE.match(v) else "must be a valid name"
    if name == "bodies":
        if (not isinstance(v, (tuple, list)) or len(v) != 2 or
                not all(isinstance(b, str) for b in v)):
            return "must be two body names"
        unknown = [b for b in v if b not in bodies]
        return f"names no body {unknown[0]!r}" if unknown else ""
    if name in ("body", "carrier"):
        return "" if isinstance(v, str) and v in bodies else "must name a body of the model"
    if name == "joint":
        return "" if isinstance(v, str) and v in joints else "must name a joint of the model"
    if name in KINDS and v is not None:
        return "" if isinstance(v, str) and v in KINDS[name] else \
            f"must be one of {', '.join(KINDS[name])}"
    if name in ("mass", "inertia") and v is not None:
        return "" if is_number(v) and v >= 0.0 else "must be a number >= 0 or None"
    return None


def _form(decl: str, v: Any) -> str:
    """What is wrong with v against the declared type decl ("" when nothing)."""
    alts = _split(decl, "|")
    if len(alts) > 1:
        if v is None and "None" in alts:
            return ""
        texts = [_form(a, v) for a in alts if a != "None"]
        return "" if "" in texts else texts[0]
    decl = decl.strip()
    if decl in ("float", "int"):
        return _number(v)
    if decl == "bool":
        return "" if isinstance(v, bool) else "must be true or false"
    if decl == "str":
        return "" if isinstance(v, str) else "must be a string"
    if decl.startswith("tuple[") and decl.endswith("]"):
        args = _split(decl[6:-1], ",")
        if not isinstance(v, (tuple, list)):
            return f"must be a sequence ({decl})"
        if args[-1] == "...":
            args = args[:1] * len(v)
        elif len(v) != len(args):
            return f"must have {len(args)} entries ({decl})"
        for i, (a, x) in enumerate(zip(args, v)):
            t = _form(a, x)
            if t:                                       # (the entry's index, then the text)
                return f"[{i}]{t}" if t.startswith("[") else f"[{i}] {t}"
        return ""
    if decl[:1].isupper() and decl.isidentifier():     # a class: a dataclass of this package
        return "" if type(v).__name__ == decl else f"must be a {decl}"
    return ""


def _number(v: Any) -> str:
    if not is_number(v):
        return "must be a number"
    return "" if abs(float(v)) < float("inf") else "must be finite"


def _vector(v: Any, n: int) -> str:
    return _form(f"tuple[{', '.join(['float'] * n)}]", v)


def _split(s: str, sep: str) -> list[str]:
    """s split at sep outside brackets, each part stripped."""
    parts, depth, cur = [], 0, ""
    for ch in s:
        depth += ch == "["
        depth -= ch == "]"
        if ch == sep and depth == 0:
            parts.append(cur.strip())
            cur = ""
        else:
            cur += ch
    parts.append(cur.strip())
    return parts

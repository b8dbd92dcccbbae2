"""Small checks shared by the builder and the TOML loader; each raises ModelError naming
the entry."""
from __future__ import annotations

import math
import numbers
import re
from typing import Any, Mapping, Sequence

import numpy as np

from .errors import ModelError

NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]{0,62}$")
GROUND = "ground"


def check_name(name: Any, entry: str) -> str:
    """A name usable in messages, CSV headers and model files."""
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise ModelError(f"name {name!r} is not valid: use letters, digits, '_' or '-', "
                         "starting with a letter or '_' (at most 63 characters)", entry)
    return name


def is_number(x: Any) -> bool:
    """A real number (Python or NumPy), not a bool."""
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


def as_list(x: Any) -> Any:
    """NumPy arrays as nested lists; anything else unchanged."""
    return x.tolist() if isinstance(x, np.ndarray) else x


def number(x: Any, what: str, entry: str) -> float:
    """A finite real number."""
    if not is_number(x):
        raise ModelError(f"{what} must be a number, got {x!r}", entry)
    try:
        v = float(x)
    except (OverflowError, ValueError):
        raise ModelError(f"{what} must be finite, got a number too large for a float",
                         entry) from None
    if not math.isfinite(v):
        raise ModelError(f"{what} must be finite, got {x!r}", entry)
    return v


def positive(x: Any, what: str, entry: str) -> float:
    """A finite number > 0."""
    v = number(x, what, entry)
    if not v > 0.0:
        raise ModelError(f"{what} must be positive, got {x!r}", entry)
    return v


def nonnegative(x: Any, what: str, entry: str) -> float:
    """A finite number >= 0."""
    v = number(x, what, entry)
    if v < 0.0:
        raise ModelError(f"{what} must be >= 0, got {x!r}", entry)
    return v


def vector(x: Any, n: int, what: str, entry: str) -> tuple[float, ...]:
    """A list of n finite numbers."""
    x = as_list(x)
    if isinstance(x, (str, bytes)) or not isinstance(x, Sequence) or len(x) != n:
        raise ModelError(f"{what} must be a list of {n} numbers, got {x!r}", entry)
    return tuple(number(v, f"{what}[{i}]", entry) for i, v in enumerate(x))


def nonzero_vector(x: Any, what: str, entry: str) -> tuple[float, float]:
    """A 2-vector of non-zero length."""
    v = vector(x, 2, what, entry)
    if math.hypot(*v) == 0.0:
        raise ModelError(f"{what} has zero length; give a direction such as [1.0, 0.0]", entry)
    return v  # type: ignore[return-value]


def pairs(x: Any, n: int, what: str, entry: str) -> tuple[tuple[float, float], ...]:
    """n points [x, y]."""
    x = as_list(x)
    if isinstance(x, (str, bytes)) or not isinstance(x, Sequence) or len(x) != n:
        raise ModelError(f"{what} must be a list of {n} [x, y] pairs, got {x!r}", entry)
    return tuple(vector(p, 2, f"{what}[{i}]", entry) for i, p in enumerate(x))  # type: ignore


def choice(x: Any, options: Any, what: str, entry: str) -> str:
    """One of a set of keywords."""
    if not isinstance(x, str) or x not in options:
        raise ModelError(f"{what} must be one of {sorted(options)}, got {x!r}", entry)
    return x


def whole(x: Any, what: str, entry: str, lo: int, hi: int) -> int:
    """A whole number in [lo, hi]."""
    if not (isinstance(x, numbers.Integral) and not isinstance(x, (bool, np.bool_))) \
            or not lo <= int(x) <= hi:
        raise ModelError(f"{what} must be a whole number >= {lo} (at most {hi}), got {x!r}",
                         entry)
    return int(x)


def flag(x: Any, what: str, entry: str) -> bool:
    """True or False (a NumPy bool too)."""
    if not isinstance(x, (bool, np.bool_)):
        raise ModelError(f"{what} must be True or False, got {x!r}", entry)
    return bool(x)


def table(x: Any, what: str, entry: str) -> Mapping[str, Any]:
    """A TOML table (mapping)."""
    if not isinstance(x, Mapping):
        raise ModelError(f"{what} must be a table, got {x!r}", entry)
    return x


def only_keys(d: Mapping[str, Any], allowed: set[str], entry: str,
              required: Sequence[str] = ()) -> None:
    """Reject unknown or non-string keys and report missing ones."""
    bad = [k for k in d if not isinstance(k, str)]
    if bad:
        raise ModelError(f"keys must be names (strings), got {bad[0]!r}", entry)
    unknown = set(d) - allowed
    if unknown:
        raise ModelError(f"unknown key(s) {sorted(unknown)}; allowed: {sorted(allowed)}", entry)
    for key in required:
        if key not in d:
            raise ModelError(f"missing key '{key}'", entry)

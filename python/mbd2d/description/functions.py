"""Functions of time for drivers: f(t) = sum_k c_k t**k + sum_h A_h sin(omega_h t + phi_h).

The core evaluates them; this module only checks and encodes the description.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

from ..errors import ModelError
from ..validate import as_list, is_number, number


@dataclass(frozen=True)
class Harmonic:
    """One term A sin(omega t + phase)."""

    amplitude: float
    omega: float
    phase: float = 0.0


@dataclass(frozen=True)
class TimeFunction:
    """A polynomial plus harmonics.

    Parameters
    ----------
    poly : sequence of float
        Coefficients c_0, c_1, ... of c_0 + c_1 t + c_2 t**2 + ...
    harmonic : sequence of Harmonic
        Terms A sin(omega t + phase).

    Examples
    --------
    >>> TimeFunction(poly=(1.047, 1.0)).encode()
    [2.0, 1.047, 1.0, 0.0]
    """

    poly: tuple[float, ...] = (0.0,)
    harmonic: tuple[Harmonic, ...] = field(default_factory=tuple)

    def encode(self) -> list[float]:
        """The flat encoding the core reads: [np, c..., nh, (A, omega, phase)...]."""
        out = [float(len(self.poly)), *map(float, self.poly), float(len(self.harmonic))]
        for h in self.harmonic:
            out += [float(h.amplitude), float(h.omega), float(h.phase)]
        return out


def _finite(x: Any, what: str, entry: str) -> float:
    return number(x, what, entry)


def as_function(spec: Any, entry: str, what: str = "f") -> TimeFunction:
    """Read a function description.

    Parameters
    ----------
    spec : TimeFunction, number, or mapping
        A constant, or ``{poly = [...], harmonic = [{amplitude, omega, phase}, ...]}``.
    entry : str
        The entry that owns it, for messages.
    what : str
        The key name, for messages.

    Returns
    -------
    TimeFunction

    Raises
    ------
    ModelError
        If the description is malformed.
    """
    if isinstance(spec, TimeFunction):
        return spec
    if is_number(spec):
        return TimeFunction(poly=(_finite(spec, what, entry),))
    if not isinstance(spec, Mapping):
        raise ModelError(f"{what} must be a number or a table like "
                         "{ poly = [c0, c1], harmonic = [{ amplitude = A, omega = w, phase = p }] }"
                         f", got {spec!r}", entry)
    if any(not isinstance(k, str) for k in spec):
        raise ModelError(f"{what} keys must be names (strings)", entry)
    unknown = set(spec) - {"poly", "harmonic"}
    if unknown:
        raise ModelError(f"{what} has unknown key(s) {sorted(unknown)}; "
                         "use 'poly' and 'harmonic'", entry)
    poly_in = as_list(spec.get("poly", [0.0]))
    if is_number(poly_in):
        poly_in = [poly_in]
    if not isinstance(poly_in, Sequence) or isinstance(poly_in, str) or len(poly_in) == 0:
        raise ModelError(f"{what}.poly must be a non-empty list of coefficients", entry)
    poly = tuple(_finite(c, f"{what}.poly[{i}]", entry) for i, c in enumerate(poly_in))
    harm_in = spec.get("harmonic", [])
    if isinstance(harm_in, Mapping):
        harm_in = [harm_in]
    if not isinstance(harm_in, Sequence) or isinstance(harm_in, str):
        raise ModelError(f"{what}.harmonic must be a list of tables", entry)
    harms = []
    for i, h in enumerate(harm_in):
        if not isinstance(h, Mapping):
            raise ModelError(f"{what}.harmonic[{i}] must be a table "
                             "{ amplitude = A, omega = w, phase = p }", entry)
        bad = set(h) - {"amplitude", "omega", "phase"}
        if bad or "amplitude" not in h or "omega" not in h:
            raise ModelError(f"{what}.harmonic[{i}] needs 'amplitude' and 'omega' (and optional "
                             f"'phase'), got keys {sorted(map(str, h))}", entry)
        harms.append(Harmonic(_finite(h["amplitude"], f"{what}.harmonic[{i}].amplitude", entry),
                              _finite(h["omega"], f"{what}.harmonic[{i}].omega", entry),
                              _finite(h.get("phase", 0.0), f"{what}.harmonic[{i}].phase", entry)))
    return TimeFunction(poly=poly, harmonic=tuple(harms))

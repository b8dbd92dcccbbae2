"""Functions of time for drivers and forces:
f(t) = sum_k c_k t**k + sum_h A_h sin(omega_h t + phi_h) + sum_s h_s L_s((t - t0_s)/(t1_s - t0_s))
       + y(t),
the steps' motion laws L (dwell, rise by h between t0 and t1, dwell), y(t) a table through
points (t_k, y_k): measured motion or a force history (a local, twice continuously
differentiable interpolation; see fortran/mbd_functions.f90).

The core evaluates them; this module only checks and encodes the description.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

from ..errors import ModelError
from ..validate import as_list, is_number, number


@dataclass(frozen=True)
class Harmonic:
    """One term A sin(omega t + phase)."""

    amplitude: float
    omega: float
    phase: float = 0.0


#: the motion laws of a step and their codes in the core (fortran/mbd_functions.f90)
LAWS = {"cubic": 1, "quintic": 2, "cycloidal": 3, "harmonic": 4, "modified-sine": 5,
        "modified-trapezoid": 6}


@dataclass(frozen=True)
class Step:
    """One step h L(u), u = (t - t0)/(t1 - t0) clamped to [0, 1]: 0 up to t0, h from t1 on.

    Parameters
    ----------
    t0, t1 : float
        Start and end of the rise (t1 > t0).
    h : float
        The rise (negative: a fall).
    law : str
        ``"cycloidal"`` (default; zero acceleration at both ends), ``"quintic"`` (the 3-4-5
        polynomial, Adams' STEP5), ``"cubic"`` (Adams' STEP), ``"harmonic"`` (simple
        harmonic), ``"modified-sine"`` or ``"modified-trapezoid"`` (the cam and indexer
        laws: peak accelerations 5.53 and 4.89 h/T^2 against the cycloidal's 6.28); cubic
        and harmonic jump in acceleration at t0 and t1.
    """

    t0: float
    t1: float
    h: float
    law: str = "cycloidal"


@dataclass(frozen=True)
class Table:
    """Points (t_k, y_k) that y(t) passes through (at least 2, t increasing).

    Between the points: the quintic Hermite with the slopes and second derivatives of the
    quadratic through the three points around each (twice continuously differentiable,
    exact on quadratics); outside: the line through the end point with its slope.
    """

    t: tuple[float, ...]
    y: tuple[float, ...]

    @classmethod
    def from_file(cls, path: str | Path, columns: Sequence[int] = (0, 1)) -> "Table":
        """The columns (t, y) of a text file (see :func:`table_columns`), checked.

        Raises
        ------
        ModelError
            If the file cannot be read or a row is not numbers, or the columns do not make a
            table (at least 2 points, t increasing).
        """
        t, y = table_columns(Path(path), list(columns), "Table.from_file")
        tab = _table({"t": t, "y": y}, "table", "Table.from_file")
        assert tab is not None
        return tab


@dataclass(frozen=True)
class TimeFunction:
    """A polynomial plus harmonics plus steps.

    Parameters
    ----------
    poly : sequence of float
        Coefficients c_0, c_1, ... of c_0 + c_1 t + c_2 t**2 + ...
    harmonic : sequence of Harmonic
        Terms A sin(omega t + phase).
    step : sequence of Step
        Motion laws: each adds h L((t - t0)/(t1 - t0)) (dwell, rise, dwell).
    table : Table, optional
        Adds y(t) through the table's points.

    Examples
    --------
    >>> TimeFunction(poly=(1.047, 1.0)).encode()
    [2.0, 1.047, 1.0, 0.0, 0.0, 0.0]
    """

    poly: tuple[float, ...] = (0.0,)
    harmonic: tuple[Harmonic, ...] = field(default_factory=tuple)
    step: tuple[Step, ...] = field(default_factory=tuple)
    table: Table | None = None

    def encode(self) -> list[float]:
        """The flat encoding the core reads:
        [np, c..., nh, (A, omega, phase)..., ns, (law, t0, t1, h)..., nt, t..., y...]."""
        out = [float(len(self.poly)), *map(float, self.poly), float(len(self.harmonic))]
        for h in self.harmonic:
            out += [float(h.amplitude), float(h.omega), float(h.phase)]
        out.append(float(len(self.step)))
        for st in self.step:
            out += [float(LAWS[st.law]), float(st.t0), float(st.t1), float(st.h)]
        tab = self.table
        out.append(float(len(tab.t)) if tab else 0.0)
        if tab:
            out += [*map(float, tab.t), *map(float, tab.y)]
        return out


def _finite(x: Any, what: str, entry: str) -> float:
    return number(x, what, entry)


def as_function(spec: Any, entry: str, what: str = "f") -> TimeFunction:
    """Read a function description.

    Parameters
    ----------
    spec : TimeFunction, number, or mapping
        A constant, or ``{poly = [...], harmonic = [{amplitude, omega, phase}, ...],
        step = [{t0, t1, h, law}, ...], table = {t = [...], y = [...]}}``.
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
        return _checked(spec, what, entry)
    if is_number(spec):
        return TimeFunction(poly=(_finite(spec, what, entry),))
    if not isinstance(spec, Mapping):
        raise ModelError(f"{what} must be a number or a table like "
                         "{ poly = [c0, c1], harmonic = [{ amplitude = A, omega = w, phase = p }] }"
                         f", got {spec!r}", entry)
    if any(not isinstance(k, str) for k in spec):
        raise ModelError(f"{what} keys must be names (strings)", entry)
    unknown = set(spec) - {"poly", "harmonic", "step", "table"}
    if unknown:
        raise ModelError(f"{what} has unknown key(s) {sorted(unknown)}; "
                         "use 'poly', 'harmonic', 'step' and 'table'", entry)
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
    return TimeFunction(poly=poly, harmonic=tuple(harms),
                        step=_steps(spec.get("step", []), what, entry),
                        table=_table(spec.get("table"), f"{what}.table", entry))


#: the most points of a table
MAX_TABLE = 10**6


def _table(spec: Any, what: str, entry: str) -> Table | None:
    """A table {t = [...], y = [...]} (or a Table), checked: equal lengths >= 2, finite,
    t increasing."""
    if spec is None or isinstance(spec, Table):
        return spec
    if not isinstance(spec, Mapping) or set(map(str, spec)) != {"t", "y"}:
        raise ModelError(f"{what} must be a table {{ t = [t0, t1, ...], y = [y0, y1, ...] }}",
                         entry)
    cols = []
    for key in ("t", "y"):
        v = as_list(spec[key])
        if not isinstance(v, Sequence) or isinstance(v, str):
            raise ModelError(f"{what}.{key} must be a list of numbers", entry)
        cols.append(tuple(_finite(x, f"{what}.{key}[{i}]", entry) for i, x in enumerate(v)))
    t, y = cols
    if len(t) != len(y) or not 2 <= len(t) <= MAX_TABLE:
        raise ModelError(f"{what} needs t and y of one length, 2 to {MAX_TABLE} points (got "
                         f"{len(t)} and {len(y)})", entry)
    bad = next((i for i in range(1, len(t)) if not t[i] > t[i - 1]), None)
    if bad is not None:
        raise ModelError(f"{what}.t must increase: t[{bad}] = {t[bad]:g} is not above "
                         f"t[{bad - 1}] = {t[bad - 1]:g}", entry)
    return Table(t, y)


def _checked(f: TimeFunction, what: str, entry: str) -> TimeFunction:
    """A TimeFunction built in code, checked as its mapping would be (its steps' laws and
    times, its table)."""
    for i, st in enumerate(f.step):
        if not isinstance(st, Step):
            raise ModelError(f"{what}.step[{i}] must be a Step, got {st!r}", entry)
        _step({"t0": st.t0, "t1": st.t1, "h": st.h, "law": st.law}, f"{what}.step[{i}]",
              entry)
    if f.table is not None:
        if not isinstance(f.table, Table):
            raise ModelError(f"{what}.table must be a Table, got {f.table!r}", entry)
        _table({"t": list(f.table.t), "y": list(f.table.y)}, f"{what}.table", entry)
    return f


def _steps(spec: Any, what: str, entry: str) -> tuple[Step, ...]:
    """The steps of a function: a table or a list of tables {t0, t1, h, law}."""
    if isinstance(spec, Mapping):
        spec = [spec]
    if not isinstance(spec, Sequence) or isinstance(spec, str):
        raise ModelError(f"{what}.step must be a list of tables "
                         "{ t0 = T0, t1 = T1, h = H, law = 'cycloidal' }", entry)
    return tuple(_step(s, f"{what}.step[{i}]", entry) for i, s in enumerate(spec))


def _step(s: Any, what: str, entry: str) -> Step:
    if not isinstance(s, Mapping):
        raise ModelError(f"{what} must be a table {{ t0 = T0, t1 = T1, h = H, law = "
                         "'cycloidal' }", entry)
    keys = set(map(str, s))
    if keys - {"t0", "t1", "h", "law"} or not {"t0", "t1", "h"} <= keys:
        raise ModelError(f"{what} needs 't0', 't1' and 'h' (and optional 'law'), got keys "
                         f"{sorted(keys)}", entry)
    law = s.get("law", "cycloidal")
    if not isinstance(law, str) or law not in LAWS:
        raise ModelError(f"{what}.law must be one of {', '.join(LAWS)}, got {law!r}", entry)
    t0, t1 = _finite(s["t0"], f"{what}.t0", entry), _finite(s["t1"], f"{what}.t1", entry)
    if not t1 > t0:
        raise ModelError(f"{what} needs t1 > t0 (got t0 = {t0:g}, t1 = {t1:g}): the rise "
                         "takes time", entry)
    return Step(t0, t1, _finite(s["h"], f"{what}.h", entry), str(law))


def table_columns(path: Path, cols: Any, entry: str) -> tuple[list[float], list[float]]:
    """Two columns of a text table: numbers separated by commas or spaces, one row per line;
    blank lines, lines starting with '#' and a first line that is not numbers (a header) are
    skipped. ``cols = [i, j]`` picks them (column numbers from 0)."""
    if (not isinstance(cols, list) or len(cols) != 2
            or not all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in cols)):
        raise ModelError(f"table.columns must be two column numbers [i, j] from 0, got {cols!r}",
                         entry)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
        raise ModelError(f"cannot read the table file {str(path)!r}: {why}", entry) from None
    first = next((i for i, ln in enumerate(lines) if ln.strip()), -1)
    t, y = [], []
    for k, line in enumerate(lines):
        words = line.replace(",", " ").split()
        if not words or words[0].startswith("#"):
            continue
        try:
            row = [float(w) for w in words]
        except ValueError:
            if k == first:
                continue                                  # a header
            raise ModelError(f"{path}:{k + 1}: not a row of numbers: {line[:60]!r}",
                             entry) from None
        if len(row) <= max(cols):
            raise ModelError(f"{path}:{k + 1}: {len(row)} columns, column {max(cols)} asked",
                             entry)
        t.append(row[cols[0]])
        y.append(row[cols[1]])
    return t, y

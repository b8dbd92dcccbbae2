"""The small motion about an equilibrium as a state-space system whose inputs are design
parameters (Adams/Linear's state matrices; scipy.signal and python-control take them)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import ModelError
from .files import CSV_FORMAT, write_text

#: The four matrices in the order of the CSV.
MATRICES = ("A", "B", "C", "D")


@dataclass
class LinearizedSystem:
    """x' = A x + B p, dq = C x + D p: the linearized motion about an equilibrium (drivers
    held at ``t``) with the design parameters ``inputs`` varied as p0 + p(t) and the
    coordinates' changes dq as outputs (model units; B and D per unit of each input), with
    ``velocities=True`` their velocities too (``NAME.x_dot`` ...: dq' = C A x + C B p), with
    ``efforts=True`` every driver's effort (``effort.NAME``, -dlambda on its row).

    The states x = [w; v] are coordinates of the free motions on a basis N of the
    constraints' null space and their rates (``states``: z1 .. zf, v1 .. vf): with forces
    alone as inputs w = z and v = z' (dq = N z); an input that moves the constraints (a
    pivot's place, a driver's offset) also enters through its rate and acceleration, which
    the realization takes out by shifting the states (docs/linearize.md). The basis, hence
    the states, is one of many; the transfer function C (sI - A)^-1 B + D, the poles (the
    damped eigenvalues of :meth:`mbd2d.Model.modes`) and the outputs are not.
    ``q``, ``lam``, ``stability`` and ``residual`` are the equilibrium's, as
    :class:`StaticsResult`.
    """

    t: float
    q: np.ndarray
    lam: np.ndarray
    stability: str
    residual: float
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    inputs: list[str]
    outputs: list[str]
    n_free: int
    model: Any = None
    stats: dict = field(default_factory=dict)

    @property
    def states(self) -> list[str]:
        """The states' labels: z1 .. zf (the free motions), v1 .. vf (their rates)."""
        return [f"z{k}" for k in range(1, self.n_free + 1)] + \
            [f"v{k}" for k in range(1, self.n_free + 1)]

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C, D)."""
        return self.a, self.b, self.c, self.d

    def select(self, outputs: Any = None, inputs: Any = None) -> LinearizedSystem:
        """The system with some outputs (coordinate names such as ``"block.y"``) and inputs
        (parameter names) only: the rows of C and D, the columns of B and D.

        Raises
        ------
        ModelError
            For a name that is no output or input of the system.
        """
        rows = _indices(outputs, self.outputs, "output", "coordinate")
        cols = _indices(inputs, self.inputs, "input", "design parameter")
        return replace(self, b=self.b[:, cols], c=self.c[rows], d=self.d[np.ix_(rows, cols)],
                       inputs=[self.inputs[k] for k in cols],
                       outputs=[self.outputs[k] for k in rows])

    def to_scipy(self) -> Any:
        """A ``scipy.signal.StateSpace`` of (A, B, C, D) (needs SciPy:
        ``pip install 'mbd2d[synthesis]'``)."""
        try:
            from scipy import signal
        except ImportError:
            raise ModelError("to_scipy needs SciPy: pip install 'mbd2d[synthesis]' (or use "
                             "res.a, res.b, res.c, res.d)", "linearized system") from None
        return signal.StateSpace(self.a, self.b, self.c, self.d)

    def table(self) -> tuple[list[str], list[tuple[str, str, str, float]]]:
        """Header and rows of the CSV: ``matrix,row,column,value``, every entry of A (states
        by states), B (states by inputs), C (outputs by states), D (outputs by inputs) in
        turn, row by row."""
        x, u, y = self.states, self.inputs, self.outputs
        rows: list[tuple[str, str, str, float]] = []
        for name, mat, rl, cl in (("A", self.a, x, x), ("B", self.b, x, u),
                                  ("C", self.c, y, x), ("D", self.d, y, u)):
            rows += [(name, rl[i], cl[j], float(mat[i, j])) for i in range(len(rl))
                     for j in range(len(cl))]
        return ["matrix", "row", "column", "value"], rows

    def to_csv(self, path: Any) -> None:
        """Write :meth:`table` as CSV, numbers as every mbd2d CSV (mbd2d-solve writes the
        same bytes)."""
        header, rows = self.table()
        lines = [",".join(header)] + [f"{m},{r},{c},{CSV_FORMAT % (v + 0.0)}"
                                      for m, r, c, v in rows]
        write_text(path, "\n".join(lines) + "\n", "to_csv")

    def summary(self) -> str:
        """A text summary: the equilibrium, the sizes, the inputs."""
        name = getattr(self.model, "name", "model")
        return "\n".join([
            f"{name}: linearized about the equilibrium ({self.stability}) at t = {self.t:g}",
            f"  {self.n_free} free motion(s): {2 * self.n_free} states, "
            f"{len(self.inputs)} input(s), {len(self.outputs)} output(s) "
            f"(A {self.a.shape[0]}x{self.a.shape[1]}, B {self.b.shape[0]}x{self.b.shape[1]}, "
            f"C {self.c.shape[0]}x{self.c.shape[1]}, D {self.d.shape[0]}x{self.d.shape[1]})",
            *[f"  input {p}" for p in self.inputs]])


def _indices(names: Any, known: list[str], what: str, kind: str) -> list[int]:
    """Positions of names in known (None: all).

    Raises
    ------
    ModelError
        For a name not in known.
    """
    if names is None:
        return list(range(len(known)))
    try:
        names = [names] if isinstance(names, str) else list(names)
    except TypeError:
        raise ModelError(f"{what}s must be a name or a list of names, got {names!r}",
                         "linearized system") from None
    out = []
    for n in names:
        if n not in known:
            raise ModelError(f"no {what} {n!r}; the system's {what}s are the {kind}s "
                             f"{', '.join(known[:8])}{' ...' if len(known) > 8 else ''}",
                             "linearized system")
        out.append(known.index(n))
    return out

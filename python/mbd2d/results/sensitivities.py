"""Design sensitivities in the results: lookups by parameter and body, and the changes of
the reactions, from the arrays the core computed."""
from __future__ import annotations

import difflib
from typing import Any

import numpy as np

from ..binding import core
from ..binding.tables import Packed
from ..errors import CoreError
from .reactions import Reaction

LEVELS = ("q", "qd", "qdd")


def parameter_index(names: list[str], name: str) -> int:
    """Column of the parameter called name.

    Raises
    ------
    KeyError
        If the run has no sensitivity with respect to it (with the closest names).
    """
    if name in names:
        return names.index(name)
    if not isinstance(name, str):
        raise KeyError(f"a parameter is given by its name (a string), got {name!r}; "
                       f"computed: {', '.join(names) or 'none'}")
    if not names:
        raise KeyError("this result has no sensitivities: run the analysis with "
                       "sensitivities=[names]")
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else ""
    raise KeyError(f"no sensitivity with respect to {name!r}{hint}; computed: "
                   f"{', '.join(names)}")


def body_columns(body_names: list[str], body: str) -> slice:
    """Columns x, y, theta of a body."""
    if body not in body_names:
        raise KeyError(f"no body {body!r}; bodies: {', '.join(body_names)}")
    i = body_names.index(body)
    return slice(3 * i, 3 * i + 3)


def reaction_dp_arrays(p: Packed, ptab: np.ndarray, q: np.ndarray, t: np.ndarray,
                       lam: np.ndarray, sq: np.ndarray, slam: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Changes of the reactions along each parameter, (nt, nc, 6, np) global and in the
    body frames, from q (nt, nq), lam (nt, neq), sq (nt, nq, np) and slam (nt, neq, np)."""
    out = core.reactions_dp(p, ptab, np.asfortranarray(q.T), np.asarray(t, dtype=float),
                            np.asfortranarray(lam.T),
                            np.asfortranarray(np.transpose(sq, (1, 2, 0))),
                            np.asfortranarray(np.transpose(slam, (1, 2, 0))))
    if out.status != 0:
        raise CoreError(out.msg)
    return np.transpose(out.dreac, (3, 1, 0, 2)), np.transpose(out.drloc, (3, 1, 0, 2))


def reaction_dp_of(p: Packed, model: Any, name: str, g: np.ndarray,
                   loc: np.ndarray) -> Reaction:
    """The Reaction of the joint or driver called name whose arrays are the changes
    (nt, np) along the parameters, from the arrays of :func:`reaction_dp_arrays`."""
    names = p.constraint_names
    if name not in names:
        raise KeyError(f"no joint or driver {name!r}; known: {', '.join(names)}")
    k = names.index(name)
    r, rl = g[:, k], loc[:, k]
    return Reaction(name, model.constraints[k].bodies, r[:, 0], r[:, 1], r[:, 2], r[:, 3],
                    r[:, 4], r[:, 5], rl[:, 0], rl[:, 1], rl[:, 3], rl[:, 4])

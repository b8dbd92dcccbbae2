"""Joint and driver reactions, from the multipliers through the core."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..binding import core
from ..binding.status import error_for
from ..binding.tables import Packed


def driver_rows(p: Packed) -> tuple[list[int], list[str]]:
    """The first rows of Phi (0-based) of every driver (an effort is -lambda there) and the
    drivers' names, in the constraints' order."""
    drivers = [k for k, f in enumerate(p.driver_flags) if f]
    return [p.row_owner.index(k) for k in drivers], [p.constraint_names[k] for k in drivers]


def driver_row(p: Packed, name: str) -> int | None:
    """First row of Phi (0-based) of the driver called name (its effort is -lambda there);
    None if name is no driver."""
    names = p.constraint_names
    if name in names and p.driver_flags[names.index(name)]:
        return p.row_owner.index(names.index(name))
    return None


@dataclass
class Reaction:
    """Reaction of a joint or driver on its two bodies over time (arrays over outputs).

    fx, fy are the force on body i (global components) and mz the moment about its centre
    of mass; fx_j, fy_j, mz_j the same on body j. The ``_local`` arrays are the forces in
    each body's own frame. Forces on ground are zero (ground has no coordinates).
    """

    name: str
    bodies: tuple[str, str]
    fx: np.ndarray
    fy: np.ndarray
    mz: np.ndarray
    fx_j: np.ndarray
    fy_j: np.ndarray
    mz_j: np.ndarray
    fx_local: np.ndarray
    fy_local: np.ndarray
    fx_j_local: np.ndarray
    fy_j_local: np.ndarray


def reaction_arrays(p: Packed, q: np.ndarray, t: np.ndarray, lam: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Joint reactions at many states (global and in the body frames): (nt, nc, 6) each."""
    qq = np.asfortranarray(np.atleast_2d(q).T)
    ll = np.asfortranarray(np.atleast_2d(lam).T)
    out = core.reactions(p, qq, np.atleast_1d(t).astype(float), ll)
    if out.status != 0:
        raise error_for("reactions", out.status, out.msg, entry="reactions")
    return np.transpose(out.reac, (2, 1, 0)), np.transpose(out.rloc, (2, 1, 0))


def reaction_of(p: Packed, model: Any, name: str,
                arrays: Callable[[], tuple[np.ndarray, np.ndarray]]) -> Reaction:
    """The Reaction of the joint or driver called name, from the (nt, nc, 6) arrays that
    ``arrays()`` gives (see :func:`reaction_arrays`); the name is checked first.

    Raises
    ------
    KeyError
        If there is no such joint or driver.
    """
    names = p.constraint_names
    if name not in names:
        raise KeyError(f"no joint or driver {name!r}; known: {', '.join(names)}")
    k = names.index(name)
    g, loc = arrays()
    c = model.constraints[k]
    r, rl = g[:, k, :], loc[:, k, :]
    return Reaction(name, c.bodies, r[:, 0], r[:, 1], r[:, 2], r[:, 3], r[:, 4], r[:, 5],
                    rl[:, 0], rl[:, 1], rl[:, 3], rl[:, 4])

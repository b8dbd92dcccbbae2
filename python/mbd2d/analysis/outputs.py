"""Results built from the core's output arrays (one column per output time)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..results.dynamics import DynamicsResult


def dynamics_result(model: ModelDescription, p: Packed, t: np.ndarray, n: int, out: Any,
                    stats: dict[str, Any], complete: bool) -> DynamicsResult:
    """The first n output rows of an inverse or forward dynamics run (``out`` from
    :mod:`mbd2d.binding.core`)."""
    e = out.e
    return DynamicsResult(t=t[:n], q=out.q.T[:n].copy(), qd=out.qd.T[:n].copy(),
                          qdd=out.qdd.T[:n].copy(), body_names=p.body_names,
                          coordinate_names=p.coordinate_names, stats=stats, complete=complete,
                          model=model, lam=out.lam.T[:n].copy(), kinetic=e[0, :n].copy(),
                          potential=e[1, :n].copy(), drift_position=e[2, :n].copy(),
                          drift_velocity=e[3, :n].copy(), row_labels=p.row_labels, packed=p)

"""The IFToMM N-four-bar (benchmark A02): N parallelogram loops in a row.

Ground pivots at x = 0, 1, ..., N carry N + 1 cranks of length 1; N couplers of length 1
join neighbouring crank tips. Crank 0 is driven through the collinear (singular) positions:
theta = pi/2 - t. Every crank stays parallel to the first, the couplers translate.

    python examples/nfourbar.py [N] [t_end]
"""
from __future__ import annotations

import math
import sys

import mbd2d


def build(n: int, driven: bool = True, omega0: float | None = None) -> mbd2d.Model:
    """The N-four-bar as a model (cranks upright at t = 0).

    Parameters
    ----------
    n : int
        Number of parallelogram loops.
    driven : bool
        Drive crank 0: theta = pi/2 - t.
    omega0 : float, optional
        For dynamics: 1 kg, 1 m uniform bars under gravity, every crank turning at omega0 and
        the couplers translating (a consistent v0).
    """
    free = omega0 is not None
    w = omega0 if free else 0.0
    m = mbd2d.Model(f"{'free-' if free else ''}{n}-four-bar")    # default gravity -9.81
    bar = {"mass": 1.0, "inertia": 1.0 / 12} if free else {}
    for k in range(n + 1):
        m.add_body(f"crank{k}", q0=[k, 0.5, math.pi / 2],
                   **bar, **({"v0": [-0.5 * w, 0.0, w]} if free else {}))
    for k in range(n):
        m.add_body(f"coupler{k}", q0=[k + 0.5, 1.0, 0.0],
                   **bar, **({"v0": [-w, 0.0, 0.0]} if free else {}))
    for k in range(n + 1):
        m.add_revolute(["ground", f"crank{k}"], [[k, 0.0], [-0.5, 0.0]], name=f"O{k}")
    for k in range(n):
        m.add_revolute([f"crank{k}", f"coupler{k}"], [[0.5, 0.0], [-0.5, 0.0]], name=f"L{k}")
        m.add_revolute([f"crank{k + 1}", f"coupler{k}"], [[0.5, 0.0], [0.5, 0.0]], name=f"R{k}")
    if driven:
        m.add_driver("absolute", body="crank0", coordinate="theta",
                     f={"poly": [math.pi / 2, -1.0]}, name="motor")
    return m


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    t_end = float(sys.argv[2]) if len(sys.argv) > 2 else 4 * math.pi
    res = build(n).kinematics(t_end=t_end, steps=2000)
    print(res, res.stats["singular_passages"])


if __name__ == "__main__":
    main()

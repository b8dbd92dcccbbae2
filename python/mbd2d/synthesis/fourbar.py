"""The four-bar of path generation built from link lengths, and the lengths of any four-bar
loop of revolutes read back from a model (for the Grashof and link-ratio terms).

The model :func:`fourbar` builds (crank angle = time, so task times are crank angles)::

    O2 (ground, crank)   ground pivot (x0, y0);   crank point (0, 0)
    A  (crank, coupler)  crank point (r2, 0);     coupler point (0, 0)
    B  (coupler, rocker) coupler point (r3, 0);   rocker point (r4, 0)
    O4 (ground, rocker)  ground pivot (x4, y4);   rocker point (0, 0)
    motor: theta_crank = theta0 + speed t

so the link lengths are the parameters ``joint.A.points.0.0`` (crank),
``joint.B.points.0.0`` (coupler) and ``joint.B.points.1.0`` (rocker), the pivots
``joint.O2.points.0.*`` and ``joint.O4.points.0.*``, and the coupler point of a path task is
given in the coupler frame (along A -> B, and to its left), as in the synthesis literature.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ..errors import ModelError
from ..model import Model
from ..validate import number, positive, vector

#: parameter names of the four-bar :func:`fourbar` builds
FOURBAR_PARAMETERS = {
    "x0": "joint.O2.points.0.0", "y0": "joint.O2.points.0.1",
    "x4": "joint.O4.points.0.0", "y4": "joint.O4.points.0.1",
    "crank": "joint.A.points.0.0", "coupler": "joint.B.points.0.0",
    "rocker": "joint.B.points.1.0",
}


def loop_configuration(o2: Sequence[float], o4: Sequence[float], crank: float, coupler: float,
                       rocker: float, theta: float, branch: int = 1
                       ) -> tuple[np.ndarray, np.ndarray] | None:
    """Closed-form position of the four-bar loop at crank angle theta: the joints A and B
    (B on the side ``branch`` = +1 (left of A -> O4) or -1), or None where the loop does not
    close (circle intersection)."""
    a = np.asarray(o2, float) + crank * np.array([math.cos(theta), math.sin(theta)])
    d_vec = np.asarray(o4, float) - a
    d = float(np.hypot(*d_vec))
    if d == 0.0:
        return None
    along = (coupler**2 - rocker**2 + d**2) / (2.0 * d)
    h2 = coupler**2 - along**2
    if h2 < 0.0:
        return None
    u = d_vec / d
    b = a + along * u + branch * math.sqrt(h2) * np.array([-u[1], u[0]])
    return a, b


def fourbar(ground: Sequence[Sequence[float]], crank: float, coupler: float, rocker: float,
            theta0: float = 0.0, speed: float = 1.0, branch: int = 1,
            name: str = "four-bar") -> Model:
    """A four-bar linkage from its link lengths, assembled at t = 0 on the chosen branch.

    Parameters
    ----------
    ground : [[x0, y0], [x4, y4]]
        The crank pivot O2 and the rocker pivot O4.
    crank, coupler, rocker : float
        Link lengths r2 (O2-A), r3 (A-B), r4 (B-O4).
    theta0 : float
        Crank angle at t = 0 (radians, from the global x axis).
    speed : float
        Crank speed: theta_crank = theta0 + speed t (default 1, so that time is the crank
        angle in radians).
    branch : {1, -1}
        Assembly branch: B to the left (+1) or the right (-1) of the line A -> O4.
    name : str
        Model name.

    Returns
    -------
    Model
        Bodies crank, coupler, rocker; joints O2, A, B, O4; driver motor (see the module
        docstring for the parameter names).

    Raises
    ------
    ModelError
        If a length is not positive, or the loop does not close at theta0.

    Examples
    --------
    >>> m = fourbar([[0, 0], [4, 0]], crank=1, coupler=4, rocker=3)
    >>> m.parameters()["joint.B.points.0.0"]
    4.0
    """
    entry = "fourbar"
    if not isinstance(ground, Sequence) or len(ground) != 2:
        raise ModelError("ground must be [[x0, y0], [x4, y4]]", entry)
    o2, o4 = vector(ground[0], 2, "ground[0]", entry), vector(ground[1], 2, "ground[1]", entry)
    r2, r3, r4 = (positive(v, k, entry) for k, v in
                  (("crank", crank), ("coupler", coupler), ("rocker", rocker)))
    th0, w = number(theta0, "theta0", entry), number(speed, "speed", entry)
    if branch not in (1, -1):
        raise ModelError(f"branch must be 1 or -1, got {branch!r}", entry)
    pos = loop_configuration(o2, o4, r2, r3, r4, th0, branch)
    if pos is None:
        raise ModelError(f"the loop does not close at the crank angle {th0:g} rad (lengths "
                         f"{r2:g}, {r3:g}, {r4:g}, ground {math.dist(o2, o4):g})", entry)
    a, b = pos
    th3 = math.atan2(b[1] - a[1], b[0] - a[0])
    th4 = math.atan2(b[1] - o4[1], b[0] - o4[0])
    m = Model(name, gravity=(0.0, 0.0))
    m.add_body("crank", q0=[o2[0], o2[1], th0])
    m.add_body("coupler", q0=[a[0], a[1], th3])
    m.add_body("rocker", q0=[o4[0], o4[1], th4])
    m.add_revolute(["ground", "crank"], [o2, [0.0, 0.0]], name="O2")
    m.add_revolute(["crank", "coupler"], [[r2, 0.0], [0.0, 0.0]], name="A")
    m.add_revolute(["coupler", "rocker"], [[r3, 0.0], [r4, 0.0]], name="B")
    m.add_revolute(["ground", "rocker"], [o4, [0.0, 0.0]], name="O4")
    m.add_driver("absolute", body="crank", coordinate="theta", f={"poly": [th0, w]},
                 name="motor")
    return m


def fourbar_parameters(ground: bool = True, lengths: bool = True) -> list[str]:
    """Names of the parameters of :func:`fourbar` a path task usually frees: the pivots and
    the three moving link lengths."""
    out = []
    if ground:
        out += [FOURBAR_PARAMETERS[k] for k in ("x0", "y0", "x4", "y4")]
    if lengths:
        out += [FOURBAR_PARAMETERS[k] for k in ("crank", "coupler", "rocker")]
    return out


# ------------------------------------------------------------------ lengths of a loop

def loop_links(model: Any, joints: Sequence[str]) -> list[tuple[str, tuple[str, int], tuple[str,
                                                                                         int]]]:
    """The links of a loop of four revolutes [J1, J2, J3, J4] (J1 and J4 on ground): for
    each link (ground J4-J1, then J1-J2, J2-J3, J3-J4) its body and the two joint points on
    it, as (body, (joint, side), (joint, side)), side 0 or 1 the joint's point index.

    Raises
    ------
    ModelError
        If the joints are not four revolutes chained through common bodies.
    """
    if len(joints) != 4:
        raise ModelError(f"a four-bar loop needs 4 revolute joints, got {list(joints)}",
                         "synthesize")
    table = {j.name: j for j in model.joints}
    for name in joints:
        if name not in table or table[name].type != "revolute":
            raise ModelError(f"{name!r} is not a revolute joint of the model", "synthesize")
    out = []
    ring = [joints[3], joints[0], joints[1], joints[2], joints[3]]
    for k in range(4):
        ja, jb = table[ring[k]], table[ring[k + 1]]
        common = [b for b in ja.bodies if b in jb.bodies]
        if not common:
            raise ModelError(f"joints {ja.name!r} and {jb.name!r} share no body",
                             "synthesize")
        body = "ground" if k == 0 and "ground" in common else common[0]
        out.append((body, (ja.name, ja.bodies.index(body)), (jb.name, jb.bodies.index(body))))
    return out


def loop_lengths(model: Any, joints: Sequence[str], names: Sequence[str]
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Lengths (ground, crank, coupler, rocker) of a four-bar loop and their derivatives with
    respect to the parameters called names (4, len(names))."""
    table = {j.name: j for j in model.joints}
    col = {n: i for i, n in enumerate(names)}
    lengths = np.zeros(4)
    d = np.zeros((4, len(names)))
    for k, (_, (ja, sa), (jb, sb)) in enumerate(loop_links(model, joints)):
        pa = np.array(table[ja].points[sa], float)
        pb = np.array(table[jb].points[sb], float)
        diff = pa - pb
        length = float(np.hypot(*diff))
        lengths[k] = length
        if length == 0.0:
            continue
        for c in range(2):
            for joint, side, sign in ((ja, sa, 1.0), (jb, sb, -1.0)):
                i = col.get(f"joint.{joint}.points.{side}.{c}")
                if i is not None:
                    d[k, i] += sign * diff[c] / length
    return lengths, d


__all__ = ["fourbar", "fourbar_parameters", "loop_configuration", "loop_links", "loop_lengths",
           "FOURBAR_PARAMETERS"]

"""Finite-difference oracles for every constraint and driver type.

For each constraint or driver type a small model is built (it need not be kinematically
determined: only Phi, J, nu and gamma are evaluated) and, at several random states drawn
from a seeded generator, the core's

* J      is compared with central differences of Phi with respect to q,
* nu     is compared with -dPhi/dt by central differences in t,
* gamma  is compared with
         -(d(J qd)/dq) qd - 2 (dJ/dt) qd - Phi_tt,
  where the first term is a central difference along the direction qd, the second a
  central difference in t and the third second differences in t (Richardson-extrapolated).

Every model carries a "spectator" body that no constraint touches, so the zero columns of
J are checked as well.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

import numpy as np
import pytest
from numpy.testing import assert_allclose

from mbd2d import Model

# f(t) with a polynomial and two harmonics: every time derivative is non-trivial
F_RICH = {"poly": [0.3, -0.7, 0.25, 0.05],
          "harmonic": [{"amplitude": 0.4, "omega": 2.0, "phase": 0.3},
                       {"amplitude": -0.15, "omega": 3.5}],
          # steps of every law: the random states' t (0.3 .. 1.7) lies inside the first
          # three rises (smooth there) and past the end of the last (its constant h)
          "step": [{"t0": 0.1, "t1": 1.9, "h": 0.35, "law": "quintic"},
                   {"t0": -0.5, "t1": 2.5, "h": -0.2},
                   {"t0": 0.05, "t1": 2.0, "h": 0.1, "law": "harmonic"},
                   {"t0": -1.0, "t1": 0.2, "h": 0.5, "law": "cubic"},
                   {"t0": -0.1, "t1": 2.1, "h": 0.15, "law": "modified-sine"},
                   {"t0": 0.2, "t1": 1.8, "h": -0.25, "law": "modified-trapezoid"}],
          # a table of uneven points around the states' times (twice differentiable inside)
          "table": {"t": [-1.0, -0.2, 0.25, 0.6, 0.8, 1.15, 1.5, 2.2, 3.0],
                    "y": [0.1, -0.3, 0.2, 0.45, 0.1, -0.2, 0.05, 0.3, 0.0]}}

# ---------------------------------------------------------------- profiles and followers

ELLIPSE_A, ELLIPSE_B, ELLIPSE_C = 1.5, 1.0, (0.2, -0.1)
N_SPLINE = 12


def ellipse_points() -> list[list[float]]:
    """12 points (counterclockwise) of an ellipse: a closed, smooth, convex curve."""
    ang = 2.0 * np.pi * np.arange(N_SPLINE) / N_SPLINE
    return [[ELLIPSE_C[0] + ELLIPSE_A * np.cos(a), ELLIPSE_C[1] + ELLIPSE_B * np.sin(a)]
            for a in ang]


def spline_knots() -> np.ndarray:
    """Knots of the chord-length parameter scaled to [0, 2 pi] (as documented in
    mbd_profiles.f90), computed here independently from the points."""
    p = np.array(ellipse_points())
    chords = np.hypot(*(np.roll(p, -1, axis=0) - p).T)
    return np.concatenate([[0.0], np.cumsum(chords)]) * (2.0 * np.pi / chords.sum())


PROFILES = {
    "circle": {"circle": {"center": [0.3, -0.2], "radius": 1.2}},
    "spline": {"spline": {"points": ellipse_points()}},
    # r = 1 + 0.2 cos a + 0.1 cos 2a + 0.15 sin a - 0.05 sin 2a > 0.5 everywhere
    "fourier": {"fourier": {"center": [-0.1, 0.25], "a": [1.0, 0.2, 0.1], "b": [0.15, -0.05]}},
}

FOLLOWERS = {
    "point": {"point": [0.35, -0.4]},
    "roller": {"roller": {"center": [-0.2, 0.45], "radius": 0.3}},
    "flat": {"flat": {"point": [0.1, -0.3], "normal": [0.6, -1.7]}},
}

# ---------------------------------------------------------------- model cases


@dataclass
class Case:
    """A model and how to draw its cam contact parameters."""

    build: Callable[[], Model]
    spline_cams: int = 0      # number of cams (the trailing alphas) on the spline profile


def _bodies(m: Model, *names: str) -> Model:
    q0 = {"a": [0.4, -0.3, 0.7], "b": [1.1, 0.8, -1.2], "cam": [0.0, 0.0, 0.3],
          "fol": [0.2, 1.5, -0.1], "spectator": [5.0, 5.0, 1.0]}
    for n in names:
        m.add_body(n, q0=q0[n])
    return m


def revolute_body_body() -> Model:
    m = _bodies(Model("rev-bb"), "a", "spectator", "b")
    m.add_revolute(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], name="pin")
    return m


def revolute_body_ground() -> Model:
    m = _bodies(Model("rev-bg"), "spectator", "a")
    m.add_revolute(["ground", "a"], [[1.0, 2.0], [0.4, -0.1]], name="pin")
    m.add_revolute(["a", "ground"], [[-0.6, 0.25], [-1.5, 0.5]], name="pin2")
    return m


def translational_body_body() -> Model:
    m = _bodies(Model("tr-bb"), "a", "b", "spectator")
    m.add_translational(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], [[0.6, 0.8], [1.0, -2.0]],
                        name="slide")
    return m


def translational_body_ground() -> Model:
    m = _bodies(Model("tr-bg"), "spectator", "a")
    m.add_translational(["ground", "a"], [[0.5, 1.5], [0.2, -0.3]], [[1.0, 1.0], [0.3, 0.7]],
                        name="slide")
    m.add_translational(["a", "ground"], [[-0.4, 0.1], [2.0, -1.0]], [[-0.2, 0.9], [1.0, 0.0]],
                        name="slide2")
    return m


def cam_case(profile: str, follower: str) -> Callable[[], Model]:
    def build() -> Model:
        m = _bodies(Model(f"cam-{profile}-{follower}"), "cam", "spectator", "fol")
        m.add_cam(["cam", "fol"], PROFILES[profile], FOLLOWERS[follower], name="contact")
        return m
    return build


def cam_on_ground() -> Model:
    """Profile fixed to ground, and a follower on ground touching a moving cam."""
    m = _bodies(Model("cam-ground"), "cam", "fol", "spectator")
    m.add_cam(["ground", "fol"], PROFILES["fourier"], FOLLOWERS["roller"], name="fixed_cam")
    m.add_cam(["cam", "ground"], PROFILES["circle"], FOLLOWERS["flat"], name="fixed_fol")
    return m


def absolute_driver(coordinate: str) -> Callable[[], Model]:
    def build() -> Model:
        m = _bodies(Model(f"abs-{coordinate}"), "spectator", "a", "b")
        m.add_driver("absolute", body="b", coordinate=coordinate, f=F_RICH, name="drive")
        return m
    return build


def relative_angle_driver() -> Model:
    m = _bodies(Model("rel-angle"), "a", "spectator", "b")
    m.add_driver("relative-angle", bodies=["a", "b"], f=F_RICH, name="drive")
    m.add_driver("relative-angle", bodies=["ground", "a"],
                 f={"poly": [0.1, 0.5], "harmonic": {"amplitude": 0.2, "omega": 1.3}},
                 name="drive_ground")
    return m


def relative_distance_driver() -> Model:
    m = _bodies(Model("rel-dist"), "a", "b", "spectator")
    m.add_translational(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], [[0.6, 0.8], [1.0, -2.0]],
                        name="slide")
    m.add_translational(["ground", "a"], [[0.5, 1.5], [0.2, -0.3]], [[1.0, 1.0], [0.3, 0.7]],
                        name="rail")
    m.add_driver("relative-distance", joint="slide", f=F_RICH, name="stroke")
    m.add_driver("relative-distance", joint="rail",
                 f={"poly": [-0.2, 0.0, 0.4], "harmonic": [{"amplitude": 0.3, "omega": 2.5,
                                                            "phase": -1.0}]},
                 name="stroke_ground")
    return m


def constant_and_linear_drivers() -> Model:
    """Drivers whose f has only a constant or only a linear term (Phi_tt = 0 exactly)."""
    m = _bodies(Model("simple-f"), "a", "b", "spectator")
    m.add_driver("absolute", body="a", coordinate="x", f=1.25, name="const")
    m.add_driver("absolute", body="a", coordinate="theta", f={"poly": [0.5, 2.0]}, name="lin")
    m.add_driver("relative-angle", bodies=["a", "b"], f={"harmonic": [
        {"amplitude": 1.0, "omega": 0.7, "phase": 0.2}]}, name="harm")
    return m


def distance_joints() -> Model:
    m = _bodies(Model("distance"), "a", "spectator", "b")
    m.add_distance(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], 2.5, name="link")
    m.add_distance(["ground", "a"], [[1.0, -1.0], [0.4, 0.6]], 1.7, name="tie")
    return m


def line_joints() -> Model:
    m = _bodies(Model("line"), "a", "b", "spectator")
    m.add_point_on_line(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], [0.6, 0.8], name="on_line")
    m.add_pin_in_slot(["ground", "a"], [[0.5, 1.5], [0.2, -0.3]], [1.0, -2.0], offset=0.15,
                      name="slot")
    m.add_pin_in_slot(["b", "ground"], [[-0.4, 0.2], [1.0, 1.0]], [0.0, 1.0], name="slot2")
    return m


def weld_joints() -> Model:
    m = _bodies(Model("weld"), "spectator", "a", "b")
    m.add_weld(["a", "b"], [[0.3, -0.2], [-0.5, 0.7]], angle=0.4, name="fix")
    m.add_weld(["ground", "a"], [[1.0, 2.0], [0.4, -0.1]], name="fix_ground")
    return m


def curve_case(profile: str) -> Callable[[], Model]:
    def build() -> Model:
        m = _bodies(Model(f"curve-{profile}"), "a", "spectator", "b")
        m.add_point_on_curve(["a", "b"], PROFILES[profile], [0.25, -0.35], name="slot")
        return m
    return build


def gear_joints() -> Model:
    m = _bodies(Model("gears"), "a", "b", "cam", "spectator")
    m.add_gear(["a", "b"], [0.5, 1.25], name="external")           # carrier: ground
    m.add_gear(["a", "b"], [0.4, 1.6], internal=True, carrier="cam", name="ring")
    return m


def rolling_joints() -> Model:
    m = _bodies(Model("rolling"), "a", "b", "spectator")
    m.add_rack_pinion(["a", "b"], [0.1, -0.2], [0.3, 0.4], [0.8, 0.6], 0.6, name="rack")
    m.add_rolling_disc(["a", "ground"], [0.2, 0.1], [0.0, -3.0], [1.0, 0.2], 0.9, name="disc")
    m.add_rolling_disc(["b", "a"], [-0.1, 0.3], [0.5, -0.5], [-0.3, 1.0], 0.4, name="disc2")
    return m


def absolute_constraints() -> Model:
    m = _bodies(Model("absolute"), "a", "spectator")
    for c in ("x", "y", "theta"):
        m.add_absolute("a", c, value=0.3, name=f"fix_{c}")
    return m


CASES: dict[str, Case] = {
    "distance": Case(distance_joints),
    "point-on-line-and-slots": Case(line_joints),
    "weld": Case(weld_joints),
    **{f"point-on-curve-{p}": Case(curve_case(p), spline_cams=int(p == "spline"))
       for p in PROFILES},
    "gear-pairs": Case(gear_joints),
    "rack-and-rolling-disc": Case(rolling_joints),
    "absolute-constraints": Case(absolute_constraints),
    "revolute-body-body": Case(revolute_body_body),
    "revolute-body-ground": Case(revolute_body_ground),
    "translational-body-body": Case(translational_body_body),
    "translational-body-ground": Case(translational_body_ground),
    **{f"cam-{p}-{f}": Case(cam_case(p, f), spline_cams=int(p == "spline"))
       for p in PROFILES for f in FOLLOWERS},
    "cam-on-ground": Case(cam_on_ground),
    "driver-absolute-x": Case(absolute_driver("x")),
    "driver-absolute-y": Case(absolute_driver("y")),
    "driver-absolute-theta": Case(absolute_driver("theta")),
    "driver-relative-angle": Case(relative_angle_driver),
    "driver-relative-distance": Case(relative_distance_driver),
    "driver-simple-f": Case(constant_and_linear_drivers),
}

N_STATES = 4

# ---------------------------------------------------------------- states


def random_states(model: Model, case: Case, seed: int) -> list[tuple[np.ndarray, np.ndarray,
                                                                     float]]:
    """N_STATES random (q, qd, t); t is away from zero so the time terms matter."""
    rng = np.random.default_rng(seed)
    neq, nq = model.counts()
    nb = len(model.bodies)
    ncam = nq - 3 * nb
    knots = spline_knots()
    out = []
    for _ in range(N_STATES):
        q = np.empty(nq)
        q[0:3 * nb:3] = rng.uniform(-2.0, 2.0, nb)
        q[1:3 * nb:3] = rng.uniform(-2.0, 2.0, nb)
        q[2:3 * nb:3] = rng.uniform(-np.pi, np.pi, nb)
        q[3 * nb:] = rng.uniform(-np.pi, 3.0 * np.pi, ncam)
        for k in range(case.spline_cams):
            # The spline is piecewise cubic: c''' jumps at the knots, and the roller and
            # flat followers use c''' in gamma (and c'' in J). A central difference
            # that straddles a knot is wrong by O(jump) (about 2e-3 here, against a 1e-6
            # tolerance; the J check is unaffected), so alpha is drawn inside
            # a knot interval (at least 20% of its length from either end, far more than
            # any difference step), possibly shifted by a whole turn to exercise the
            # wrap-around.
            i = rng.integers(0, N_SPLINE)
            lo, hi = knots[i], knots[i + 1]
            a = lo + (hi - lo) * rng.uniform(0.2, 0.8)
            q[3 * nb + k] = a + 2.0 * np.pi * rng.integers(-1, 2)
        qd = rng.uniform(-1.5, 1.5, nq)
        t = float(rng.uniform(0.3, 1.7))
        # F_RICH's table is twice differentiable: its third derivative jumps at the points,
        # and the Richardson second difference of Phi_tt (steps up to H_T2) straddling one
        # is off by O(H_T2 jump) (7.7e-4 at t = 0.7986 next to the point 0.8); t keeps
        # 3 H_T2 away from them
        while min(abs(t - tk) for tk in F_RICH["table"]["t"]) < 3 * H_T2:
            t += 6 * H_T2
        out.append((q, qd, t))
    return out


# ---------------------------------------------------------------- finite differences

H_Q = 1e-6     # step for dPhi/dq and dPhi/dt (first derivatives)
H_DIR = 1e-5   # step along qd for d(J qd)/dq qd
# Phi_tt: second differences with steps 2e-3 and 1e-3 combined by Richardson extrapolation
# (truncation O(h^4) ~ 1e-11, roundoff ~ eps |Phi| / h^2 ~ 1e-9). A plain second difference
# with h = 1e-3 is off by h^2 f''''/12 ~ 2e-6 for F_RICH, which would be the oracle's
# error, not the engine's.
H_T2 = 2e-3


def fd_jacobian(m: Model, q: np.ndarray, t: float, columns: list[int]) -> np.ndarray:
    jfd = np.zeros((m.counts()[0], q.size))
    for k in columns:
        e = np.zeros_like(q)
        e[k] = H_Q
        jfd[:, k] = (m.phi(q + e, t) - m.phi(q - e, t)) / (2 * H_Q)
    return jfd


def fd_phi_tt(m: Model, q: np.ndarray, t: float) -> np.ndarray:
    p0 = m.phi(q, t)

    def second(h: float) -> np.ndarray:
        return (m.phi(q, t + h) - 2.0 * p0 + m.phi(q, t - h)) / h**2

    return (4.0 * second(H_T2 / 2) - second(H_T2)) / 3.0


def fd_gamma(m: Model, q: np.ndarray, qd: np.ndarray, t: float) -> np.ndarray:
    quad = (m.jacobian(q + H_DIR * qd, t) @ qd - m.jacobian(q - H_DIR * qd, t) @ qd) / (2 * H_DIR)
    mixed = (m.jacobian(q, t + H_Q) @ qd - m.jacobian(q, t - H_Q) @ qd) / (2 * H_Q)
    return -quad - 2.0 * mixed - fd_phi_tt(m, q, t)


@dataclass
class Evaluated:
    """Core values and their finite-difference oracles at one state."""

    q: np.ndarray
    qd: np.ndarray
    t: float
    jac: np.ndarray
    jac_fd: np.ndarray
    nu: np.ndarray
    nu_fd: np.ndarray
    gamma: np.ndarray
    gamma_fd: np.ndarray


def _seed(name: str) -> int:
    return sum(ord(ch) * (i + 1) for i, ch in enumerate(name))


def spectator_columns(m: Model) -> list[int]:
    k = [b.name for b in m.bodies].index("spectator")
    return [3 * k, 3 * k + 1, 3 * k + 2]


@functools.lru_cache(maxsize=None)
def evaluated(name: str) -> tuple[Model, list[Evaluated]]:
    """Everything the comparisons need, computed once per case (cam evaluations are slow:
    the core re-checks the profile on every call)."""
    c = CASES[name]
    m = c.build()
    # the spectator's columns are checked to be exactly zero in their own test
    cols = [k for k in range(m.counts()[1]) if k not in spectator_columns(m)]
    out = []
    for q, qd, t in random_states(m, c, _seed(name)):
        out.append(Evaluated(q, qd, t, m.jacobian(q, t), fd_jacobian(m, q, t, cols),
                             m.nu(q, t), -(m.phi(q, t + H_Q) - m.phi(q, t - H_Q)) / (2 * H_Q),
                             m.gamma(q, qd, t), fd_gamma(m, q, qd, t)))
    return m, out


@pytest.fixture(params=sorted(CASES))
def case(request):
    name = request.param
    m, states = evaluated(name)
    return name, m, states


def test_shapes_and_rows(case):
    name, m, states = case
    neq, nq = m.counts()
    assert neq == len(m.constraint_rows())
    assert nq == len(m.coordinate_names)
    s = states[0]
    assert m.phi(s.q, s.t).shape == (neq,)
    assert s.jac.shape == (neq, nq)
    assert s.nu.shape == (neq,)
    assert s.gamma.shape == (neq,)


def test_jacobian_matches_finite_differences(case):
    name, m, states = case
    for s in states:
        scale = max(1.0, np.abs(s.jac_fd).max())
        assert_allclose(s.jac, s.jac_fd, rtol=0, atol=1e-7 * scale,
                        err_msg=f"{name} at q={s.q}, t={s.t}")


def test_spectator_columns_are_zero(case):
    name, m, states = case
    for s in states:
        assert np.all(s.jac[:, spectator_columns(m)] == 0.0), name


def test_nu_matches_time_differences(case):
    name, m, states = case
    for s in states:
        scale = max(1.0, np.abs(s.nu_fd).max())
        assert_allclose(s.nu, s.nu_fd, rtol=0, atol=1e-7 * scale, err_msg=f"{name} at t={s.t}")


def test_gamma_matches_finite_differences(case):
    name, m, states = case
    for s in states:
        scale = max(1.0, np.abs(s.gamma_fd).max())
        assert_allclose(s.gamma, s.gamma_fd, rtol=0, atol=1e-6 * scale,
                        err_msg=f"{name} at q={s.q}, qd={s.qd}, t={s.t}")


def test_joints_have_no_time_terms(case):
    """Joints do not depend on t: their rows of nu are exactly zero, and their gamma does
    not change with t."""
    name, m, states = case
    joint_names = {j.name for j in m.joints}
    mask = np.array([r.split(".")[0] in joint_names for r in m.constraint_rows()])
    s = states[0]
    assert np.all(s.nu[mask] == 0.0)
    assert np.array_equal(s.gamma[mask], m.gamma(s.q, s.qd, s.t + 0.37)[mask])


def test_gamma_is_quadratic_in_velocity(case):
    """gamma(q, 3 qd) - gamma(q, 0) = 9 (gamma(q, qd) - gamma(q, 0)): -(J qd)_q qd is a
    quadratic form in qd (and J_t = 0 for every type here)."""
    name, m, states = case
    s = states[0]
    g0 = m.gamma(s.q, np.zeros_like(s.qd), s.t)
    g1 = s.gamma - g0
    g3 = m.gamma(s.q, 3.0 * s.qd, s.t) - g0
    scale = max(1.0, np.abs(g3).max())
    assert_allclose(g3, 9.0 * g1, rtol=0, atol=1e-12 * scale)


def step_closed_form(st: dict, t: float) -> tuple[float, float, float]:
    """h L(u), h L'(u)/T, h L''(u)/T**2 of a step (Norton's motion laws), 0 before t0 and
    (h, 0, 0) from t1 on (right-continuous: at t0 the rise's start)."""
    t0, t1, h = st["t0"], st["t1"], st["h"]
    if t < t0:
        return 0.0, 0.0, 0.0
    if t >= t1:
        return h, 0.0, 0.0
    T, u = t1 - t0, (t - t0) / (t1 - t0)
    law = st.get("law", "cycloidal")
    if law == "cubic":
        y, y1, y2 = 3 * u**2 - 2 * u**3, 6 * u - 6 * u**2, 6 - 12 * u
    elif law == "quintic":
        y, y1, y2 = (10 * u**3 - 15 * u**4 + 6 * u**5, 30 * u**2 - 60 * u**3 + 30 * u**4,
                     60 * u - 180 * u**2 + 120 * u**3)
    elif law == "cycloidal":
        w = 2 * np.pi
        y, y1, y2 = u - np.sin(w * u) / w, 1 - np.cos(w * u), w * np.sin(w * u)
    elif law == "harmonic":
        y, y1, y2 = ((1 - np.cos(np.pi * u)) / 2, np.pi / 2 * np.sin(np.pi * u),
                     np.pi**2 / 2 * np.cos(np.pi * u))
    else:
        y, y1, y2 = modified_law(law, u)
    return h * y, h * y1 / T, h * y2 / T**2


def _accel_shape(law: str, u: float) -> float:
    """The modified laws' acceleration for C = 1 (Norton, ch. 3): sine quarter-waves on the
    first and last eighths, a sine half-wave over the middle three quarters (modified sine),
    or constants on the second and fourth quarter-pairs with a cosine half-wave between
    (modified trapezoid)."""
    if u < 1 / 8:
        return np.sin(4 * np.pi * u)
    if u >= 7 / 8:
        return -np.sin(4 * np.pi * (1 - u))
    if law == "modified-sine":
        return np.cos(4 * np.pi / 3 * (u - 1 / 8))
    if u < 3 / 8:
        return 1.0
    if u < 5 / 8:
        return np.cos(4 * np.pi * (u - 3 / 8))
    return -1.0


def modified_law(law: str, u: float) -> tuple[float, float, float]:
    """L, L', L'' of a modified law by quadrature of its acceleration (40-point
    Gauss-Legendre on each smooth segment, exact to round-off for these analytic pieces):
    L'(u) = int_0^u a, L(u) = int_0^u (u - r) a(r) dr, the scale C from L(1) = 1
    (independent of the core's closed forms)."""
    nodes, weights = np.polynomial.legendre.leggauss(40)
    edges = [0.0, 1 / 8, 3 / 8, 5 / 8, 7 / 8, 1.0]

    def integrals(x: float) -> tuple[float, float]:
        p = v = 0.0
        for a, b in zip(edges[:-1], edges[1:]):
            b = min(b, x)
            if b > a:
                r = a + (b - a) * (nodes + 1) / 2
                acc = np.array([_accel_shape(law, rk) for rk in r])
                v += (b - a) / 2 * float(weights @ acc)
                p += (b - a) / 2 * float(weights @ ((x - r) * acc))
        return p, v

    c = 1.0 / integrals(1.0)[0]
    p, v = integrals(u)
    return c * p, c * v, c * _accel_shape(law, u)


def table_at_point(tab: dict, t: float) -> tuple[float, float, float]:
    """A table's y, y', y'' at one of its points t_k: y_k and the derivatives of the quartic
    through the five points around it (numpy's least squares on five points: the
    interpolant)."""
    tk, yk = np.array(tab["t"]), np.array(tab["y"])
    k = int(np.flatnonzero(tk == t)[0])
    j0 = min(max(k - 2, 0), len(tk) - 5)
    c = np.polynomial.polynomial.polyfit(tk[j0:j0 + 5] - t, yk[j0:j0 + 5], 4)
    return float(yk[k]), float(c[1]), float(2 * c[2])


def test_driver_time_function_values():
    """The driver row is g(q) - f(t) with f evaluated in closed form here."""
    m = absolute_driver("y")()
    q = np.arange(9, dtype=float) * 0.1
    for t in (-0.2, 0.25, 0.8, 1.5):          # (the table's points: see table_at_point)
        f = (0.3 - 0.7 * t + 0.25 * t**2 + 0.05 * t**3
             + 0.4 * np.sin(2.0 * t + 0.3) - 0.15 * np.sin(3.5 * t))
        f1 = (-0.7 + 0.5 * t + 0.15 * t**2 + 0.8 * np.cos(2.0 * t + 0.3)
              - 0.525 * np.cos(3.5 * t))
        f2 = 0.5 + 0.3 * t - 1.6 * np.sin(2.0 * t + 0.3) + 0.15 * 12.25 * np.sin(3.5 * t)
        for st in F_RICH["step"]:
            g = step_closed_form(st, t)
            f, f1, f2 = f + g[0], f1 + g[1], f2 + g[2]
        g = table_at_point(F_RICH["table"], t)
        f, f1, f2 = f + g[0], f1 + g[1], f2 + g[2]
        # body "b" is the third body: y is q[7]
        assert_allclose(m.phi(q, t), [q[7] - f], rtol=0, atol=1e-14)
        assert_allclose(m.nu(q, t), [f1], rtol=0, atol=1e-14)
        assert_allclose(m.gamma(q, np.ones(9), t), [f2], rtol=0, atol=1e-13)

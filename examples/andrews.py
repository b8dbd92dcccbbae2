"""Andrews' squeezing mechanism (Hairer & Wanner, Solving ODEs II, sec. VII.7; problem 'andrews'
of the IVP test set, Mazzia & Magherini): seven bodies, ten revolute joints, one degree of
freedom, driven by a constant torque on the crank against a stiff spring. Gravity is neglected.

The test set writes it in seven relative angles (beta, Theta, gamma, Phi, delta, Omega,
epsilon); here it is in absolute coordinates (x, y, theta of each centre of mass). The absolute
angles are

    th1 = beta           crank OF, pivot O at the origin, F at rr along th1
    th2 = beta + Theta   rod FE, E = F - d (cos th2, sin th2)
    th3 = gamma          triangle BDE pivoted at B; E = B + A(th3)(0, -ss), D = B + A(th3)(sd, -sc)
    th4 = Phi + delta    rod EG, E = G + A(th4)(0, -e)
    th5 = delta          rod AG pivoted at A, G = A + A(th5)(zt, 0)
    th6 = Omega + eps    rod HE, E = H + A(th6)(zf, 0)
    th7 = epsilon        rod AH pivoted at A, H = A + A(th7)(0, -u)

and the spring (c0, l0) joins the ground point C to D on the triangle.

    python examples/andrews.py      # writes examples/andrews.toml, runs dopri5 to t = 0.03
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

import mbd2d

HERE = Path(__file__).resolve().parent
TOML = HERE / "andrews.toml"

# ---------------------------------------------------------------- IVP test set data (SI units)
MASS = (.04325, .00365, .02373, .00706, .07050, .00706, .05498)
INERTIA = (2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5)
XA, YA = -.06934, -.00227
XB, YB = -0.03635, .03273
XC, YC = .014, .072
D, DA = 28e-3, 115e-4
E, EA = 2e-2, 1421e-5
RR, RA = 7e-3, 92e-5
SS, SA, SB, SC, SD = 35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2
TA, TB = 2308e-5, 916e-5
U, UA, UB = 4e-2, 1228e-5, 449e-5
ZF, ZT, FA = 2e-2, 4e-2, 1421e-5
C0, L0 = 4530.0, 7785e-5
MOM = 33e-3

#: Consistent initial relative angles (at rest): beta, Theta, gamma, Phi, delta, Omega, epsilon.
Y0 = (-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568)

T_END = 0.03
#: Reference solution at t = 0.03 (IVP test set, RADAU5 at tight tolerance, 16 digits).
REF = (15.81077119629904, -15.75637105984298, 0.04082224013073101, -0.5347301163226948,
       0.5244099658805304, 0.5347301163226948, 1.048080741042263)
RELATIVE = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")
BODIES = ("b1", "b2", "b3", "b4", "b5", "b6", "b7")


def rot(th: float, p: tuple[float, float]) -> np.ndarray:
    """A(th) p."""
    c, s = math.cos(th), math.sin(th)
    return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])


def absolute_angles(y: tuple[float, ...]) -> tuple[float, ...]:
    """Absolute angles th1..th7 from the relative angles."""
    be, Th, ga, Ph, de, Om, ep = y
    return (be, be + Th, ga, Ph + de, de, Om + ep, ep)


def relative_angles(theta: np.ndarray) -> np.ndarray:
    """Relative angles (beta, Theta, gamma, Phi, delta, Omega, epsilon) from the absolute
    angles th1..th7 (last axis); works for angles, their rates and accelerations alike."""
    th = np.asarray(theta, dtype=float)
    t1, t2, t3, t4, t5, t6, t7 = (th[..., k] for k in range(7))
    return np.stack([t1, t2 - t1, t3, t4 - t5, t5, t6 - t7, t7], axis=-1)


# Points in the body frames (origin at the centre of mass, rotated by the body's angle).
LOCAL = {
    "O": (-RA, 0.0), "F1": (RR - RA, 0.0),                      # b1
    "F2": (DA, 0.0), "E2": (DA - D, 0.0),                        # b2
    "B3": (-SB, SA), "E3": (-SB, SA - SS), "D3": (SD - SB, SA - SC),  # b3
    "E4": (0.0, -EA), "G4": (0.0, E - EA),                       # b4
    "A5": (-TA, -TB), "G5": (ZT - TA, -TB),                      # b5
    "H6": (FA - ZF, 0.0), "E6": (FA, 0.0),                       # b6
    "A7": (UA, UB), "H7": (UA, UB - U),                          # b7
}


def initial_q(y: tuple[float, ...] = Y0) -> list[list[float]]:
    """Forward kinematics: [x, y, theta] of each body's centre of mass from the relative
    angles (each from its own chain of the test set's geometry)."""
    th = absolute_angles(y)
    o, a, b = np.zeros(2), np.array([XA, YA]), np.array([XB, YB])
    f = o + rot(th[0], (RR, 0.0))
    g = a + rot(th[4], (ZT, 0.0))
    h = a + rot(th[6], (0.0, -U))
    com = [o + rot(th[0], (RA, 0.0)),
           f + rot(th[1], (-DA, 0.0)),
           b + rot(th[2], (SB, -SA)),
           g + rot(th[3], (0.0, -(E - EA))),
           a + rot(th[4], (TA, TB)),
           h + rot(th[5], (ZF - FA, 0.0)),
           a + rot(th[6], (-UA, -UB))]
    return [[float(c[0]), float(c[1]), float(t)] for c, t in zip(com, th)]


def build(name: str = "andrews") -> mbd2d.Model:
    """Andrews' squeezing mechanism as a model (21 coordinates, 20 equations, 1 DOF)."""
    m = mbd2d.Model(name, gravity=(0.0, 0.0))
    for bname, q0, mass, inertia in zip(BODIES, initial_q(), MASS, INERTIA):
        m.add_body(bname, q0=q0, mass=mass, inertia=inertia)
    P = LOCAL
    m.add_revolute(["ground", "b1"], [[0.0, 0.0], P["O"]], name="O")
    m.add_revolute(["b1", "b2"], [P["F1"], P["F2"]], name="F")
    m.add_revolute(["ground", "b3"], [[XB, YB], P["B3"]], name="B")
    m.add_revolute(["b2", "b3"], [P["E2"], P["E3"]], name="E23")
    m.add_revolute(["b3", "b4"], [P["E3"], P["E4"]], name="E34")
    m.add_revolute(["b3", "b6"], [P["E3"], P["E6"]], name="E36")
    m.add_revolute(["b4", "b5"], [P["G4"], P["G5"]], name="G")
    m.add_revolute(["ground", "b5"], [[XA, YA], P["A5"]], name="A5")
    m.add_revolute(["b6", "b7"], [P["H6"], P["H7"]], name="H")
    m.add_revolute(["ground", "b7"], [[XA, YA], P["A7"]], name="A7")
    m.add_spring(["ground", "b3"], [[XC, YC], P["D3"]], stiffness=C0, damping=0.0,
                 length0=L0, name="spring")
    m.add_torque("b1", f=MOM, name="motor")
    return m


def _num(x: float) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return "[" + ", ".join(_num(x) for x in v) + "]"


def toml_text(model: mbd2d.Model) -> str:
    """The model as TOML (every number with repr precision, so it loads back exactly)."""
    out = ["# Andrews' squeezing mechanism (Hairer & Wanner II, VII.7; IVP test set 'andrews').",
           "# Generated by examples/andrews.py -- edit that file and rerun it instead.",
           "# 7 bodies, 10 revolutes, 1 DOF; constant torque on b1 against the spring on b3.",
           f"# Reference at t = {T_END}: beta, Theta, gamma, Phi, delta, Omega, epsilon =",
           "#   " + ", ".join(repr(r) for r in REF),
           "# (Theta = b2 - b1, Phi = b4 - b5, Omega = b6 - b7 in the absolute angles).",
           "[model]", f'name = "{model.name}"', f"gravity = {_vec(model.gravity)}", ""]
    for b in model.bodies:
        out += ["[[body]]", f'name = "{b.name}"', f"q0 = {_vec(b.q0)}",
                f"mass = {_num(b.mass)}", f"inertia = {_num(b.inertia)}", ""]
    for j in model.joints:
        pts = "[" + ", ".join(_vec(p) for p in j.points) + "]"
        out += ["[[joint]]", f'name = "{j.name}"', f'type = "{j.type}"',
                f'bodies = ["{j.bodies[0]}", "{j.bodies[1]}"]', f"points = {pts}", ""]
    for f in model.forces:
        out += ["[[force]]", f'name = "{f.name}"', f'type = "{f.type}"']
        if f.type == "spring":
            pts = "[" + ", ".join(_vec(p) for p in f.points) + "]"
            out += [f'bodies = ["{f.bodies[0]}", "{f.bodies[1]}"]', f"points = {pts}",
                    f"stiffness = {_num(f.stiffness)}", f"damping = {_num(f.damping)}",
                    f"length0 = {_num(f.length0)}"]
        elif f.type == "torque":
            out += [f'body = "{f.bodies[0]}"', f"f = {_num(MOM)}"]
        else:  # pragma: no cover
            raise ValueError(f"unexpected force type {f.type!r}")
        out.append("")
    return "\n".join(out)


def to_toml(path: str | Path = TOML) -> Path:
    """Write the model file (examples/andrews.toml by default)."""
    p = Path(path)
    p.write_text(toml_text(build()), encoding="utf-8")
    return p


def angle_errors(res: mbd2d.DynamicsResult) -> np.ndarray:
    """Relative angles at the last output minus the reference (7 values)."""
    th = np.array([res.body(b).theta[-1] for b in BODIES])
    return relative_angles(th) - np.array(REF)


def main() -> None:
    path = to_toml()
    print(f"wrote {path}")
    m = build()
    t0 = time.perf_counter()
    res = m.dynamics(t_end=T_END, steps=30, method="dopri5", rtol=1e-10, atol=1e-12)
    dt = time.perf_counter() - t0
    err = angle_errors(res)
    print(f"dopri5 rtol=1e-10 atol=1e-12: {res.stats['steps']} steps "
          f"({res.stats['rejected_steps']} rejected), {dt:.3f} s")
    for name, r, e in zip(RELATIVE, REF, err):
        print(f"  {name:8s} {r:+.16f}  error {e:+.2e}")
    print(f"  max |error| = {np.max(np.abs(err)):.2e}")


if __name__ == "__main__":
    main()

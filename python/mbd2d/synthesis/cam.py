"""Cam synthesis: the profile of a disc cam whose translating follower moves by a program.

    cam_profile(program, base_radius, follower="roller", roller_radius=0.0, offset=0.0,
                points=720) -> CamDesign

The program s(theta) is a function in the form of a driver's function of time (``poly``,
``harmonic``, ``step``) with its t read as the cam angle theta [rad], closing over one turn:
a rise of 20 mm over 90 degrees by the cycloidal law, a dwell, the return, a dwell is
``{"step": [{"t0": 0, "t1": pi/2, "h": 0.02}, {"t0": pi, "t1": 3*pi/2, "h": -0.02}]}``.
The core evaluates s, s', s'' (the functions' own code). The cam turns counterclockwise about
its origin; the follower translates along +y, its axis at x = offset.

Roller follower (a knife edge with roller_radius = 0), Rp = base_radius + roller_radius,
d0 = sqrt(Rp**2 - e**2), in the cam's frame (R(-theta) turns the ground frame into it):
    pitch point        P = R(-theta) (e, d0 + s)
    tangent            P' = R(-theta) w,  w = (d0 + s, s' - e)  (the pitch curve runs clockwise)
    surface            C = P - Rr n,  n = J P'/|P'| (outward; J turns by +90 degrees)
    pressure angle     phi = atan2(s' - e, d0 + s)
    pitch curvature    rho = -|w|**3 / (w x u),  u = (2 s' - e, s'' - d0 - s)  (> 0 convex)
and the surface's radius of curvature rho - Rr; where 0 < rho < Rr the roller cannot follow
the pitch curve (undercut: the surface has a cusp). Flat-faced follower (its face normal to
the axis): C = R(-theta) (s', base_radius + s), radius of curvature base_radius + s + s''
(> 0, else a cusp), pressure angle 0, contact at x = s' along the face (Norton, Cam Design
and Manufacturing Handbook, ch. 7 and 8). Oscillating followers (``arm``): a roller at the end
of an arm, or a flat face on it, turning about a ground pivot by the program's angle (see
_arm and _arm_flat).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..binding import core
from ..description.functions import TimeFunction, as_function
from ..errors import ModelError
from ..model import Model
from ..validate import nonnegative, number, only_keys, positive, vector
from .taskfile import read_toml

ENTRY = "cam_profile"
#: followers of cam_profile
FOLLOWERS = ("roller", "flat")
#: a program closes when s and s' at 2 pi equal those at 0 to this, relative to the largest
#: of each over the turn (or to the base radius); s'' may jump there as at any step's ends
CLOSE_TOL = 1e-9


@dataclass
class CamDesign:
    """A synthesized disc cam (see the module's header for the formulas).

    Attributes
    ----------
    theta : ndarray
        Cam angles of the samples, ``points`` of them over [0, 2 pi).
    s, ds, dds : ndarray
        The program and its first two derivatives with respect to theta.
    points : ndarray
        (points, 2) the cam's surface in its own frame, one point per theta.
    pressure_angle : ndarray
        Angle between the contact normal and the follower's axis [rad] (0: flat face).
    curvature_radius : ndarray
        The surface's radius of curvature (> 0 convex, < 0 concave; < 0 where ``convex`` is
        an undercut: the roller is sharper than the pitch curve there).
    convex : ndarray
        Where the pitch curve (the roller centre's path in the cam) is convex.
    undercut : bool
        True when the surface has a cusp somewhere (the follower cannot keep the program).
    face : tuple of float
        Flat-faced follower: the contact's extent along the face (min s', max s' from the
        axis; on an arm, the distance from the pivot's foot on the face).
    """

    program: TimeFunction
    follower: str
    base_radius: float
    roller_radius: float
    offset: float
    theta: np.ndarray
    s: np.ndarray
    ds: np.ndarray
    dds: np.ndarray
    points: np.ndarray
    pressure_angle: np.ndarray
    curvature_radius: np.ndarray
    convex: np.ndarray
    undercut: bool
    face: tuple[float, float]
    #: an oscillating follower: its arm's ground pivot, length (roller), angle at psi = 0
    #: and the face's offset from the pivot (flat face)
    pivot: tuple[float, float] | None = None
    arm_length: float = 0.0
    arm_angle0: float = 0.0
    face_offset: float = 0.0

    @property
    def max_pressure_angle(self) -> float:
        """The largest |pressure angle| [rad] over the turn."""
        return float(np.abs(self.pressure_angle).max())

    @property
    def min_curvature_radius(self) -> float:
        """The smallest radius of curvature of the surface where the pitch curve is convex
        (negative: undercut there); inf when it is nowhere convex."""
        convex = self.curvature_radius[self.convex]
        return float(convex.min()) if convex.size else math.inf

    def profile(self) -> dict[str, Any]:
        """The cam joint's ``profile`` (a periodic spline through the surface points)."""
        return {"spline": {"points": self.points.tolist()}}

    def follower_spec(self) -> dict[str, Any]:
        """The cam joint's ``follower`` on the follower body (its origin on the axis; an
        arm's origin at its pivot, the roller at (length, 0))."""
        if self.follower == "flat":
            return {"flat": {"point": [0.0, self.face_offset], "normal": [0.0, -1.0]}}
        at = [self.arm_length, 0.0] if self.pivot is not None else [0.0, 0.0]
        if self.roller_radius == 0.0:
            return {"point": at}
        return {"roller": {"center": at, "radius": self.roller_radius}}

    def model(self, speed: float = 2 * math.pi, name: str = "cam-follower",
              masses: Mapping[str, tuple[float, float]] | None = None) -> Model:
        """The cam and its follower as a model: the cam turning at ``speed`` [rad/s] about
        the origin (driver ``motor``), the follower on the guide ``guide`` along +y (an arm
        on the revolute ``arm_pivot``), the cam joint ``contact``; ``masses`` maps "cam" and
        "follower" to (mass, inertia).

        Raises
        ------
        ModelError
            If the cam is undercut (its surface has a cusp) or an argument is bad.
        """
        speed = number(speed, "speed", ENTRY)
        if not speed > 0.0:
            raise ModelError(f"speed must be positive (the profile is made for a cam turning "
                             f"counterclockwise), got {speed:g}; for a clockwise cam, "
                             "mirror the model", ENTRY)
        if self.undercut:
            bad = np.flatnonzero(self.convex & (self.curvature_radius <= 0.0))
            raise ModelError(f"the cam is undercut (its surface has a cusp near theta = "
                             f"{math.degrees(self.theta[bad[0]]):.1f} deg, radius of "
                             f"curvature {self.min_curvature_radius:.3g}): the follower "
                             "cannot keep the program; raise base_radius, use a smaller "
                             "roller or a longer rise", ENTRY)
        masses = dict(masses or {})
        unknown = set(masses) - {"cam", "follower"}
        if unknown:
            raise ModelError(f"masses are for 'cam' and 'follower', got {sorted(unknown)}",
                             ENTRY)
        m = Model(name)
        if self.pivot is not None:
            q0f = [*self.pivot, self.arm_angle0 + float(self.s[0])]
        else:
            y0 = (self.base_radius if self.follower == "flat" else self._d0()) + float(self.s[0])
            q0f = [self.offset if self.follower == "roller" else 0.0, y0, 0.0]
        for body, q0 in (("cam", [0.0, 0.0, 0.0]), ("follower", q0f)):
            mi = masses.get(body)
            m.add_body(body, q0=q0, **({"mass": mi[0], "inertia": mi[1]} if mi else {}))
        m.add_revolute(["ground", "cam"], [[0.0, 0.0], [0.0, 0.0]], name="pivot")
        if self.pivot is not None:
            m.add_revolute(["ground", "follower"], [list(self.pivot), [0.0, 0.0]],
                           name="arm_pivot")
        else:
            m.add_translational(["ground", "follower"], [[q0f[0], 0.0], [0.0, 0.0]],
                                [[0.0, 1.0], [0.0, 1.0]], name="guide")
        m.add_cam(["cam", "follower"], self.profile(), self.follower_spec(), name="contact")
        m.add_driver("absolute", body="cam", coordinate="theta", f={"poly": [0.0, speed]},
                     name="motor")
        return m

    def _d0(self) -> float:
        rp = self.base_radius + self.roller_radius
        return math.sqrt(rp * rp - self.offset * self.offset)


def cam_profile(program: Any, base_radius: float, follower: str = "roller",
                roller_radius: float = 0.0, offset: float = 0.0, points: int = 720,
                arm: Mapping[str, Any] | None = None) -> CamDesign:
    """The disc cam that moves a translating follower, or a roller on an oscillating arm,
    by ``program``.

    Parameters
    ----------
    program : mapping, number or TimeFunction
        s(theta) as a function of time with t read as the cam angle (see the module's
        header); it must close over one turn (s and s' equal at 0 and 2 pi).
    base_radius : float
        Radius of the base circle (the cam's smallest radius where s = 0).
    follower : str
        ``"roller"`` (with ``roller_radius``; 0 is a knife edge) or ``"flat"`` (a flat face
        normal to the follower's axis).
    roller_radius : float
        Roller radius (roller follower).
    offset : float
        Roller follower: the axis' offset x = offset from the cam's centre.
    points : int
        Samples of the surface over the turn (the spline's points), at least 16.
    arm : mapping, optional
        ``{"pivot": [x, y], "length": L}``: the roller (or knife edge) sits at the end of an
        arm pivoted in the ground at ``pivot``; with ``follower="flat"``, ``{"pivot": [x, y],
        "offset": e}``: the arm carries a flat face at the distance e from the pivot. The
        program is then the arm's angle psi(theta) [rad], counterclockwise positive, a
        positive psi lifting the follower away from the cam's centre.

    Returns
    -------
    CamDesign

    Raises
    ------
    ModelError
        For a program that does not close or reaches inside the cam's centre, or a bad
        argument.
    """
    f = as_function(program, ENTRY, "program")
    rb = positive(base_radius, "base_radius", ENTRY)
    if follower not in FOLLOWERS:
        raise ModelError(f"follower must be 'roller' or 'flat', got {follower!r}", ENTRY)
    rr = nonnegative(roller_radius, "roller_radius", ENTRY)
    e = number(offset, "offset", ENTRY)
    if follower == "flat" and (rr != 0.0 or e != 0.0):
        raise ModelError("a flat-faced follower has no roller_radius and no offset", ENTRY)
    if not isinstance(points, (int, np.integer)) or isinstance(points, bool) or points < 16:
        raise ModelError(f"points must be a whole number >= 16, got {points!r}", ENTRY)
    if arm is not None and e != 0.0:
        raise ModelError("an oscillating arm has no offset (a flat face's offset from the "
                         "pivot is the arm's 'offset')", ENTRY)
    if abs(e) >= rb + rr:
        raise ModelError(f"|offset| = {abs(e):g} must be below base_radius + roller_radius "
                         f"= {rb + rr:g} (the follower's axis must cross the base circle)",
                         ENTRY)
    theta = np.linspace(0.0, 2 * np.pi, int(points), endpoint=False)
    s, ds, dds = _program(f, theta, rb)
    if follower == "flat":
        if arm is not None:
            return _arm_flat(f, rb, arm, theta, s, ds, dds)
        return _flat(f, rb, theta, s, ds, dds)
    if arm is not None:
        return _arm(f, rb, rr, arm, theta, s, ds, dds)
    return _roller(f, rb, rr, e, theta, s, ds, dds)


def _program(f: TimeFunction, theta: np.ndarray, rb: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, s', s'' at theta from the core; checks that the program closes over the turn."""
    out = core.fun_values(np.asarray(f.encode(), dtype=float),
                          np.append(theta, 2 * np.pi))
    if out.status != 0:
        raise ModelError(f"program: {out.msg}", ENTRY)
    vals = [np.asarray(v, dtype=float) for v in (out.f, out.f1, out.f2)]
    for k, v in enumerate(vals):
        if not np.all(np.isfinite(v)):
            raise ModelError("program: its values overflow over the turn", ENTRY)
        if k < 2 and abs(v[-1] - v[0]) > CLOSE_TOL * max(rb, float(np.abs(v).max())):
            what = ("s", "s'")[k]
            raise ModelError(f"program does not close over one turn: {what}(2 pi) - "
                             f"{what}(0) = {v[-1] - v[0]:.3g}; the rises and returns must "
                             "sum to zero and the follower end at the speed it starts with",
                             ENTRY)
    return vals[0][:-1], vals[1][:-1], vals[2][:-1]


def _rotate_back(theta: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """R(-theta) (x, y) per sample, as (n, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([c * x + s * y, -s * x + c * y])


def _roller(f: TimeFunction, rb: float, rr: float, e: float, theta: np.ndarray,
            s: np.ndarray, ds: np.ndarray, dds: np.ndarray) -> CamDesign:
    """A translating roller: its centre at (e, d0 + s) in the ground frame."""
    d0 = math.sqrt((rb + rr)**2 - e * e)
    if np.any(d0 + s <= 0.0):
        raise ModelError("program: the follower reaches the cam's centre (d0 + s <= 0); "
                         "raise base_radius", ENTRY)
    zero, one = np.zeros_like(s), np.ones_like(s)
    pitch = _pitch(theta, np.column_stack([np.full_like(s, e), d0 + s]),
                   np.column_stack([zero, ds]), np.column_stack([zero, dds]),
                   np.column_stack([zero, one]), rr)
    return CamDesign(f, "roller", rb, rr, e, theta, s, ds, dds, *pitch, (0.0, 0.0))


def _arm(f: TimeFunction, rb: float, rr: float, arm: Mapping[str, Any], theta: np.ndarray,
         s: np.ndarray, ds: np.ndarray, dds: np.ndarray) -> CamDesign:
    """An oscillating roller: the arm of length L about the ground point P at the angle
    phi = phi0 + psi(theta) (psi the program, counterclockwise lifts); its centre
    R = P + L u(phi), R' = L psi' J u, R'' = L psi'' J u - L psi'**2 u. phi0 puts the roller
    on the prime circle |R| = Rb + Rr at psi = 0, on the side where a positive psi moves it
    away from the cam's centre: phi0 = beta - acos(c/|P|), c = (Rp**2 - |P|**2 - L**2)/(2L),
    beta the direction of P."""
    if not isinstance(arm, Mapping):
        raise ModelError("arm must be a table { pivot = [x, y], length = L }", ENTRY)
    only_keys(arm, {"pivot", "length"}, "cam_profile arm", required=["pivot", "length"])
    piv = np.array(vector(arm["pivot"], 2, "arm.pivot", ENTRY), dtype=float)
    length = positive(arm["length"], "arm.length", ENTRY)
    rp, dist = rb + rr, float(np.hypot(*piv))
    c = (rp * rp - dist * dist - length * length) / (2 * length)
    if not dist > abs(c):
        raise ModelError(f"the arm cannot put its roller on the prime circle (radius {rp:g}): "
                         f"pivot at {dist:g} from the cam's centre, arm {length:g}; its "
                         "length must lie between |pivot| - Rp and |pivot| + Rp", ENTRY)
    phi0 = math.atan2(piv[1], piv[0]) - math.acos(c / dist)
    phi = phi0 + s
    u = np.column_stack([np.cos(phi), np.sin(phi)])
    ju = np.column_stack([-u[:, 1], u[:, 0]])
    rg = piv + length * u
    if np.any(np.hypot(rg[:, 0], rg[:, 1]) <= rr):
        raise ModelError("program: the roller reaches the cam's centre; raise base_radius",
                         ENTRY)
    pitch = _pitch(theta, rg, length * ds[:, None] * ju,
                   length * (dds[:, None] * ju - (ds * ds)[:, None] * u), ju, rr)
    d = CamDesign(f, "roller", rb, rr, 0.0, theta, s, ds, dds, *pitch, (0.0, 0.0))
    d.pivot, d.arm_length, d.arm_angle0 = (float(piv[0]), float(piv[1])), length, phi0
    return d


def _arm_flat(f: TimeFunction, rb: float, arm: Any, theta: np.ndarray, s: np.ndarray,
              ds: np.ndarray, dds: np.ndarray) -> CamDesign:
    """A flat face on an oscillating arm: the arm about the ground point P at the angle
    phi = phi0 + psi(theta), its face the line P + e J u + lambda u (u = (cos phi, sin phi),
    e the face's offset from the pivot), the cam on its -J u side. In ground-aligned axes the
    face is m . Y = h with m = J u (the cam's outward normal at the contact) and
    h = m . P + e = |P| sin(beta - phi) + e; in the cam's frame the normal turns at
    alpha' = psi' - 1, so the surface is the envelope Y = h m + h_a J m, h_a = h'/(psi' - 1),
    with the radius of curvature h + h_aa, h_aa = (h'' (psi' - 1) - h' psi'')/(psi' - 1)**3
    (> 0, else a cusp). phi0 puts the face on the base circle at psi = 0 on the side where a
    positive psi lifts it: phi0 = beta - pi + asin((Rb - e)/|P|)."""
    if not isinstance(arm, Mapping):
        raise ModelError("arm must be a table { pivot = [x, y], offset = e }", ENTRY)
    only_keys(arm, {"pivot", "offset"}, "cam_profile arm", required=["pivot"])
    piv = np.array(vector(arm["pivot"], 2, "arm.pivot", ENTRY), dtype=float)
    e = number(arm.get("offset", 0.0), "arm.offset", ENTRY)
    dist, beta = float(np.hypot(*piv)), math.atan2(piv[1], piv[0])
    if not dist > abs(rb - e):
        raise ModelError(f"the face cannot touch the base circle (radius {rb:g}): pivot at "
                         f"{dist:g} from the cam's centre, face offset {e:g}", ENTRY)
    if np.any(ds >= 1.0):
        raise ModelError("program: the arm would turn with the cam (psi' >= 1: the face "
                         "cannot stay on it)", ENTRY)
    phi0 = beta - math.pi + math.asin((rb - e) / dist)
    phi = phi0 + s
    u = np.column_stack([np.cos(phi), np.sin(phi)])
    m = np.column_stack([-u[:, 1], u[:, 0]])
    sb, cb = np.sin(beta - phi), np.cos(beta - phi)
    h = dist * sb + e
    h1 = -dist * cb * ds
    h2 = -dist * sb * ds**2 - dist * cb * dds
    w = ds - 1.0
    ha = h1 / w
    rho = h + (h2 * w - h1 * dds) / w**3
    jm = np.column_stack([-m[:, 1], m[:, 0]])
    y = h[:, None] * m + ha[:, None] * jm
    vel = np.column_stack([-(y - piv)[:, 1], (y - piv)[:, 0]])       # J (Y - P)
    angle = np.arctan2(vel[:, 0] * m[:, 1] - vel[:, 1] * m[:, 0],
                       vel[:, 0] * m[:, 0] + vel[:, 1] * m[:, 1])
    lam = np.einsum("ij,ij->i", y - piv, u)
    d = CamDesign(f, "flat", rb, 0.0, 0.0, theta, s, ds, dds,
                  _rotate_back(theta, y[:, 0], y[:, 1]), angle, rho,
                  np.ones(len(s), dtype=bool), bool(np.any(rho <= 0.0)),
                  (float(lam.min()), float(lam.max())))
    d.pivot, d.arm_angle0, d.face_offset = (float(piv[0]), float(piv[1])), phi0, e
    return d


def _pitch(theta: np.ndarray, rg: np.ndarray, rg1: np.ndarray, rg2: np.ndarray,
           vdir: np.ndarray, rr: float) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                 np.ndarray, bool]:
    """The surface, pressure angle, radius of curvature, convexity and undercut of a roller
    whose centre is rg(theta) in the ground frame (derivatives rg1, rg2; vdir the direction
    its motion takes when the program rises). In ground-aligned axes the pitch curve's
    tangent is w = rg' - J rg and w' = rg'' - J rg', u = w' - J w (d/dtheta R(-theta) =
    -R(-theta) J); the outward normal J w/|w|, the pitch radius -|w|**3/(w x u) (> 0 convex),
    the pressure angle from vdir to the normal."""
    jrg = np.column_stack([-rg[:, 1], rg[:, 0]])
    w = rg1 - jrg
    w1 = rg2 - np.column_stack([-rg1[:, 1], rg1[:, 0]])
    u = w1 - np.column_stack([-w[:, 1], w[:, 0]])
    wn = np.hypot(w[:, 0], w[:, 1])
    ng = np.column_stack([-w[:, 1], w[:, 0]]) / wn[:, None]
    normal = _rotate_back(theta, ng[:, 0], ng[:, 1])
    surface = _rotate_back(theta, rg[:, 0], rg[:, 1]) - rr * normal
    cross = w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]
    with np.errstate(divide="ignore"):
        rho = np.where(cross != 0.0, -wn**3 / cross, np.inf)
    angle = np.arctan2(vdir[:, 0] * ng[:, 1] - vdir[:, 1] * ng[:, 0],
                       vdir[:, 0] * ng[:, 0] + vdir[:, 1] * ng[:, 1])
    return surface, angle, rho - rr, rho > 0.0, bool(np.any((rho > 0.0) & (rho < rr)))


def _flat(f: TimeFunction, rb: float, theta: np.ndarray, s: np.ndarray, ds: np.ndarray,
          dds: np.ndarray) -> CamDesign:
    rho = rb + s + dds
    return CamDesign(f, "flat", rb, 0.0, 0.0, theta, s, ds, dds,
                     _rotate_back(theta, ds, rb + s), np.zeros_like(s), rho,
                     np.ones(len(s), dtype=bool), bool(np.any(rho <= 0.0)),
                     (float(ds.min()), float(ds.max())))


#: the keys of a cam task file's [cam] table (cam_profile's arguments and the model's speed)
CAM_KEYS = {"program", "base_radius", "follower", "roller_radius", "offset", "points",
            "speed", "name", "arm"}


def load_cam(path: str | Path) -> tuple[CamDesign, Model, float]:
    """Read a cam task file (the input of ``mbd2d cam TASK.toml --out MODEL.toml``)::

        [cam]
        base_radius = 0.05
        follower = "roller"             # roller | flat
        roller_radius = 0.01
        offset = 0.0                    # optional
        points = 720                    # optional
        arm = { pivot = [0.12, 0.0], length = 0.1 }   # optional: an oscillating arm
        speed = 6.283185307179586       # optional: the motor's rad/s (default 2 pi)
        program = { step = [{ t0 = 0.0, t1 = 1.5707963267948966, h = 0.02 },
                            { t0 = 3.141592653589793, t1 = 4.71238898038469, h = -0.02 }] }

    Returns
    -------
    (CamDesign, Model, float)
        The design, its cam-follower model and the cam's speed [rad/s].

    Raises
    ------
    ModelError
        If the file cannot be read, a key is unknown or malformed, or the cam is undercut.
    """
    p, data = read_toml(path, "cam task file", ENTRY)
    only_keys(data, {"cam"}, str(p), required=["cam"])
    spec = data["cam"]
    if not isinstance(spec, Mapping):
        raise ModelError("[cam] must be a table", str(p))
    only_keys(spec, CAM_KEYS, "[cam]", required=["program", "base_radius"])
    args = {k: v for k, v in spec.items() if k not in ("program", "base_radius", "speed",
                                                        "name")}
    design = cam_profile(spec["program"], spec["base_radius"], **args)
    speed = number(spec.get("speed", 2 * math.pi), "speed", "[cam]")
    model = design.model(speed=speed, name=str(spec.get("name", "cam-follower")))
    return design, model, speed


def cam_report(d: CamDesign, speed: float | None = None) -> str:
    """The design's figures as text (pressure angle, curvature, face width; with the cam's
    speed [rad/s] the follower's largest speed s' w and acceleration s'' w**2)."""
    k = int(np.argmax(np.abs(d.pressure_angle)))
    what = "swing" if d.pivot is not None else "lift"
    lines = [f"{d.follower} follower" + (" on an arm" if d.pivot is not None else "")
             + f", base radius {d.base_radius:g}"
             + (f", roller radius {d.roller_radius:g}" if d.follower == "roller" else "")
             + (f", offset {d.offset:g}" if d.pivot is None and d.follower == "roller" else "")
             + f", {len(d.theta)} profile points",
             f"{what}: {d.s.min():.6g} .. {d.s.max():.6g}"]
    if speed is not None:
        lines.append(f"at {speed:g} rad/s: largest {what} speed {np.abs(d.ds).max() * speed:.6g}"
                     f", acceleration {np.abs(d.dds).max() * speed**2:.6g}")
    lines += [f"largest pressure angle: {math.degrees(d.pressure_angle[k]):.3f} deg at theta = "
              f"{math.degrees(d.theta[k]):.2f} deg",
              f"smallest radius of curvature (convex): {d.min_curvature_radius:.6g}"
              + ("  UNDERCUT: the surface has a cusp" if d.undercut else "")]
    if d.follower == "flat":
        lines.append(f"contact along the face: {d.face[0]:.6g} .. {d.face[1]:.6g} "
                     f"(face width at least {d.face[1] - d.face[0]:.6g})")
    return "\n".join(lines)

"""Quantities a linkage is judged by, over a run: transmission angle, velocity ratio and
mechanical advantage, and the distance to a dead centre.

* Transmission angle (Norton, *Design of Machinery*, ch. 4): at the joint B where a two-force
  coupler (its other joint A) drives the output link, mu is the angle between the coupler
  B->A and the output link B->P (P its other pivot): in [0, pi], best at pi/2, and for a
  four-bar cos mu = (b^2 + c^2 - a^2 - d^2 + 2 a d cos theta2) / (2 b c). When the output
  slides (a translational joint), the ideal direction of the force is along the slide:
  mu = pi/2 - delta, delta the acute angle between the coupler and the slide axis (in
  [0, pi/2]; pi/2 when the coupler pushes along the slide).
* Velocity ratio and mechanical advantage (virtual work): each quantity X (a coordinate, or
  the quantity a driver prescribes) moves by dX/ds per unit of the quantity s a driver D
  moves, the other drivers held: the kinematic influence coefficients, computed by the core
  (J u = e_D). The velocity ratio is dY/dX = (dY/ds)/(dX/ds); the mechanical advantage, the
  load at Y that an effort at X balances, is its inverse dX/dY (power in = power out).
* Distance to a dead centre: sigma_min / sigma_max of the column-scaled J in the core's
  units, computed by the core; 0 at a singular configuration.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..binding import core
from ..binding.pack import pack
from ..binding.params import parameter_table
from ..binding.status import OK, error_for
from ..binding.tables import MeasureTables, Packed
from ..description.joints import PointOnLine, Revolute, Translational
from ..description.parameters import find
from ..errors import MbdError, ModelError
from ..validate import GROUND
from .columns import require_sensitivities
from .reactions import driver_row


def packed_of(res: Any) -> Packed:
    """The flat tables of the result's model (packed once per result)."""
    p = getattr(res, "packed", None)
    if p is None:
        model = getattr(res, "model", None)
        if model is None:
            raise ModelError("the result carries no model (result.model is None)", "result")
        p = pack(model)
        try:
            res.packed = p
        except AttributeError:  # pragma: no cover - frozen results
            pass
    return p


def _states(res: Any) -> tuple[np.ndarray, np.ndarray]:
    if len(res.t) == 0:
        raise ModelError("the result has no rows", "result")
    return np.asfortranarray(res.q.T, dtype=np.float64), np.ascontiguousarray(res.t,
                                                                              dtype=np.float64)


# ----------------------------------------------------------------------------- dead centres
def dead_centre_distance(res: Any) -> np.ndarray:
    """sigma_min / sigma_max of the column-scaled J at every output (the core)."""
    p = packed_of(res)
    q, t = _states(res)
    out = core.conditioning(p, q, t)
    if out.status != OK:
        raise error_for("measures", out.status, out.msg, entry="dead_centre_distance")
    return np.asarray(out.cond, dtype=float).copy()


# ----------------------------------------------------------------------------- ratios
def _quantity(model: Any, p: Packed, name: Any, what: str) -> tuple[str, int]:
    """('driver', row) or ('coordinate', column) of a quantity's name (0-based)."""
    if not isinstance(name, str):
        raise ModelError(f"{what} must be a driver name or a coordinate name, got {name!r}",
                         what)
    row = driver_row(p, name)
    if row is not None:
        return "driver", row
    if name in p.coordinate_names:
        return "coordinate", p.coordinate_names.index(name)
    drivers = [c.name for c in model.constraints if c.is_driver]
    raise ModelError(f"no driver or coordinate {name!r}; drivers: {', '.join(drivers)}; "
                     f"coordinates: {', '.join(p.coordinate_names)}", what)


def _reference(model: Any, p: Packed, x: tuple[str, int], y: tuple[str, int],
               via: Any) -> int:
    """Row of the driver whose motion relates X and Y."""
    if via is not None:
        kind, row = _quantity(model, p, via, "via")
        if kind != "driver":
            raise ModelError(f"via must name a driver, got the coordinate {via!r}", "via")
        return row
    for kind, row in (x, y):
        if kind == "driver":
            return row
    drivers = [c.name for c in model.constraints if c.is_driver]
    if len(drivers) != 1:
        raise ModelError("neither quantity is a driver and the model has "
                         f"{len(drivers)} drivers ({', '.join(drivers)}): name the one that "
                         "moves them with via=", "via")
    row = driver_row(p, drivers[0])
    assert row is not None
    return row


def ratio_recipe(model: Any, p: Packed, x: Any, y: Any, via: Any = None
                 ) -> tuple[int, tuple[str, int], tuple[str, int]]:
    """The reference driver's row and the two quantities of a ratio (0-based); what
    ``mbd2d-solve`` takes for a velocity ratio or a mechanical advantage.

    Raises
    ------
    ModelError
        If a name is neither a driver nor a coordinate, or no driver relates them.
    """
    qx, qy = _quantity(model, p, x, "input"), _quantity(model, p, y, "output")
    return _reference(model, p, qx, qy, via), qx, qy


#: the core's ratio kinds and quantity kinds (fortran/mbd_measures.f90)
RATIO_KINDS = {"velocity_ratio": 1, "mechanical_advantage": 2}
QUANTITY_KINDS = {"coordinate": 1, "driver": 2}


def ratio_values(res: Any, kind: str, x: Any, y: Any, via: Any = None) -> np.ndarray:
    """The velocity ratio dY/dX or the mechanical advantage dX/dY at every output row, by
    the core (the influence coefficients of the reference driver's row).

    Raises
    ------
    ModelError
        If a name is neither a driver nor a coordinate, no driver relates them, or a
        quantity does not move with the driver at all.
    """
    p = packed_of(res)
    ref, qx, qy = ratio_recipe(res.model, p, x, y, via)
    q, t = _states(res)
    out = core.ratio(p, q, t, RATIO_KINDS[kind], ref + 1,
                     (QUANTITY_KINDS[qx[0]], qx[1] + 1), (QUANTITY_KINDS[qy[0]], qy[1] + 1))
    if out.status != OK:
        raise _ratio_failure(res.model, p, kind, ref, (x, y), int(out.status), out.msg,
                             int(out.bad))
    return np.asarray(out.ratio, dtype=float).copy()


def _ratio_failure(model: Any, p: Packed, kind: str, ref: int, names: tuple[Any, Any],
                   status: int, msg: str, bad: int) -> MbdError:
    """The error of a ratio the core could not compute: bad 1 or 2 names the quantity (X or
    Y) that does not move with the reference driver (row ref, 0-based)."""
    if bad in (1, 2):
        return ModelError(f"{names[bad - 1]!r} does not move with the driver "
                          f"'{model.constraints[p.row_owner[ref]].name}' (its influence "
                          "coefficient is zero throughout): no ratio to it", "velocity_ratio")
    return error_for("measures", status, msg, entry=kind)


def measure_failure(model: Any, p: Packed, spec: str, status: int, msg: str,
                    bad: int) -> MbdError:
    """The error the measure spec raises where the core failed to compute it (status, its
    message, and for a ratio the quantity that does not move: bad 1 X, 2 Y)."""
    name, args = parse_measure(spec)
    if name in RATIO_KINDS:
        ref, _, _ = ratio_recipe(model, p, *args)
        return _ratio_failure(model, p, name, ref, (args[0], args[1]), status, msg, bad)
    return error_for("measures", status, msg, entry=name)


# ----------------------------------------------------------------------------- transmission
def _joint(model: Any, name: Any) -> Any:
    for c in model.joints:
        if c.name == name:
            return c
    names = [c.name for c in model.joints]
    raise ModelError(f"no joint {name!r}; joints: {', '.join(names)}", "transmission_angle")


def _other_revolute(model: Any, body: str, joint: Any) -> Any:
    for c in model.joints:
        if c is not joint and isinstance(c, Revolute) and body in c.bodies:
            return c
    return None


def transmission_angle(res: Any, joint: Any, output: Any = None) -> np.ndarray:
    """The transmission angle at a revolute joint between a coupler and an output link
    (radians, one value per output row), by the core from :func:`angle_recipe`."""
    kind, bodies, points = angle_recipe(res.model, joint, output)
    q, _ = _states(res)
    out = core.link_angle(q, kind, bodies, points)
    if out.status != OK:
        raise error_for("measures", out.status, out.msg, entry="transmission_angle")
    return np.asarray(out.mu, dtype=float).copy()


def transmission_angle_dp(res: Any, joint: Any, output: Any = None) -> np.ndarray:
    """The transmission angle's exact design derivatives (rows, n_params) [rad per unit of
    each parameter] from the result's sensitivities: along the motion (dq/dp) and, where a
    parameter is a point of the angle's own recipe, along that point (the core).

    Raises
    ------
    ModelError
        If the result has no sensitivities, or as :func:`transmission_angle`.
    """
    require_sensitivities(getattr(res, "dq_dp", None) is not None, "transmission_angle")
    _angle_items(res.model, joint, output)          # the joint's own errors first
    args = [joint] if output is None else [joint, output]
    return measure_dp(res, ":".join(["transmission_angle", *args]))


def angle_recipe(model: Any, joint: Any, output: Any = None
                 ) -> tuple[int, np.ndarray, np.ndarray]:
    """Where the transmission angle at ``joint`` is measured (see the module banner): kind
    1 (the output turns about a second revolute joint) or 2 (it slides), the bodies (3,)
    (1-based, 0 ground) and points (2, 3) in them: the joint B on the output link, the
    coupler's other joint A, and the output's other pivot P (kind 1) or its slide's axis
    (kind 2, in the body that carries the axis). ``mbd2d-solve`` takes the same recipe.

    Raises
    ------
    ModelError
        If the joint is not a revolute joint between two moving bodies, ``output`` is not
        one of its bodies, the coupler has no second revolute joint, or the output link
        neither turns about a second revolute joint nor slides in a translational joint.
    """
    kind, items = _angle_items(model, joint, output)
    return kind, *_recipe([(b, pt) for b, pt, _ in items])


def _angle_items(model: Any, joint: Any, output: Any = None
                 ) -> tuple[int, list[tuple[int, Any, str]]]:
    """angle_recipe's kind and its three (body, point, parameter name prefix of the point:
    NAME.0 is its x, NAME.1 its y)."""
    index = {b.name: k + 1 for k, b in enumerate(model.bodies)}
    index[GROUND] = 0
    j = _joint(model, joint)
    entry = "transmission_angle"
    if not isinstance(j, Revolute):
        raise ModelError(f"joint {joint!r} is a {j.type} joint; the transmission angle is "
                         "taken at the revolute joint between the coupler and the output link",
                         entry)
    out = j.bodies[1] if output is None else output
    if out not in j.bodies or out == GROUND:
        raise ModelError(f"output must be one of the moving bodies of joint {joint!r} "
                         f"({', '.join(b for b in j.bodies if b != GROUND)}), got {out!r}",
                         entry)
    cpl = j.bodies[1 - j.bodies.index(out)]
    if cpl == GROUND:
        raise ModelError(f"joint {joint!r} joins {out!r} to ground: there is no coupler",
                         entry)
    ja = _other_revolute(model, cpl, j)
    if ja is None:
        raise ModelError(f"the coupler {cpl!r} has no second revolute joint: its force line "
                         "runs between its two joints", entry)
    kb, ka = j.bodies.index(out), ja.bodies.index(cpl)
    first = [(index[out], j.points[kb], f"joint.{j.name}.points.{kb}"),
             (index[cpl], ja.points[ka], f"joint.{ja.name}.points.{ka}")]
    jp = _other_revolute(model, out, j)
    if jp is not None:
        pb = 1 - jp.bodies.index(out)
        return 1, first + [(index[jp.bodies[pb]], jp.points[pb],
                            f"joint.{jp.name}.points.{pb}")]
    for c in model.joints:
        if isinstance(c, (Translational, PointOnLine)) and out in c.bodies:
            if isinstance(c, PointOnLine):
                axis, owner, name = c.axis, c.bodies[0], f"joint.{c.name}.axis"
            else:
                k = c.bodies.index(out)
                axis, owner, name = c.axes[k], c.bodies[k], f"joint.{c.name}.axes.{k}"
            return 2, first + [(index[owner], axis, name)]
    raise ModelError(f"the output link {out!r} neither turns about a second revolute joint "
                     "nor slides in a translational joint", entry)


def _angle_refs(model: Any, p: Packed, items: list[tuple[int, Any, str]]) -> np.ndarray:
    """The raw-parameter entries (2, 3; 1-based) of the x and y of an angle's three points
    (_angle_items)."""
    params = find(model, [f"{n}.{i}" for _, _, n in items for i in (0, 1)], "measures")
    return parameter_table(p, params)[1].reshape(3, 2).T


def _recipe(items: list[tuple[int, Any]]) -> tuple[np.ndarray, np.ndarray]:
    bodies = np.array([b for b, _ in items], dtype=np.int32)
    points = np.asfortranarray(np.array([[float(v) for v in s] for _, s in items]).T)
    return bodies, points


# ----------------------------------------------------------------------------- by name
#: the measures a table takes by name, with their argument counts (least, most)
MEASURES = {"transmission_angle": (1, 2), "velocity_ratio": (2, 3),
            "mechanical_advantage": (2, 3), "dead_centre_distance": (0, 0)}
FORMS = ("transmission_angle:JOINT[:OUTPUT], velocity_ratio:INPUT:OUTPUT[:VIA], "
         "mechanical_advantage:INPUT:OUTPUT[:VIA] or dead_centre_distance")


def parse_measure(spec: Any) -> tuple[str, list[str]]:
    """A measure's name and arguments from its spec "NAME:ARG:...".

    Raises
    ------
    ModelError
        For an unknown measure or a wrong number of arguments.
    """
    if not isinstance(spec, str):
        raise ModelError(f"a measure is a text {FORMS}, got {spec!r}", "measures")
    name, *args = spec.split(":")
    if name not in MEASURES or not MEASURES[name][0] <= len(args) <= MEASURES[name][1] \
            or not all(args):
        raise ModelError(f"unknown measure {spec!r}; write {FORMS}", "measures")
    return name, args


def measure(res: Any, spec: str) -> np.ndarray:
    """The values of the measure spec (see :func:`parse_measure`) at every output row."""
    name, args = parse_measure(spec)
    if name == "transmission_angle":
        return transmission_angle(res, *args)
    if name == "dead_centre_distance":
        return dead_centre_distance(res)
    return ratio_values(res, name, *args)


def measure_list(specs: Any) -> list[Any]:
    """The measures asked for as a list: None (none), one spec, or a list of specs.

    Raises
    ------
    ModelError
        For anything else.
    """
    if specs is None:
        return []
    if isinstance(specs, str):
        return [specs]
    try:
        return list(specs)
    except TypeError:
        raise ModelError(f"measures must be a list of specs ({FORMS}), got {specs!r}",
                         "measures") from None


#: the core's measure kinds (fortran/mbd_measures.f90, MEAS_*)
MEASURE_KINDS = {"transmission_angle": 1, "velocity_ratio": 2, "mechanical_advantage": 3,
                 "dead_centre_distance": 4}


def measure_tables(model: Any, p: Packed, specs: Any, moved: bool = False) -> MeasureTables:
    """The measures asked for (see :func:`measure_list`) as the core's tables; with moved,
    the raw-parameter entries an angle's points come from (a sweep's case may set them).

    Raises
    ------
    ModelError
        For a spec the model does not have (as the measure's own function raises it).
    """
    specs = measure_list(specs)
    nm = len(specs)
    t = MeasureTables(list(specs), np.zeros(nm, dtype=np.int32),
                      np.zeros((5, nm), dtype=np.int32, order="F"),
                      np.zeros((2, 3, nm), order="F"),
                      np.zeros((2, 3, nm), dtype=np.int32, order="F"))
    for j, spec in enumerate(specs):
        name, args = parse_measure(spec)
        t.kind[j] = MEASURE_KINDS[name]
        if name == "transmission_angle":
            kind, items = _angle_items(model, *args)
            t.mint[0, j] = kind
            for k, (b, pt, _) in enumerate(items):
                t.mint[1 + k, j] = b
                t.mpts[:, k, j] = [float(v) for v in pt]
            if moved:
                t.mref[:, :, j] = _angle_refs(model, p, items)
        elif name != "dead_centre_distance":
            ref, qx, qy = ratio_recipe(model, p, *args)
            t.mint[:, j] = [ref + 1, QUANTITY_KINDS[qx[0]], qx[1] + 1, QUANTITY_KINDS[qy[0]],
                            qy[1] + 1]
    return t


def spec_of(name: str, x: Any, y: Any, via: Any = None) -> str:
    """The spec of a ratio measure from its quantities' names (each checked to be text).

    Raises
    ------
    ModelError
        If a name is not text.
    """
    for what, v in (("input", x), ("output", y), ("via", via)):
        if not isinstance(v, str) and not (what == "via" and v is None):
            raise ModelError(f"{what} must be a driver name or a coordinate name, got {v!r}",
                             what)
    return ":".join([name, x, y] + ([] if via is None else [via]))


def measure_dp(res: Any, spec: str) -> np.ndarray:
    """The exact design derivatives (rows, n_params) of the measure spec (see
    :func:`parse_measure`) from the result's sensitivities, by the core (see
    :func:`measure_derivatives`).

    Raises
    ------
    ModelError
        If the result has no sensitivities, or as :func:`measure` raises for the spec.
    """
    return measure_derivatives(res, [spec])[:, 0, :]


def measure_derivatives(res: Any, specs: Any) -> np.ndarray:
    """The exact design derivatives (rows, k, n_params) of the k measures asked for (see
    :func:`measure_list`) from the result's sensitivities dq/dp, by the core in one call
    (``api_measures``): a transmission angle along the motion and along its own points where
    a parameter is one; a velocity ratio or mechanical advantage by the quotient rule on
    the influence coefficients' derivatives (J du/dp = -(J_q dq/dp + J_p) u); the dead-centre
    distance from its singular values' (dsigma = u^T d(J D) v). Where a ratio's denominator
    or sin(mu) vanishes: +-inf.

    Raises
    ------
    ModelError
        If the result has no sensitivities, or as :func:`measure` raises for a spec.
    """
    return measures_and_derivatives(res, specs)[1]


def measures_and_derivatives(res: Any, specs: Any) -> tuple[np.ndarray, np.ndarray]:
    """The measures asked for (rows, k) and their exact design derivatives (rows, k,
    n_params) in one core call (see :func:`measure_derivatives`).

    Raises
    ------
    ModelError
        If the result has no sensitivities, or as :func:`measure` raises for a spec.
    """
    require_sensitivities(getattr(res, "dq_dp", None) is not None, "measures")
    p = packed_of(res)
    tables = measure_tables(res.model, p, specs, moved=True)
    q, t = _states(res)
    if not tables.specs:
        return np.zeros((len(t), 0)), np.zeros((len(t), 0, res.dq_dp.shape[2]))
    sq = np.transpose(res.dq_dp, (1, 2, 0))
    out = core.measures_dp(p, q, sq, t, tables, res.ptab)
    if out.status != OK:
        raise measure_failure(res.model, p, tables.specs[max(int(out.bad[0]), 1) - 1],
                              int(out.status), out.msg, int(out.bad[1]))
    return (np.asarray(out.vals, dtype=float).T.copy(),
            np.transpose(np.asarray(out.dvals, dtype=float), (2, 0, 1)).copy())


def measure_derivative_columns(res: Any, specs: Any) -> tuple[list[str], np.ndarray]:
    """The measures asked for and their design derivatives (rows, k, n_params)
    (:func:`measure_derivatives`); none when the result has no sensitivities."""
    if getattr(res, "dq_dp", None) is None:
        return [], np.zeros((len(res.t), 0, 0))
    specs = measure_list(specs)
    return list(specs), measure_derivatives(res, specs)


def measure_columns(res: Any, specs: Any) -> tuple[list[str], list[np.ndarray]]:
    """The table columns of the measures asked for (see :func:`measure_list`): named by
    their specs."""
    specs = measure_list(specs)
    return specs, [measure(res, s)[:, None] for s in specs]

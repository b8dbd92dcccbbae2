"""What the front doors add for contacts, friction and cam joints: the methods that carry
stick-slip friction, the event log's size, and the report of cam joints that would have to
pull their follower (a real follower lifts off there)."""
from __future__ import annotations


import numpy as np

from ..binding import core
from ..binding.status import error_for
from ..binding.tables import Packed
from ..description.builder import ModelDescription
from ..description.joints import Cam, PointOnCurve
from ..errors import LiftOffWarning, ModelError, warn
from ..results.contacts import LiftOff, pull_intervals
from ..results.dynamics import DynamicsResult

#: events kept by a run with contacts or stick-slip joints (more are counted, not kept)
MAX_EVENTS = 100_000
#: the dynamics methods that carry stick-slip friction (its events need error control)
STICK_SLIP_METHODS = ("dopri5", "partitioned")


def stick_slip_joints(model: ModelDescription) -> list[str]:
    """Names of the joints with stick-slip friction."""
    return [j.name for j in model.joints
            if getattr(j, "friction", None) is not None and j.friction.model == "stick-slip"]


def has_events(model: ModelDescription) -> bool:
    """Contacts or stick-slip joints: the run keeps an event log."""
    return bool(model.contacts) or bool(stick_slip_joints(model))


def check_method(model: ModelDescription, method: str) -> None:
    """Stick-slip friction runs in dopri5 and partitioned only.

    Raises
    ------
    ModelError
        Naming the joints and the methods that can carry them.
    """
    joints = stick_slip_joints(model)
    if joints and method not in STICK_SLIP_METHODS:
        raise ModelError(f"stick-slip friction (joint(s) {', '.join(joints)}) runs in "
                         f"{' and '.join(STICK_SLIP_METHODS)} (its stick and slip events need "
                         f"error-controlled steps); {method} carries the regularized model: "
                         "use method='dopri5', or friction model = \"regularized\"",
                         f"model {model.name!r}")


def check_statics(model: ModelDescription) -> None:
    """Statics has no friction (the holding force of a joint at rest is indeterminate).

    Raises
    ------
    ModelError
        Naming the joints with friction.
    """
    joints = [j.name for j in model.joints if getattr(j, "friction", None) is not None]
    fric = [c.name for c in model.contacts if c.friction.mu > 0 or c.friction.mu_static > 0]
    if joints or fric:
        raise ModelError(f"statics does not carry friction ({', '.join(joints + fric)}): the "
                         "force that holds a joint or contact at rest is indeterminate; run "
                         "dynamics (stick-slip joints stick at rest), or remove the friction",
                         f"model {model.name!r}")


def report_pulls(model: ModelDescription, p: Packed, res: DynamicsResult) -> None:
    """Fill res.lift_off with the intervals where a cam joint pulls its follower onto the
    profile, and warn (LiftOffWarning) naming the joint and the first interval."""
    cams = [k for k, c in enumerate(model.constraints)
            if isinstance(c, Cam) and not isinstance(c, PointOnCurve)]
    if not cams or len(res.t) == 0:
        return
    out = core.cam_forces(p, np.asfortranarray(res.q.T), np.asarray(res.t, dtype=float),
                          np.asfortranarray(res.lam.T))
    if out.status != 0:
        raise error_for("reactions", out.status, out.msg, entry="cam joints")
    pulls: list[LiftOff] = []
    for k in cams:
        fn = out.fn[k]
        scale = float(np.max(np.abs(fn))) if fn.size else 0.0
        fn = np.where(np.abs(fn) <= 1e-9 * scale, 0.0, fn)      # round-off is no pull
        pulls += pull_intervals(res.t, fn, model.constraints[k].name)
    res.lift_off = pulls
    for name in dict.fromkeys(x.joint for x in pulls):
        mine = [x for x in pulls if x.joint == name]
        first = mine[0]
        warn(f"cam joint '{name}': the follower would need a pulling force "
             f"({len(mine)} interval(s), the first from t = {first.t_start:.6g} to "
             f"{first.t_end:.6g} s, strongest {min(x.min_force for x in mine):.4g}); "
             "a real follower lifts off there. res.lift_off lists them; a "
             "follower-profile contact in forward dynamics shows the lift-off",
             LiftOffWarning)


__all__ = ["MAX_EVENTS", "STICK_SLIP_METHODS", "stick_slip_joints", "has_events",
           "check_method", "check_statics", "report_pulls"]

"""Contact and friction results: the event list (onsets, separations, stick and slip) and the
time histories of each contact's force, penetration and sliding speed, and of each joint's
friction.

The core writes six numbers per force element and output (``fortran/mbd_dynamics.f90``,
dyn_element_outputs): a contact [normal force, friction force, penetration (negative: the
gap), sliding speed, contact point x, y]; a joint's friction [normal load, friction force
along the slip, 0, slip speed, 1 when stuck, friction moment (revolute)].
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: kinds of the core's event records (mbd_events)
EVENT_KINDS = {1: "onset", 2: "separation", 3: "stick", 4: "slip", 5: "reversal"}


@dataclass(frozen=True)
class ContactEvent:
    """A contact closing (``onset``) or opening (``separation``) at time t; ``speed`` is the
    rate of penetration there (the impact speed), or of separation."""

    t: float
    contact: str
    kind: str
    speed: float


@dataclass(frozen=True)
class FrictionEvent:
    """A joint starting to stick (``stick``), to slip (``slip``) or sliding back
    (``reversal``) at time t; ``force`` is the friction force then (the lock force that
    held it, for a slip)."""

    t: float
    joint: str
    kind: str
    force: float


@dataclass(frozen=True)
class LiftOff:
    """An interval where a cam joint must pull its follower onto the profile (a real
    follower would lift off): from t_start to t_end, the strongest pull ``min_force`` (< 0)."""

    joint: str
    t_start: float
    t_end: float
    min_force: float


@dataclass
class ContactHistory:
    """A contact over the output times: normal and friction force, penetration (negative: the
    gap), sliding speed at the contact point, and the contact point (n, 2) (where it
    touches; zero while open)."""

    name: str
    normal_force: np.ndarray
    friction_force: np.ndarray
    penetration: np.ndarray
    sliding_speed: np.ndarray
    point: np.ndarray


@dataclass
class FrictionHistory:
    """A joint's friction over the output times: the normal load (|normal reaction|, or the
    pin force for a revolute), the friction force along the slip, the friction moment of a
    revolute (force x pin radius), the slip speed, and whether it sticks."""

    name: str
    normal_load: np.ndarray
    friction_force: np.ndarray
    moment: np.ndarray
    sliding_speed: np.ndarray
    stuck: np.ndarray


def element_arrays(eo: np.ndarray, n: int) -> np.ndarray:
    """The core's (6, nf, rows) outputs as (n, nf, 6)."""
    return np.ascontiguousarray(np.transpose(eo, (2, 1, 0))[:n])


def events_from(evo: np.ndarray, nev: int, names: list[tuple[str, str]]
                ) -> tuple[list[ContactEvent], list[FrictionEvent]]:
    """Contact and friction events from the core's records [t, element, kind, value]."""
    contacts: list[ContactEvent] = []
    friction: list[FrictionEvent] = []
    for r in range(min(int(nev), evo.shape[1])):
        t, k, kind, val = evo[:, r]
        k = int(k) - 1
        if not 0 <= k < len(names):
            continue
        name, what = names[k]
        label = EVENT_KINDS.get(int(kind), "unknown")
        if what == "contact":
            contacts.append(ContactEvent(float(t), name, label, float(val)))
        else:
            friction.append(FrictionEvent(float(t), name, label, float(val)))
    return contacts, friction


def history(elements: np.ndarray, names: list[tuple[str, str]], name: str,
            what: str) -> Any:
    """The ContactHistory (what = 'contact') or FrictionHistory ('friction') of an element.

    Raises
    ------
    KeyError
        If there is no such element.
    """
    keys = [n for n, w in names if w == what]
    if name not in keys:
        known = ", ".join(keys) or "(none)"
        kind = "contact" if what == "contact" else "joint with friction"
        raise KeyError(f"no {kind} {name!r}; known: {known}")
    k = names.index((name, what))
    e = elements[:, k, :]
    if what == "contact":
        return ContactHistory(name, e[:, 0], e[:, 1], e[:, 2], e[:, 3], e[:, 4:6])
    return FrictionHistory(name, e[:, 0], e[:, 1], e[:, 5], e[:, 3], e[:, 4] > 0.5)


def pull_intervals(t: np.ndarray, fn: np.ndarray, joint: str) -> list[LiftOff]:
    """The intervals where a cam joint's normal force fn is negative (ends at the output
    times, by linear interpolation of the zero crossings)."""
    out: list[LiftOff] = []
    neg = fn < 0.0
    k = 0
    while k < len(t):
        if not neg[k]:
            k += 1
            continue
        j = k
        while j + 1 < len(t) and neg[j + 1]:
            j += 1
        ts = t[k] if k == 0 else t[k - 1] + (t[k] - t[k - 1]) * fn[k - 1] / (fn[k - 1] - fn[k])
        te = t[j] if j == len(t) - 1 else \
            t[j] + (t[j + 1] - t[j]) * fn[j] / (fn[j] - fn[j + 1])
        out.append(LiftOff(joint, float(ts), float(te), float(fn[k:j + 1].min())))
        k = j + 1
    return out


__all__ = ["ContactEvent", "FrictionEvent", "LiftOff", "ContactHistory", "FrictionHistory",
           "EVENT_KINDS", "element_arrays", "events_from", "history", "pull_intervals"]

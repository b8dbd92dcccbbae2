"""Layer 5, the results: arrays by time with per-body views, multipliers, energies, reactions
and efforts, the degree-of-freedom report, and result files (CSV, NPZ).

Results hold data and answer questions about it; pictures of a result are drawn by
:mod:`mbd2d.plots` (a lower layer), reactions are computed from the multipliers through
:mod:`mbd2d.binding`. Nothing here runs an analysis.
"""
from __future__ import annotations

from .contacts import ContactEvent, ContactHistory, FrictionEvent, FrictionHistory, LiftOff
from .dof import DofReport
from .dynamics import DynamicsResult
from .files import read_csv
from .columns import SUFFIXES
from .kinematics import BodyResult, KinematicsResult
from .frf import FrequencyResponseResult
from .linear import LinearizedSystem
from .modes import ModesResult
from .points import PointResult
from .reactions import Reaction
from .statics import StaticsResult

__all__ = ["BodyResult", "KinematicsResult", "DynamicsResult", "StaticsResult", "ModesResult",
           "FrequencyResponseResult", "LinearizedSystem",
           "Reaction",
           "DofReport", "PointResult", "SUFFIXES", "read_csv", "ContactEvent", "FrictionEvent",
           "LiftOff", "ContactHistory", "FrictionHistory"]

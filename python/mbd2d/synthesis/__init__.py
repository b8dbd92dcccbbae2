"""Linkage synthesis (layer 8, above the Model): fit a mechanism's named parameters to a task
with exact kinematics and exact gradients, defect-free by construction.

    synthesize(model, free=[names], task=..., bounds={name: (lo, hi)}, constraints=[...],
               starts=K, client=None) -> SynthesisResult

Tasks: :class:`PathTask` (path generation, prescribed, shifted or free timing),
:class:`FunctionTask`, :class:`MotionTask`. Constraints: :class:`Grashof`,
:class:`LinkRatio`, :class:`TransmissionAngle`, :class:`PeakEffort`, :class:`MeasureBound`.
:func:`fourbar` builds
the four-bar of path generation from link lengths; :func:`load_task` reads a task file.
:func:`cam_profile` synthesizes a disc cam from a follower program (motion laws). See
docs/synthesis.md.
"""
from __future__ import annotations

from .cam import CamDesign, cam_profile, cam_report, load_cam
from .fourbar import FOURBAR_PARAMETERS, fourbar, fourbar_parameters, loop_configuration
from .problem import Evaluation, Problem
from .search import StartRecord, SynthesisResult, latin_hypercube, run_all, synthesize
from .taskfile import TaskFile, load_task
from .tasks import FunctionTask, MotionTask, PathTask, Task, make_task
from .terms import Grashof, LinkRatio, MeasureBound, PeakEffort, TransmissionAngle, make_term

__all__ = ["synthesize", "SynthesisResult", "StartRecord", "Problem", "Evaluation", "Task",
           "PathTask", "MotionTask", "FunctionTask", "make_task", "Grashof", "LinkRatio",
           "TransmissionAngle", "PeakEffort", "MeasureBound", "make_term", "fourbar",
           "fourbar_parameters",
           "loop_configuration", "FOURBAR_PARAMETERS", "run_all", "latin_hypercube",
           "load_task", "TaskFile", "cam_profile", "CamDesign", "load_cam", "cam_report"]

"""Layer 2, the model description: what a model is made of, checked as it is built.

Bodies, joints, drivers, forces and functions of time, the builder
(:class:`~mbd2d.description.builder.ModelDescription`) and the TOML format. Nothing here runs
an analysis or calls the core; :class:`mbd2d.Model` adds the analyses on top.
"""
from __future__ import annotations

from .bodies import Body
from .builder import ModelDescription
from .functions import Harmonic, Step, TimeFunction
from .joints import joint_keys

__all__ = ["Body", "ModelDescription", "Harmonic", "Step", "TimeFunction", "joint_keys"]

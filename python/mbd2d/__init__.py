"""mbd2d: planar multibody kinematics with a Fortran core.

Examples
--------
>>> import mbd2d
>>> model = mbd2d.load("examples/fourbar_grashof.toml")
>>> res = model.kinematics(t_end=1.0, steps=100)
>>> res.body("coupler").theta.shape
(101,)
"""
from __future__ import annotations

from .analysis.stepping import KinematicStepper
from .description.functions import Harmonic, Step, Table, TimeFunction
from .errors import (AnalysisError, AssemblyError, ConvergenceError, CoreError,
                     InconsistentConstraintsError, InsufficientMemoryError, IntegrationError,
                     LiftOffWarning, MbdError, MbdWarning, ModelError, RedundantConstraintWarning,
                     SingularConfigurationError, SingularJacobianError, SingularPassageWarning,
                     StiffnessWarning, ToggleError)
from .model import Model, load, loads
from .plots import animate, plot_mechanism, plot_paths, plot_sweep, plot_timeseries
from .results import (BodyResult, DofReport, DynamicsResult, FrequencyResponseResult,
                      KinematicsResult, LinearizedSystem, ModesResult, PointResult, Reaction,
                      StaticsResult)
from .studies import (ToleranceResult, export_sweep, grid, sweep, tolerance,
                      tolerance_samples, write_sweep)
from .synthesis import CamDesign, SynthesisResult, cam_profile, synthesize

__version__ = "0.1.0"

__all__ = ["load", "loads", "Model", "TimeFunction", "Harmonic", "Step", "Table",
           "KinematicsResult", "BodyResult", "PointResult", "DynamicsResult", "KinematicStepper",
           "StaticsResult", "ModesResult", "FrequencyResponseResult", "LinearizedSystem",
           "Reaction",
           "DofReport", "MbdError", "ModelError", "AnalysisError", "IntegrationError",
           "AssemblyError", "InconsistentConstraintsError", "ConvergenceError",
           "SingularJacobianError", "SingularConfigurationError", "ToggleError", "CoreError",
           "InsufficientMemoryError", "MbdWarning", "RedundantConstraintWarning",
           "SingularPassageWarning", "StiffnessWarning", "LiftOffWarning", "plot_mechanism",
           "plot_paths",
           "plot_timeseries", "plot_sweep", "animate", "sweep", "grid", "tolerance", "ToleranceResult",
           "write_sweep", "export_sweep", "tolerance_samples", "synthesize", "SynthesisResult",
           "cam_profile", "CamDesign", "__version__"]

"""Typed exceptions of mbd2d.

Every failure the engine knows of maps to one class here. Input mistakes raise
:class:`ModelError` (a :class:`ValueError`); numerical failures raise a subclass of
:class:`AnalysisError`, which carries the results computed before the failure.
"""
from __future__ import annotations

from typing import Any


class MbdError(Exception):
    """Base class of every mbd2d error."""


class ModelError(MbdError, ValueError):
    """The model or the call is malformed; the message names the entry and what to do.

    Parameters
    ----------
    message : str
        What is wrong and how to fix it.
    entry : str, optional
        The offending entry, such as ``"joint 'O2'"``.
    """

    def __init__(self, message: str, entry: str | None = None) -> None:
        self.entry = entry
        super().__init__(f"{entry}: {message}" if entry else message)


class AnalysisError(MbdError):
    """A numerical failure during an analysis.

    Attributes
    ----------
    t : float or None
        Time of the failure.
    results : KinematicsResult or None
        The rows computed before the failure (possibly only t0, or none). (Typed ``Any``
        here: errors are the lowest layer and know no result class.)
    status : int
        The core's status code.
    """

    def __init__(self, message: str, *, t: float | None = None,
                 results: Any = None, status: int = 0,
                 **details: Any) -> None:
        super().__init__(message)
        self.t = t
        self.results = results
        self.status = status
        for key, value in details.items():
            setattr(self, key, value)


class AssemblyError(AnalysisError):
    """No configuration satisfies the constraints near the given estimates ``q0``."""


class InconsistentConstraintsError(AssemblyError):
    """Redundant constraints contradict each other: no configuration satisfies them all.

    Attributes
    ----------
    constraints : list of str
        The constraints that disagree.
    residual : float
        The smallest residual ||Phi||_inf reached.
    """


class ConvergenceError(AnalysisError):
    """Newton-Raphson did not converge at a regular configuration."""


class SingularJacobianError(AnalysisError):
    """The constraint Jacobian is singular where a solve needed it (e.g. assembled at a
    dead centre)."""


class SingularConfigurationError(AnalysisError):
    """The mechanism reached a singular (dead-centre, toggle) configuration.

    Attributes
    ----------
    t : float
        Located time of the singular configuration (to about 1e-10 s).
    driver : str or None
        Name of the driver that can no longer be met, if one.
    dependent : list of str
        Names of the constraints whose rows became dependent.
    q : numpy.ndarray
        The configuration there.
    sigma_min, sigma_max : float
        Extreme singular values of J there.
    results : KinematicsResult
        Every output row up to the singular time.
    """


#: Another name for the dead-centre error, as mechanism engineers say it.
ToggleError = SingularConfigurationError


class IntegrationError(AnalysisError):
    """A dynamics integrator failed: step-size underflow, blow-up, or a Newton iteration that
    did not converge at a fixed step. Carries the results up to the failure."""


class MbdWarning(UserWarning):
    """Base class of mbd2d warnings."""


class RedundantConstraintWarning(MbdWarning):
    """Some constraint equations repeat what the others impose; they are solved in least
    squares (exactly, when consistent), and reactions are statically indeterminate."""


class SingularPassageWarning(MbdWarning):
    """The run passed through singular configurations (bifurcation points) and stayed on the
    branch it started on; in dynamics (partitioned), a step ended so close to one that the
    accelerations there, and the motion after it, may be inaccurate."""


class StiffnessWarning(MbdWarning):
    """dopri5's (or partitioned's) steps were limited by stability, not accuracy: the model is
    stiff (a stiff spring, damper or contact whose fast motion has died out), and an explicit
    method needs a step below 3.3 / |lambda| however smooth the motion. The implicit
    generalized-alpha method takes steps set by the motion's accuracy."""


class LiftOffWarning(MbdWarning):
    """A cam joint must pull its follower onto the profile somewhere in the run: a real
    follower would lift off there (``res.lift_off`` lists the intervals)."""


def warn(message: str, category: type[Warning]) -> None:
    """warnings.warn attributed to the line that called into mbd2d (the first frame outside
    the package), however deep in it the warning arises."""
    import os
    import sys
    import warnings

    here = os.path.dirname(os.path.abspath(__file__)) + os.sep
    level, frame = 2, sys._getframe(1)
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(here):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)


class CoreError(MbdError):
    """The Fortran core reported an internal error (a LAPACK argument error, or a status the
    analysis cannot produce); a bug."""


class InsufficientMemoryError(MbdError, MemoryError):
    """An analysis needs more memory than it can get (the core's status 10): refused before
    the run from an estimate, refused by the core before allocating a request above half the
    physical memory (or above what is free), or an allocation that failed. The message says
    how much was asked and what to change: fewer steps, ``every=k`` to keep fewer output rows,
    ``solver="banded"`` for large models. The process and its earlier results are unharmed.

    Attributes
    ----------
    nbytes : float or None
        The size asked for, in bytes, when known.
    """

    def __init__(self, message: str, nbytes: float | None = None) -> None:
        super().__init__(message)
        self.nbytes = nbytes


__all__ = ["MbdError", "ModelError", "AnalysisError", "AssemblyError",
           "InconsistentConstraintsError", "ConvergenceError", "SingularJacobianError",
           "IntegrationError",
           "SingularConfigurationError", "ToggleError", "CoreError", "InsufficientMemoryError",
           "MbdWarning",
           "RedundantConstraintWarning", "SingularPassageWarning", "StiffnessWarning",
           "LiftOffWarning"]

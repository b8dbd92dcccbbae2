"""Status codes of the Fortran core (``fortran/mbd_status.f90``): 0 ok, < 0 bad input,
> 0 numerical failure at a valid input; and THE table that maps each status of each analysis
to its exception class.

Every front door takes the class of a failure from :data:`ERRORS` (through
:func:`error_for`); it writes the message (the time, the entries, what to do). A status an
analysis cannot produce, or one the table does not know, is a :class:`CoreError` (a bug).
"""
from __future__ import annotations

from typing import Any

from ..errors import (AnalysisError, AssemblyError, ConvergenceError, CoreError,
                      InconsistentConstraintsError, InsufficientMemoryError, IntegrationError,
                      MbdError, ModelError, SingularConfigurationError, SingularJacobianError)

OK = 0
# bad input (< 0)
BAD_INPUT = -1          # malformed table (sizes, kinds)
BAD_BODY = -2           # body index out of range, self-joint
BAD_PARAM = -3          # non-finite or degenerate parameter
BAD_COUNT = -4          # equations and coordinates do not match
BAD_SETTING = -5        # analysis settings (steps, tolerance, ...)
# numerical failure (> 0)
SINGULAR = 1            # singular Jacobian where one was needed
NO_CONVERGENCE = 2      # Newton did not converge
SINGULAR_CONFIG = 3     # dead centre / toggle reached, located
ASSEMBLY_FAILED = 4     # no configuration satisfies Phi(q, t0) = 0
LAPACK = 5              # LAPACK reported an illegal argument
INCONSISTENT = 6        # redundant constraints that contradict
BRANCH_SWITCH = 7       # solution left its assembly branch
INTEGRATOR_FAILED = 8   # step size underflow, blow-up
USER_ABORT = 9          # a user callback asked to stop
NO_MEMORY = 10          # an allocation failed or would not fit (mbd_memory.f90)

#: Every status the core defines, by name.
STATUS_NAMES = {
    BAD_INPUT: "MBD_BAD_INPUT", BAD_BODY: "MBD_BAD_BODY", BAD_PARAM: "MBD_BAD_PARAM",
    BAD_COUNT: "MBD_BAD_COUNT", BAD_SETTING: "MBD_BAD_SETTING", SINGULAR: "MBD_SINGULAR",
    NO_CONVERGENCE: "MBD_NO_CONVERGENCE", SINGULAR_CONFIG: "MBD_SINGULAR_CONFIG",
    ASSEMBLY_FAILED: "MBD_ASSEMBLY_FAILED", LAPACK: "MBD_LAPACK",
    INCONSISTENT: "MBD_INCONSISTENT", BRANCH_SWITCH: "MBD_BRANCH_SWITCH",
    INTEGRATOR_FAILED: "MBD_INTEGRATOR_FAILED", USER_ABORT: "MBD_USER_ABORT",
    NO_MEMORY: "MBD_NO_MEMORY",
}

Table = dict[int, type[MbdError]]

# what every analysis shares: bad input is the user's to fix; LAPACK argument errors, a
# branch switch and a user abort are never produced by these calls (a bug if they appear)
_COMMON: Table = {BAD_INPUT: ModelError, BAD_BODY: ModelError, BAD_PARAM: ModelError,
                  BAD_COUNT: ModelError, BAD_SETTING: ModelError, LAPACK: CoreError,
                  BRANCH_SWITCH: CoreError, USER_ABORT: CoreError,
                  NO_MEMORY: InsufficientMemoryError}
# a run that assembles at t0, then follows the drivers (kinematics, inverse dynamics)
_KINEMATIC: Table = {**_COMMON, SINGULAR: SingularJacobianError,
                     NO_CONVERGENCE: ConvergenceError,
                     SINGULAR_CONFIG: SingularConfigurationError,
                     ASSEMBLY_FAILED: AssemblyError, INCONSISTENT: InconsistentConstraintsError,
                     INTEGRATOR_FAILED: CoreError}
# an answer at one configuration, found by assembly (DOF analysis, stepper start)
_ASSEMBLY: Table = {**_COMMON, SINGULAR: SingularJacobianError, NO_CONVERGENCE: AssemblyError,
                    SINGULAR_CONFIG: SingularJacobianError, ASSEMBLY_FAILED: AssemblyError,
                    INCONSISTENT: InconsistentConstraintsError, INTEGRATOR_FAILED: CoreError}
# only input checks (evaluation at a state, table sizes, reactions, profile points)
_INPUT_ONLY: Table = {**_COMMON, **{s: CoreError for s in (
    SINGULAR, NO_CONVERGENCE, SINGULAR_CONFIG, ASSEMBLY_FAILED, INCONSISTENT,
    INTEGRATOR_FAILED)}}

#: THE table: analysis -> core status -> exception class.
ERRORS: dict[str, Table] = {
    "kinematics": _KINEMATIC,
    "inverse": _KINEMATIC,
    "dynamics": {**_KINEMATIC, SINGULAR_CONFIG: SingularJacobianError,
                 INTEGRATOR_FAILED: IntegrationError},
    "statics": {**_ASSEMBLY, NO_CONVERGENCE: ConvergenceError},
    # statics, then the eigenvalues of the linearized motion about the equilibrium
    "modes": {**_ASSEMBLY, NO_CONVERGENCE: ConvergenceError},
    # statics, then the linearized motion's response to harmonic inputs (SINGULAR: an
    # undamped resonance on a frequency asked for)
    "frf": {**_ASSEMBLY, NO_CONVERGENCE: ConvergenceError},
    # statics, then the linearized motion as a state-space system (SINGULAR: a massless
    # free motion)
    "linearize": {**_ASSEMBLY, NO_CONVERGENCE: ConvergenceError},
    # the stepper has no step control: a singular J or a failed Newton step both end in
    # ConvergenceError (Model.kinematics locates dead centres)
    "stepper": {**_KINEMATIC, SINGULAR: ConvergenceError,
                SINGULAR_CONFIG: ConvergenceError},
    "stepper-start": _ASSEMBLY,
    "dof": _ASSEMBLY,
    "eval": _INPUT_ONLY,
    "sizes": _INPUT_ONLY,
    "reactions": _INPUT_ONLY,
    "profile": _INPUT_ONLY,
    # mechanism measures at the states of a run (conditioning, influence coefficients)
    "measures": _INPUT_ONLY,
}

#: What to change when memory runs out, for messages.
MEMORY_ADVICE = ("use fewer steps, keep fewer output rows with every=k, or for a large model "
                 "solver=\"banded\" (no dense n x n matrix)")


def error_class(analysis: str, status: int) -> type[MbdError]:
    """The exception class of a core status in an analysis (CoreError when the analysis
    cannot produce it)."""
    return ERRORS[analysis].get(int(status), CoreError)


def error_for(analysis: str, status: int, text: str, *, entry: str | None = None,
              t: float | None = None, results: Any = None, nbytes: float | None = None,
              **details: Any) -> MbdError:
    """The exception of a core status in an analysis, with the caller's message.

    Parameters
    ----------
    analysis : str
        A key of :data:`ERRORS`.
    status : int
        The core's status (not OK).
    text : str
        What happened and what to do; for a CoreError the status name and "a bug" are
        added, for an InsufficientMemoryError the advice on what to change.
    entry : str, optional
        The entry a ModelError names.
    t, results, details
        Carried by an AnalysisError (``err.t``, ``err.results``, ...).
    nbytes : float, optional
        The size an InsufficientMemoryError asked for.
    """
    cls = error_class(analysis, status)
    if issubclass(cls, ModelError):
        return cls(text, entry)
    if issubclass(cls, AnalysisError):
        return cls(text, t=t, results=results, status=int(status), **details)
    if issubclass(cls, InsufficientMemoryError):
        return cls(f"not enough memory in {analysis}: {text}; {MEMORY_ADVICE}", nbytes)
    name = STATUS_NAMES.get(int(status), "an unknown status")
    return cls(f"internal error in the core ({analysis}: status {int(status)}, {name}): {text}"
               " -- a bug; please report it with the model")

"""Status codes of the Fortran core (``fortran/mbd_status.f90``): 0 ok, < 0 bad input,
> 0 numerical failure at a valid input."""
from __future__ import annotations

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

"""Kinematics one step per call, for time loops that live in Python (co-simulation, custom
drivers, interactive tools). Each :meth:`KinematicStepper.step` is one call into the core."""
from __future__ import annotations

import numpy as np

from ..binding import core
from ..binding.pack import pack
from ..binding.status import NO_CONVERGENCE, error_for
from ..description.builder import ModelDescription
from ..errors import ModelError
from ..validate import number
from .settings import check_solver, require_determined


class KinematicStepper:
    """Position, velocity and acceleration analysis driven one output time at a time.

    Each step predicts q from the last state (q + h q_dot + h^2/2 q_ddot), runs Newton-Raphson
    on Phi(q, t) = 0 and solves J q_dot = nu, J q_ddot = gamma, all in one core call. There
    is no step control: a singular configuration or a failed Newton iteration raises
    :class:`~mbd2d.ConvergenceError`. :meth:`Model.kinematics` (the whole loop in the core)
    is faster and locates dead centres; use it unless the loop must be in Python.

    Parameters
    ----------
    model : Model
        A kinematically determined model with as many equations as coordinates.
    t0 : float
        Start time; the q0 estimates are assembled there.
    tol : float, optional
        Newton tolerance relative to the model's length scale (default 1e-12).

    Attributes
    ----------
    t : float
        Time of the current state.
    q, qd, qdd : numpy.ndarray
        Coordinates, velocities and accelerations at ``t``.

    Examples
    --------
    >>> import mbd2d
    >>> s = mbd2d.KinematicStepper(mbd2d.load("examples/fourbar_grashof.toml"))
    >>> q, qd, qdd = s.step(0.01)
    >>> q.shape
    (9,)
    """

    def __init__(self, model: ModelDescription, t0: float = 0.0, tol: float | None = None) -> None:
        if not isinstance(model, ModelDescription):
            raise ModelError(f"KinematicStepper needs a Model, got {type(model).__name__}",
                             "stepping")
        self._p = pack(model)
        require_determined(self._p, model)
        if self._p.neq != self._p.nq:
            raise ModelError("stepping needs as many equations as coordinates (no redundant "
                             "constraints); use Model.kinematics", "stepping")
        self._tol, _ = check_solver(tol, None)
        self.t = number(t0, "t0", "stepping")
        self.q = self._p.q0.copy()
        self.qd = np.zeros_like(self.q)
        self.qdd = np.zeros_like(self.q)
        self._call(self.t, assemble=True)

    def _call(self, t: float, assemble: bool) -> None:
        """One core call from the current state to t; the state changes only on success
        (the core works on copies)."""
        p = self._p
        analysis = "stepper-start" if assemble else "stepper"
        out = core.kin_step(p, self.q.copy(), self.qd.copy(), self.qdd.copy(), self.t, t,
                            self._tol, 0, assemble)
        status = out.status
        stays = (f"the state stays at t = {self.t:.9g} s (Model.kinematics locates singular "
                 "configurations)")
        if status < 0:
            raise error_for(analysis, status, out.msg, entry="stepping")
        if status > 0:
            raise error_for(analysis, status, f"{out.msg}; {stays}", t=t)
        if not (np.isfinite(out.q).all() and np.isfinite(out.qd).all()
                and np.isfinite(out.qdd).all()):
            raise error_for(analysis, NO_CONVERGENCE,
                            f"the step to t = {t:.9g} s gave non-finite coordinates, velocities "
                            f"or accelerations (a step far too long for Newton-Raphson); {stays}",
                            t=t)
        self.q, self.qd, self.qdd, self.t = out.q, out.qd, out.qdd, t

    def step(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance to time t (one core call).

        Parameters
        ----------
        t : float
            The new time (any direction; small steps keep Newton on its branch).

        Returns
        -------
        tuple of numpy.ndarray
            q, q_dot, q_ddot at t (finite).

        Raises
        ------
        ModelError
            If t is not a finite number.
        ConvergenceError
            If Newton-Raphson fails, J is singular, or the step gives non-finite values;
            the state stays where it was.
        """
        self._call(number(t, "t", "stepping"), assemble=False)
        return self.q, self.qd, self.qdd

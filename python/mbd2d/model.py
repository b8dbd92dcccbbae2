"""Layer 7, the model users get: the description (:mod:`mbd2d.description`) plus every
analysis as a method, and the TOML readers that build it.

Examples
--------
>>> import mbd2d
>>> model = mbd2d.load("examples/fourbar_grashof.toml")
>>> model.kinematics(t_end=1.0, steps=10).q.shape[0]
11
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from . import plots
from .analysis.dof import analyze_dof
from .analysis.dynamics import run_dynamics
from .analysis.evaluate import evaluate
from .analysis.inverse import run_inverse
from .analysis.kinematics import run_kinematics
from .analysis.frf import run_frf
from .analysis.linearize import run_linearize
from .analysis.modes import run_modes
from .analysis.mbdfile import export as export_mbd
from .analysis.statics import run_statics
from .binding.pack import pack
from .binding.params import open_values
from .description import toml_io
from .description.builder import ModelDescription
from .description.entries import reads_entries
from .errors import MbdError
from .description.parameters import parameter_list
from .results import (DofReport, DynamicsResult, FrequencyResponseResult, KinematicsResult,
                      LinearizedSystem, ModesResult, StaticsResult)
from .validate import flag


class Model(ModelDescription):
    """A planar multibody model: its description (bodies, joints, drivers, forces, built with
    the ``add_*`` methods or read from TOML) and every analysis of it.

    Parameters
    ----------
    name : str
        Model name (used in plots and exported files).
    gravity : sequence of float
        Gravity vector (dynamics only).

    Examples
    --------
    >>> m = Model("pendulum")
    >>> _ = m.add_body("bar", q0=[0.5, 0.0, 0.0])
    >>> _ = m.add_revolute(["ground", "bar"], [[0, 0], [-0.5, 0]])
    >>> _ = m.add_driver("absolute", body="bar", coordinate="theta", f={"poly": [0.0, 1.0]})
    >>> m.counts()
    (3, 3)
    """

    # ------------------------------------------------------------------ sizes
    def counts(self) -> tuple[int, int]:
        """(number of equations, number of coordinates), after the core has checked the
        model."""
        p = pack(self)
        return p.neq, p.nq

    @reads_entries
    def parameters(self) -> dict[str, float | None]:
        """Every design parameter by name, with its value (see
        :meth:`~mbd2d.description.builder.ModelDescription.parameters`); a gear or rolling
        phase left open gets the value the core takes from the q0 estimates.

        Examples
        --------
        >>> import mbd2d
        >>> p = mbd2d.load("examples/fourbar_grashof.toml").parameters()
        >>> p["driver.motor.f.poly.1"], p["model.gravity.1"]
        (6.283185307179586, -9.81)
        """
        values = super().parameters()
        if any(v is None for v in values.values()):
            values.update(open_values(pack(self), parameter_list(self)))
        return values

    # ------------------------------------------------------------------ analyses
    @reads_entries
    def kinematics(self, t_end: float, steps: int, t0: float = 0.0, tol: float | None = None,
                   maxit: int | None = None, every: int = 1, solver: str = "auto",
                   sensitivities: Any = None, progress: bool | None = None,
                   positions_only: bool = False) -> KinematicsResult:
        """Kinematic analysis at steps + 1 uniform times from t0 to t_end.

        The whole time loop runs in the Fortran core. Assembly refines the q0 estimates at t0.

        Parameters
        ----------
        t_end : float
            Final time.
        steps : int
            Number of intervals; the result has steps + 1 rows.
        t0 : float
            Start time.
        tol : float, optional
            Newton tolerance on ||Phi||_inf relative to the model's length scale
            (default 1e-12).
        maxit : int, optional
            Newton iterations per step (default 25).
        every : int, optional
            Keep every k-th output row (and the last): memory stays flat on long runs. The
            step size is still (t_end - t0) / steps.
        solver : {"auto", "dense", "banded"}, optional
            Linear solver of the Newton loop: dense LU, or band LU (dgbtrf) of J after a
            reverse Cuthill-McKee ordering. "auto" picks the band for square J with at least
            60 coordinates whose band is at most a quarter of them wide
            (``res.stats["solver"]`` says which ran).
        sensitivities : list of str, optional
            Design parameters (names from :meth:`parameters`) to differentiate with respect
            to: the result then has ``dq_dp``, ``dqd_dp``, ``dqdd_dp``, each (rows,
            n_coordinates, n_params), and ``res.sensitivity(body, name)``. They come from
            the differentiated constraint equations, J dq/dp = -Phi_p and so on, solved
            with each step's factorization (exact to round-off; see docs/sensitivities.md).
        progress : bool, optional
            A progress bar (tqdm) while the core runs: None (default) shows it when the run
            lasts more than about 2 s on a terminal or in a notebook, True always, False
            never. The results are the same bit for bit (one core call either way); Ctrl-C
            stops the run at its next step.
        positions_only : bool, optional
            Compute the positions alone (coupler curves, sweeps of paths): ``res.qd`` and
            ``res.qdd`` are None. Where J is well conditioned the core then steps by chord
            corrections on a kept factorization of J from a polynomial prediction of the
            positions, each step ending as a full step's Newton correction does (below
            resolution); near singular configurations it takes full steps. The positions
            are as close to the exact ones as a full run's (docs/kinematics.md). Not with
            ``sensitivities``; no inverse dynamics.

        Returns
        -------
        KinematicsResult
            When every body has a mass and an inertia (and ``maxit`` is not given, and not
            ``positions_only``), a DynamicsResult with the inverse dynamics too (see
            :meth:`inverse_dynamics`).

        Raises
        ------
        ModelError
            If the model is malformed or not kinematically determined.
        SingularConfigurationError
            At a dead centre; carries the results up to it (``err.results``).
        AssemblyError, ConvergenceError, SingularJacobianError
            On other numerical failures.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=10)
        >>> res.q.shape[0]
        11
        """
        positions_only = flag(positions_only, "positions_only", "analysis")
        if self.has_masses() and maxit is None and not positions_only:
            return run_inverse(self, t_end=t_end, steps=steps, t0=t0, tol=tol, every=every,
                               solver=solver, sensitivities=sensitivities, progress=progress)
        return run_kinematics(self, t_end=t_end, steps=steps, t0=t0, tol=tol, maxit=maxit,
                              every=every, solver=solver, sensitivities=sensitivities,
                              progress=progress, positions_only=positions_only)

    @reads_entries
    def analyze_dof(self, t: float = 0.0, tol: float | None = None) -> DofReport:
        """Degrees of freedom and redundant constraints at the configuration assembled from
        the q0 estimates at time t.

        Returns
        -------
        DofReport
            Coordinates, equations, rank of J, degrees of freedom, mobility of the joints
            alone, and the redundant equations by name (``print(report)`` for a summary).

        Raises
        ------
        InconsistentConstraintsError
            If redundant constraints contradict each other.
        AssemblyError
            If no configuration satisfies the constraints near q0.

        Examples
        --------
        >>> import mbd2d
        >>> print(mbd2d.load("examples/door_two_hinges.toml").analyze_dof().redundant_rows)
        ['upper.x', 'upper.y']
        """
        return analyze_dof(self, t=t, tol=tol)

    @reads_entries
    def inverse_dynamics(self, t_end: float, steps: int, t0: float = 0.0,
                         tol: float | None = None, every: int = 1, solver: str = "auto",
                         sensitivities: Any = None,
                         progress: bool | None = None) -> DynamicsResult:
        """Kinematics of the driven model plus, at every output time, the multipliers lambda
        (J^T lambda = Q - M q_ddot), the joint reactions (``res.reaction(name)``), the driver
        efforts (``res.effort(name)``) and the energies. ``every`` and ``solver`` as in
        :meth:`kinematics` (the multipliers are computed at the kept outputs only).

        With ``sensitivities=[names]`` (geometry, masses, inertias, gravity, force and
        driver parameters) the result also has the kinematic sensitivities of
        :meth:`kinematics`, ``dlam_dp`` (rows, neq, n_params), ``res.effort_dp(driver)``
        (rows, n_params) and ``res.reaction_dp(name)``. ``progress`` as in :meth:`kinematics`
        (the bar counts the kinematic pass, then the multipliers').

        Raises
        ------
        ModelError
            If a body has no mass or inertia, or the model is not kinematically determined.
        SingularConfigurationError, AssemblyError, ConvergenceError
            As :meth:`kinematics`.
        """
        return run_inverse(self, t_end=t_end, steps=steps, t0=t0, tol=tol, every=every,
                           solver=solver, sensitivities=sensitivities, progress=progress)

    @reads_entries
    def dynamics(self, t_end: float, steps: int, method: str | None = None,
                 rtol: float | None = None, atol: float | None = None, h: float | None = None,
                 rho_inf: float | None = None, alpha: float | None = None,
                 beta: float | None = None, t0: float = 0.0, every: int = 1,
                 max_steps: int | None = None, sensitivities: Any = None,
                 progress: bool | None = None, solver: str = "auto") -> DynamicsResult:
        """Forward dynamics of M q_ddot + J^T lambda = Q, Phi = 0 from the assembled q0 and
        v0 (projected onto J q_dot = nu), outputs at steps + 1 uniform times (every
        every-th of them kept).

        Parameters
        ----------
        t_end, steps, t0 : float, int, float
            Output times t0 + k (t_end - t0)/steps.
        method : {'dopri5', 'generalized-alpha', 'baumgarte-rk4', 'partitioned'}
            dopri5 (default): index 1, Dormand-Prince 5(4), error-controlled, with projection
            onto the position and velocity constraints after each step;
            generalized-alpha: implicit index 3, error-controlled or fixed step h; the choice
            for stiff models;
            baumgarte-rk4: index 1 with Baumgarte stabilization, fixed step h;
            partitioned: coordinate partitioning (Wehage-Haug), Dormand-Prince on the
            independent coordinates.
        rtol, atol : float, optional
            Error tolerances of the adaptive methods (defaults 1e-6, 1e-8); atol applies to
            lengths in units of the model's length scale (see README, "Any unit of length").
        h : float, optional
            Fixed step (generalized-alpha, baumgarte-rk4).
        rho_inf : float, optional
            Generalized-alpha spectral radius at infinite frequency, in [0, 1] (default 0.8).
        alpha, beta : float, optional
            Baumgarte coefficients (default 10, 10).
        every : int, optional
            Output decimation (default 1): of the output times k = 0 .. steps only those with
            k % every == 0, and always the last (k = steps), are stored and returned, so
            memory grows as steps / every. The integration (its time grid and, for fixed
            steps, h) is the same as with every = 1, and so are the rows kept.
        max_steps : int, optional
            Limit on the integrator's steps, accepted and rejected (default 10_000_000). It
            ends a run whose steps collapse; a long run at a tight tolerance (or a fixed h
            that needs more steps) raises it. When it is reached the run stops with an
            IntegrationError that says so, the results up to then kept.
        sensitivities : list of str, optional
            Design parameters to differentiate with respect to (dopri5 and
            generalized-alpha), giving ``dq_dp``, ``dqd_dp``, ``dqdd_dp`` (rows,
            n_coordinates, n_params) and the multipliers' ``dlam_dp`` (rows, neq, n_params;
            with ``effort_dp``, ``reaction_dp``: the derivatives of the index-1 multipliers
            at each output's state along its sensitivities). dopri5 integrates the
            variational equations with the state; generalized-alpha differentiates its
            discrete equations (at a fixed h the exact derivatives of its own solution);
            either way under the same error control. The start's sensitivities are those
            of the assembled q0 (the minimum-norm change) and of the projected v0. They take
            the path ``solver`` gives.
        progress : bool, optional
            A progress bar while the core integrates, as in :meth:`kinematics`.
        solver : {"auto", "dense", "banded"}, optional
            Linear algebra of every saddle-point solve ([M J^T; J 0], generalized-alpha's
            iteration matrix, the projections, the consistent start, the multipliers):
            dense LU, or band LU after an ordering that interleaves each body's coordinates
            with the rows of its constraints (no n x n matrix: cost and memory linear in the
            number of bodies of a chain-like model). "auto" picks the band for at least 60
            coordinates whose band is narrow (``res.stats["solver"]`` and
            ``res.stats["band"]`` say which ran). On the dense path a small saddle matrix
            (at most 64 rows; generalized-alpha's up to 128) takes a sparse LU replayed in
            a fixed pivot order. Systems with a diagonal upper-left block (the index-1 ones
            beyond that size and on the band path; on the band path generalized-alpha's when
            its K is diagonal, as for pins) go through the Schur complement J A^-1 J^T where
            it is well conditioned (``res.stats["schur"]``).

        Returns
        -------
        DynamicsResult

        Raises
        ------
        ModelError
            If a body has no mass or inertia, or a setting is invalid (every or max_steps not
            a whole number >= 1).
        IntegrationError
            When the method fails (blow-up, step-size underflow, the step limit max_steps);
            carries the partial results.

        Examples
        --------
        >>> res = model.dynamics(10.0, 100_000, method="generalized-alpha", h=1e-4,
        ...                      every=100)   # doctest: +SKIP
        >>> res.t.shape                        # doctest: +SKIP
        (1001,)
        """
        return run_dynamics(self, t_end=t_end, steps=steps, method=method, rtol=rtol,
                            atol=atol, h=h, rho_inf=rho_inf, alpha=alpha, beta=beta, t0=t0,
                            every=every, max_steps=max_steps, sensitivities=sensitivities,
                            progress=progress, solver=solver)

    @reads_entries
    def statics(self, t: float = 0.0, sensitivities: Any = None,
                solver: str = "auto") -> StaticsResult:
        """Static equilibrium under gravity, springs and loads (drivers held at t), with the
        multipliers, reactions (``res.reaction(name)``) and stability. With
        ``sensitivities=[names]`` also ``eq.dq_dp`` (n_coordinates, n_params) and
        ``eq.dlam_dp``, the derivatives of the equilibrium. ``solver`` as in
        :meth:`dynamics` (``res.stats["solver"]`` says which ran; sensitivities use the dense
        path).

        Raises
        ------
        ConvergenceError
            If no equilibrium is found near the q0 estimates.
        SingularJacobianError
            If the equilibrium is not unique (a free motion without stiffness).
        """
        return run_statics(self, t=t, sensitivities=sensitivities, solver=solver)

    def modes(self, t: float = 0.0, count: int | None = None, equilibrium: bool = True,
              solver: str = "auto") -> ModesResult:
        """Natural frequencies, damping ratios and mode shapes of the small vibrations about
        the static equilibrium near the q0 estimates (drivers held at t, as in
        :meth:`statics`): the linearized equations M_r z'' + C_r z' + K_r z = 0 on the free
        motions, K_r including the constraints' curvature under the equilibrium's
        multipliers. ``count`` asks for the lowest modes only (default: all, or the lowest 20
        of a model of more than 3000 coordinates); ``equilibrium=False`` linearizes about
        the assembled q0 as given (an equilibrium the caller knows, or a neutral one).

        Returns
        -------
        ModesResult
            ``res.frequency`` (Hz), ``res.omega2``, ``res.shapes``, ``res.kinds``,
            ``res.eigenvalues`` with ``res.damping_ratio``; ``res.plot(k)``,
            ``res.animate(k, path)``, ``res.to_csv(path)``, ``res.summary()``.

        Raises
        ------
        ConvergenceError
            If no equilibrium is found near the q0 estimates.
        SingularJacobianError
            If a free motion carries no mass, or the equilibrium is not unique.
        """
        return run_modes(self, t=t, count=count, equilibrium=equilibrium, solver=solver)

    def frequency_response(self, inputs: Any, frequencies: Any, t: float = 0.0,
                           equilibrium: bool = True, solver: str = "auto"
                           ) -> FrequencyResponseResult:
        """The steady response of the small vibrations about the static equilibrium (drivers
        held at t, as in :meth:`modes`) to design parameters varied harmonically,
        p = p0 + Re(P e^(i 2 pi f t)): a shaker's force (a force function's constant term),
        a spring's free length (a displacement input), gravity (a base acceleration), a
        pivot's place (a base motion). The linearized equations M dq'' + C dq' + K dq +
        J^T dlambda = (Q_p - J_p^T lambda) P, J dq = -Phi_p P are solved for each frequency
        on the free motions, with the exact K, C and parameter derivatives of the design
        sensitivities (at f = 0 the response is ``statics(sensitivities=...).dq_dp``).

        Parameters
        ----------
        inputs : str or sequence of str
            Design parameters (:meth:`parameters` names them).
        frequencies : array_like
            Frequencies in Hz (>= 0).
        t, equilibrium, solver
            As :meth:`modes`.

        Returns
        -------
        FrequencyResponseResult
            ``res.response`` (n_frequencies, n_coordinates, n_inputs) complex,
            ``res.response_of(body, "y", input)``, ``res.peak(...)``, ``res.plot(body)``
            (Bode), ``res.to_csv(path)``, ``res.summary()``.

        Raises
        ------
        ModelError
            For an unknown input, no input, bad frequencies, contacts or joint friction.
        ConvergenceError
            If no equilibrium is found near the q0 estimates.
        SingularJacobianError
            If a frequency asked for is an undamped natural frequency (0 Hz with a motion
            without stiffness), or a free motion carries no mass.
        """
        return run_frf(self, inputs, frequencies, t=t, equilibrium=equilibrium, solver=solver)

    @reads_entries
    def linearize(self, inputs: Any, t: float = 0.0, equilibrium: bool = True,
                  solver: str = "auto", velocities: bool = False,
                  efforts: bool = False) -> LinearizedSystem:
        """The small motion about the static equilibrium (drivers held at t, as in
        :meth:`modes`) as a state-space system x' = A x + B p, dq = C x + D p whose inputs
        p are design parameters (a force's amplitude, a spring's free length, gravity, a
        pivot's place) and whose outputs are the coordinates' changes: Adams/Linear's state
        matrices, for control design (``res.to_scipy()``). From the equations of
        :meth:`frequency_response` with the same exact K, C and parameter derivatives: its
        transfer function C (i 2 pi f I - A)^-1 B + D is that response.

        Parameters
        ----------
        inputs : str or sequence of str
            Design parameters (:meth:`parameters` names them).
        t, equilibrium, solver
            As :meth:`modes`.
        velocities : bool
            Also the coordinates' velocities as outputs (``NAME.x_dot`` ...: C A and C B,
            after the coordinates' rows), for velocity feedback; only for inputs that act
            through forces (D = 0: an input that moves the mechanism directly would move
            its velocities by its rate).
        efforts : bool
            Also every driver's effort as an output (``effort.NAME``, the force or torque
            that holds its motion, as :meth:`inverse_dynamics` gives it), after the other
            outputs: for a motor torque or a held base force in a control loop; only for
            inputs whose rate and acceleration do not act on the constraints (a force,
            gravity; an input that moves the constraints is named).

        Returns
        -------
        LinearizedSystem
            ``res.a``, ``res.b``, ``res.c``, ``res.d``, ``res.states``, ``res.inputs``,
            ``res.outputs``, ``res.select(outputs=[...])``, ``res.to_scipy()``,
            ``res.to_csv(path)``, ``res.summary()``.

        Raises
        ------
        ModelError
            For an unknown input, no input, contacts or joint friction; velocities or
            efforts with an input that moves the mechanism directly (named); efforts of a
            model without drivers.
        ConvergenceError
            If no equilibrium is found near the q0 estimates.
        SingularJacobianError
            If a free motion carries no mass.

        Examples
        --------
        >>> m = mbd2d.load("examples/pendulum_spring.toml")
        >>> sys = m.linearize("model.gravity.1")
        >>> sys.a.shape[0] == 2 * sys.n_free
        True
        """
        return run_linearize(self, inputs, t=t, equilibrium=equilibrium, solver=solver,
                             velocities=velocities, efforts=efforts)

    # ------------------------------------------------------------------ at one state
    @reads_entries
    def phi(self, q: Any, t: float = 0.0) -> np.ndarray:
        """Phi(q, t), computed by the core."""
        return evaluate(self, q, None, t)[0]

    @reads_entries
    def jacobian(self, q: Any, t: float = 0.0) -> np.ndarray:
        """J = Phi_q(q, t), computed by the core."""
        return evaluate(self, q, None, t)[1]

    @reads_entries
    def nu(self, q: Any, t: float = 0.0) -> np.ndarray:
        """nu = -Phi_t(q, t), computed by the core."""
        return evaluate(self, q, None, t)[2]

    @reads_entries
    def gamma(self, q: Any, qd: Any, t: float = 0.0) -> np.ndarray:
        """gamma(q, q_dot, t), the right-hand side of J q_ddot = gamma, computed by the core."""
        return evaluate(self, q, qd, t)[3]

    # ------------------------------------------------------------------ pictures
    @reads_entries
    def configuration(self, t: float = 0.0) -> plots.Configuration:
        """The model assembled at time t from its q0 estimates, as a one-row motion for the
        pictures; the q0 estimates themselves when assembly fails (``.note`` says so)."""
        try:
            return plots.Configuration(self, self.analyze_dof(t=t).q, t)
        except MbdError as exc:
            q0 = pack(self).q0
            return plots.Configuration(self, q0, t, note=f"q0 estimates (assembly failed: "
                                       f"{type(exc).__name__})")

    @reads_entries
    def plot(self, t: float = 0.0, **kwargs: Any) -> Any:
        """The model assembled at time t: :func:`mbd2d.plot_mechanism` (returns the Axes).

        Examples
        --------
        >>> import mbd2d
        >>> ax = mbd2d.load("examples/slider_crank.toml").plot()
        """
        conf = self.configuration(t)
        kwargs.setdefault("title", f"{self.name}" + (f": {conf.note}" if conf.note else
                                                     f" at t = {t:g} s"))
        return plots.plot_mechanism(conf, **kwargs)

    def _repr_png_(self) -> bytes | None:
        """The assembled model's picture, for Jupyter (None when it cannot be drawn)."""
        try:
            conf = self.configuration()
            title = f"{self.name}" + (f": {conf.note}" if conf.note else "")
            return plots.png_bytes(conf, title=title)
        except (ImportError, MbdError, ValueError):
            return None

    # ------------------------------------------------------------------ files
    @reads_entries
    def export(self, path: str | Path, t_end: float | None = None, steps: int | None = None,
               t0: float = 0.0, tol: float | None = None, maxit: int | None = None,
               analysis: str = "kinematics", every: int = 1, solver: str = "auto",
               method: str | None = None, rtol: float | None = None,
               atol: float | None = None, h: float | None = None,
               rho_inf: float | None = None, alpha: float | None = None,
               beta: float | None = None, max_steps: int | None = None, t: float = 0.0,
               outputs: Sequence[str] | None = None, positions_only: bool = False,
               sensitivities: Sequence[str] | None = None,
               measures: Sequence[str] | None = None, count: int | None = None,
               equilibrium: bool = True, inputs: Sequence[str] | None = None,
               frequencies: Any = None) -> None:
        """Write a plain-text model file that the standalone ``mbd2d-solve`` runs without
        Python (format: docs/mbd-format.md), with the analysis and its settings.

        Parameters
        ----------
        path : str or pathlib.Path
            The file to write (.mbd).
        t_end, steps, t0, every : float, int, float, int
            The output times, as for the analyses (not for statics).
        analysis : str
            The analysis ``mbd2d-solve`` runs: "kinematics", "inverse-dynamics", "dynamics",
            "statics", "modes", "frf" or "check".
        tol, maxit, solver
            As :meth:`kinematics` (``tol`` and ``solver`` also for inverse dynamics).
        method, rtol, atol, h, rho_inf, alpha, beta, max_steps
            As :meth:`dynamics`.
        t : float
            Statics, modes: the time of loads and drivers.
        count, equilibrium
            Modes: as :meth:`modes` (the CSV is ``res.to_csv(path)``, or with
            ``outputs=["damped"]`` ``res.to_csv(path, damped=True)``); ``equilibrium`` also
            frf.
        inputs, frequencies
            Frf (the frequency response): as :meth:`frequency_response` (the CSV is
            ``res.to_csv(path)``).
        outputs : list of str, optional
            Optional CSV columns: "energy", "multipliers", "reactions", "efforts" (not for
            kinematics; no energy for statics), as ``res.to_csv(path, energy=True, ...)``.
        positions_only : bool, optional
            Kinematics: positions alone, as :meth:`kinematics` (the CSV has t and NAME.x,
            NAME.y, NAME.theta per body).
        sensitivities : list of str, optional
            Design parameters (names as :meth:`parameters`): ``mbd2d-solve`` computes the
            sensitivities as the analysis does with ``sensitivities=[...]`` and writes their
            columns ``d(COLUMN)/d(NAME)``, as ``res.to_csv(path, sensitivities=True)``
            (kinematics, inverse dynamics, statics, and dynamics by dopri5 or
            generalized-alpha).
        measures : list of str, optional
            Measure columns, as ``res.to_csv(path, measures=[...])``:
            ``transmission_angle:JOINT[:OUTPUT]``, ``velocity_ratio:INPUT:OUTPUT[:VIA]``,
            ``mechanical_advantage:INPUT:OUTPUT[:VIA]``, ``dead_centre_distance`` (not for
            statics).

        Raises
        ------
        ModelError
            If the model or a setting is invalid (checked as for a Python run).

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_masses.toml")
        >>> m.export("/tmp/fourbar.mbd", t_end=1.0, steps=100, analysis="dynamics",
        ...          method="generalized-alpha", h=1e-3, outputs=["energy", "reactions"])
        """
        export_mbd(self, path, t_end=t_end, steps=steps, t0=t0, tol=tol, maxit=maxit,
                   analysis=analysis, every=every, solver=solver, method=method, rtol=rtol,
                   atol=atol, h=h, rho_inf=rho_inf, alpha=alpha, beta=beta,
                   max_steps=max_steps, t=t, outputs=outputs, positions_only=positions_only,
                   sensitivities=sensitivities, measures=measures, count=count,
                   equilibrium=equilibrium, inputs=inputs, frequencies=frequencies)


def load(path: str | Path) -> Model:
    """Read a model from a TOML file.

    Parameters
    ----------
    path : str or Path
        The .toml file.

    Returns
    -------
    Model

    Raises
    ------
    ModelError
        If the file is missing, is not valid TOML, or describes an invalid model; the message
        names the entry and the key.

    Examples
    --------
    >>> import mbd2d
    >>> mbd2d.load("examples/fourbar_seed.toml")
    Model('seed-four-bar': 3 bodies, 4 joints, 1 drivers)
    """
    return toml_io.load(path, cls=Model)


def loads(text: str, source: str = "<string>", base: str | Path | None = None) -> Model:
    """Read a model from TOML text; see :func:`load` (``base``: the directory table files
    are relative to, default the current one)."""
    return toml_io.loads(text, source=source, cls=Model, base=base)


def from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Model:
    """Build a model from parsed TOML (nested dicts and lists); see :func:`load`."""
    return toml_io.from_dict(data, source=source, cls=Model)


__all__ = ["Model", "load", "loads", "from_dict"]

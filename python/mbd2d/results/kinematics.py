"""Kinematic results: positions, velocities and accelerations by time, per-body views, CSV
and NPZ output."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import plots
from ..errors import MbdError, ModelError
from ..validate import vector
from . import measures
from .columns import derivative_names, motion_columns, require_sensitivities
from .files import check_outputs, write_csv, writing
from .measures import measure_columns, measure_derivative_columns
from .points import PointResult
from .sensitivities import LEVELS, body_columns, parameter_index


def repr_png(obj: Any) -> bytes | None:
    """PNG of a result's mechanism picture for notebooks; None (plain text shown instead)
    when matplotlib is missing or the picture cannot be drawn."""
    try:
        return plots.png_bytes(obj)
    except (ImportError, MbdError, ValueError):
        return None


@dataclass
class BodyResult:
    """Time histories of one body (arrays over the output times; the velocities and
    accelerations None after a ``positions_only`` run)."""

    name: str
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    x_dot: np.ndarray | None
    y_dot: np.ndarray | None
    theta_dot: np.ndarray | None
    x_ddot: np.ndarray | None
    y_ddot: np.ndarray | None
    theta_ddot: np.ndarray | None


@dataclass
class KinematicsResult:
    """Positions, velocities and accelerations at the output times.

    Attributes
    ----------
    t : numpy.ndarray
        Output times (n,).
    q, qd, qdd : numpy.ndarray
        Coordinates, velocities, accelerations (n, nq); rows are times. Columns are
        ``coordinate_names``: x, y, theta of each body, then extra coordinates (cam alpha).
        ``qd`` and ``qdd`` are None after a ``positions_only`` run.
    body_names, coordinate_names : list of str
    stats : dict
        Newton corrections, LU factorizations, rejected steps, tolerance used.
    complete : bool
        False when the run stopped early (see the exception that carried this result).
    parameter_names : list of str
        The design parameters of ``sensitivities=[...]`` (empty without them).
    dq_dp, dqd_dp, dqdd_dp : numpy.ndarray or None
        Their sensitivities d q / d p, d q_dot / d p, d q_ddot / d p, each
        (n, n_coordinates, n_params), computed in the core (None without them).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray | None
    qdd: np.ndarray | None
    body_names: list[str]
    coordinate_names: list[str]
    stats: dict[str, Any] = field(default_factory=dict)
    complete: bool = True
    model: Any = None
    parameter_names: list[str] = field(default_factory=list)
    dq_dp: np.ndarray | None = None
    dqd_dp: np.ndarray | None = None
    dqdd_dp: np.ndarray | None = None

    def body(self, name: str) -> BodyResult:
        """Histories of the body called name.

        Raises
        ------
        KeyError
            If there is no such body.
        """
        try:
            i = self.body_names.index(name)
        except ValueError:
            raise KeyError(f"no body {name!r}; bodies: {', '.join(self.body_names)}") from None
        c = slice(3 * i, 3 * i + 3)
        q = self.q[:, c]
        if self.qd is None or self.qdd is None:
            return BodyResult(name, q[:, 0], q[:, 1], q[:, 2], None, None, None, None, None,
                              None)
        qd, qdd = self.qd[:, c], self.qdd[:, c]
        return BodyResult(name, q[:, 0], q[:, 1], q[:, 2], qd[:, 0], qd[:, 1], qd[:, 2],
                          qdd[:, 0], qdd[:, 1], qdd[:, 2])

    def sensitivity(self, body: str, name: str, of: str = "q") -> np.ndarray:
        """d(x, y, theta)/dp of a body over time, shape (n, 3), for the design parameter
        called name; ``of`` = "qd" or "qdd" for the velocities' or accelerations'.

        Raises
        ------
        KeyError
            For an unknown body, a parameter the run was not asked for, or a bad ``of``.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> res = m.kinematics(1.0, 10, sensitivities=["joint.B.points.0.0"])
        >>> res.sensitivity("rocker", "joint.B.points.0.0").shape
        (11, 3)
        """
        if of not in LEVELS:
            raise KeyError(f"of must be one of {', '.join(LEVELS)}, got {of!r}")
        k = parameter_index(self.parameter_names, name)
        arr = {"q": self.dq_dp, "qd": self.dqd_dp, "qdd": self.dqdd_dp}[of]
        assert arr is not None
        return arr[:, body_columns(self.body_names, body), k]

    def point(self, name: str, s: Any) -> PointResult:
        """Position, velocity and acceleration of a point fixed in a body.

        Parameters
        ----------
        name : str
            The body.
        s : sequence of two floats
            The point in the body's frame.

        Returns
        -------
        PointResult
            ``.r``, ``.v``, ``.a`` (n, 2) global position, velocity, acceleration (also
            ``.x``, ``.y``, ``.x_dot``, ..., ``.speed``); indexing it indexes ``.r``. After a
            ``positions_only`` run ``.v`` and ``.a`` are None.

        Raises
        ------
        ModelError
            If s is not two finite numbers.
        KeyError
            If there is no such body.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=4)
        >>> p = res.point("coupler", [0.0, 1.0])
        >>> p.r.shape, p.v.shape, p.a.shape
        ((5, 2), (5, 2), (5, 2))
        """
        sx, sy = vector(s, 2, "s", "point")
        b = self.body(name)
        q = np.column_stack([b.x, b.y, b.theta])
        if self.qd is None:
            return PointResult.of(name, (sx, sy), q, None, None)
        qd = np.column_stack([b.x_dot, b.y_dot, b.theta_dot])
        qdd = np.column_stack([b.x_ddot, b.y_ddot, b.theta_ddot])
        return PointResult.of(name, (sx, sy), q, qd, qdd)

    def point_dp(self, name: str, s: Any, of: str = "r") -> np.ndarray:
        """The exact design derivatives of a point fixed in a body (rows, 2, n_params):
        d(x, y)/dp of its position (``of="r"``), velocity (``"v"``) or acceleration
        (``"a"``), in ``parameter_names`` order, from the body's sensitivities (d r_P =
        d r_i + B s' d theta, ...; see :mod:`mbd2d.results.points`): which dimension moves
        the coupler curve, and how much.

        Raises
        ------
        ModelError
            Without sensitivities, or if s is not two finite numbers.
        KeyError
            For an unknown body or a bad ``of``.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> res = m.kinematics(1.0, 4, sensitivities=["joint.B.points.0.0"])
        >>> res.point_dp("coupler", [0.0, 1.0]).shape
        (5, 2, 1)
        """
        require_sensitivities(self.dq_dp is not None, "point_dp")
        if of not in ("r", "v", "a"):
            raise KeyError(f"of must be one of r, v, a, got {of!r}")
        sx, sy = vector(s, 2, "s", "point")
        c = body_columns(self.body_names, name)
        levels = [x[:, c] for x in self._levels()]
        dlevels = [x[:, c, :] for x in (self.dq_dp, self.dqd_dp, self.dqdd_dp) if x is not None]
        k = "rva".index(of)
        if k >= len(levels):
            raise ModelError("the run computed positions only (positions_only=True): run "
                             "the kinematics without it for velocities and accelerations",
                             "positions_only")
        return PointResult.derivatives((sx, sy), levels[:k + 1], dlevels[:k + 1])[k]

    # ------------------------------------------------------------------ mechanism measures
    def transmission_angle(self, joint: str, output: str | None = None) -> np.ndarray:
        """Transmission angle at a revolute joint between a coupler and an output link.

        mu is the angle between the coupler (from ``joint`` to the coupler's other revolute
        joint) and the output link (from ``joint`` to its other pivot), in [0, pi]; pi/2 is
        ideal, and designers keep it within about pi/2 +- 50 deg. For an output that slides
        (a translational joint), mu = pi/2 - the acute angle between the coupler and the
        slide, in [0, pi/2]. A four-bar a (crank), b (coupler), c (rocker), d (ground) has
        cos mu = (b^2 + c^2 - a^2 - d^2 + 2 a d cos theta2) / (2 b c).

        Parameters
        ----------
        joint : str
            The revolute joint between the coupler and the output link (e.g. "B").
        output : str, optional
            Which of its bodies is the output link (default: its second body).

        Returns
        -------
        numpy.ndarray
            mu in radians at every output time.

        Raises
        ------
        ModelError
            If the joint or the bodies around it do not form a coupler and an output link.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=4)
        >>> res.transmission_angle("B").shape
        (5,)
        """
        return measures.transmission_angle(self, joint, output)

    def transmission_angle_dp(self, joint: str, output: str | None = None) -> np.ndarray:
        """The transmission angle's exact derivatives along the design parameters of a run
        with ``sensitivities=[...]``: d(mu)/d(p) (rows, n_params), rad per unit of each
        parameter, in ``parameter_names`` order. The core differentiates the angle along
        the motion's sensitivities and, where a parameter is one of the angle's own points
        (the pivot of the output link, the coupler's joints), along that point too.

        Raises
        ------
        ModelError
            Without sensitivities, or as :meth:`transmission_angle`.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> res = m.kinematics(1.0, 4, sensitivities=["joint.O4.points.1.0"])
        >>> res.transmission_angle_dp("B").shape
        (5, 1)
        """
        return measures.transmission_angle_dp(self, joint, output)

    def velocity_ratio(self, input: str, output: str, via: str | None = None) -> np.ndarray:
        """d(output)/d(input) along the motion: the kinematic influence coefficients.

        Each quantity is a coordinate name (``"rocker.theta"``, ``"slider.x"``, see
        ``coordinate_names``) or a driver name (the quantity it prescribes). Both are
        differentiated by the quantity s of one driver, the others held (J u = e_s, solved
        by the core at every output): ``via``, else whichever of input and output is a
        driver, else the model's only driver. The ratio is a property of the configuration,
        defined even where the driver stands still.

        Returns
        -------
        numpy.ndarray
            dY/dX at every output; +-inf where the input stands still (its dead centre or
            limit position); inf where J is singular for the driver.

        Raises
        ------
        ModelError
            If a name is neither a driver nor a coordinate, or a quantity does not move with
            the driver at all.
        """
        return measures.ratio_values(self, "velocity_ratio", input, output, via)

    def mechanical_advantage(self, input: str, output: str,
                             via: str | None = None) -> np.ndarray:
        """The mechanical advantage from input to output: the load at the output that a unit
        effort at the input balances, by virtual work the inverse of the velocity ratio,
        d(input)/d(output) (e.g. output force per input torque for a crank and a slider).
        Quantities and ``via`` as in :meth:`velocity_ratio`.

        Returns
        -------
        numpy.ndarray
            At every output time; signed (negative when the output moves against the
            input); +-inf where the output stands still (a limit position, the toggle a
            press uses); 0 where J is singular for the driver.

        Raises
        ------
        ModelError
            As :meth:`velocity_ratio`.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/slider_crank.toml").kinematics(t_end=0.5, steps=4)
        >>> ma = res.mechanical_advantage("motor", "slider.x")   # N per N m
        >>> ma.shape
        (5,)
        """
        return measures.ratio_values(self, "mechanical_advantage", input, output, via)

    def dead_centre_distance(self) -> np.ndarray:
        """Distance to a dead centre at every output: sigma_min / sigma_max of the
        constraint Jacobian J, computed by the core with lengths in units of the model's
        length scale and the columns of J scaled to unit length (the measure the kinematics
        uses to call a configuration singular). It is 0 at a dead centre (toggle) or
        bifurcation and near a toggle falls like sqrt(t* - t). Each output costs an SVD of
        the dense J (a few microseconds for a four-bar, seconds for thousands of
        coordinates: keep fewer rows with ``every``).

        Returns
        -------
        numpy.ndarray
            Values in [0, 1] at every output time.
        """
        return measures.dead_centre_distance(self)

    def velocity_ratio_dp(self, input: str, output: str, via: str | None = None
                          ) -> np.ndarray:
        """The velocity ratio's exact derivatives along the design parameters of a run with
        ``sensitivities=[...]``: (rows, n_params) in ``parameter_names`` order. The core
        differentiates the influence coefficients, J du/dp = -(J_q dq/dp + J_p) u with J's
        factors reused, and the ratio by the quotient rule. Quantities and ``via`` as in
        :meth:`velocity_ratio`; +-inf where the input stands still, inf where J is singular.

        Raises
        ------
        ModelError
            Without sensitivities, or as :meth:`velocity_ratio`.

        Examples
        --------
        >>> import mbd2d
        >>> m = mbd2d.load("examples/fourbar_grashof.toml")
        >>> res = m.kinematics(1.0, 4, sensitivities=["joint.O4.points.1.0"])
        >>> res.velocity_ratio_dp("motor", "rocker.theta").shape
        (5, 1)
        """
        return measures.measure_dp(self, measures.spec_of("velocity_ratio", input, output,
                                                          via))

    def mechanical_advantage_dp(self, input: str, output: str, via: str | None = None
                                ) -> np.ndarray:
        """The mechanical advantage's exact design derivatives (rows, n_params), as
        :meth:`velocity_ratio_dp` (+-inf where the output stands still).

        Raises
        ------
        ModelError
            Without sensitivities, or as :meth:`mechanical_advantage`.
        """
        return measures.measure_dp(self, measures.spec_of("mechanical_advantage", input,
                                                          output, via))

    def dead_centre_distance_dp(self) -> np.ndarray:
        """The dead-centre distance's exact design derivatives (rows, n_params): with the
        column-scaled J D = U S V^T, d sigma_i = u_i^T d(J D) v_i along the motion's
        sensitivities and the parameters (the core; an SVD with vectors per output). The
        distance is measured with lengths in the model's length scale L, a power of 2 taken
        from the model's size: it jumps where a parameter moves the model across a power of
        2 (L changes); the derivative is the one at fixed L.

        Raises
        ------
        ModelError
            Without sensitivities.
        """
        return measures.measure_dp(self, "dead_centre_distance")

    # ------------------------------------------------------------------ pictures
    def plot(self, times: Any = None, trace: Any = None, forces: bool = False,
             **kwargs: Any) -> Any:
        """The mechanism at a few times with traced paths: :func:`mbd2d.plot_mechanism`
        (returns the matplotlib Axes)."""
        return plots.plot_mechanism(self, times=times, trace=trace, forces=forces, **kwargs)

    def plot_paths(self, points: Any = None, **kwargs: Any) -> Any:
        """Paths of body points over the run: :func:`mbd2d.plot_paths` (returns the
        Axes)."""
        return plots.plot_paths(self, points, **kwargs)

    def plot_timeseries(self, bodies: Any = None, kind: str = "motion", **kwargs: Any) -> Any:
        """Quantities against time: :func:`mbd2d.plot_timeseries` (returns the Figure)."""
        return plots.plot_timeseries(self, bodies=bodies, kind=kind, **kwargs)

    def animate(self, path: Any = None, fps: float = 30, trace: Any = None,
                forces: bool = False, **kwargs: Any) -> Any:
        """Animate the run: a GIF (Pillow) or MP4 (ffmpeg) at ``path``, or without a path an
        inline HTML animation for Jupyter; see :func:`mbd2d.plots.animate` for ``speed``,
        ``max_frames``, ``size``, ``dpi`` and the rest.

        Examples
        --------
        >>> import mbd2d
        >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=60)
        >>> res.animate("/tmp/crank_rocker.gif", fps=15, trace=[("coupler", [0.0, 1.0])])
        '/tmp/crank_rocker.gif'
        """
        return plots.animate(self, path, fps=fps, trace=trace, forces=forces, **kwargs)

    def _repr_png_(self) -> bytes | None:
        """The mechanism picture, for Jupyter (None when it cannot be drawn)."""
        return repr_png(self)

    def table(self, sensitivities: bool = False, measures: Any = None, **outputs: bool
              ) -> tuple[list[str], np.ndarray]:
        """Header and rows of the CSV: t, then NAME.x ... NAME.theta_ddot per body (NAME.x,
        NAME.y, NAME.theta after a ``positions_only`` run); then a column per measure of
        ``measures`` (specs ``transmission_angle:JOINT[:OUTPUT]``,
        ``velocity_ratio:INPUT:OUTPUT[:VIA]``, ``mechanical_advantage:INPUT:OUTPUT[:VIA]``,
        ``dead_centre_distance``, each named by its spec); with ``sensitivities=True`` (a
        run with ``sensitivities=[names]``), then for each parameter P in turn the
        derivatives of the motion columns, ``d(NAME.x)/d(P)`` ... ``d(NAME.theta_ddot)/d(P)``,
        and of the measures, ``d(transmission_angle:B)/d(P)`` ... (their exact design
        derivatives, :func:`mbd2d.results.measures.measure_derivatives`).

        A kinematic result has no optional columns (``energy``, ``multipliers``,
        ``reactions``, ``efforts`` need a DynamicsResult): asking for one is a ModelError.
        """
        check_outputs(outputs, (), "table")
        header, rows = self._motion_table()
        names, blocks = measure_columns(self, measures)
        if sensitivities:
            dn, db = self._motion_derivatives("table", measures)
            names, blocks = names + dn, blocks + db
        return header + names, np.hstack([rows] + blocks)

    def _levels(self) -> list[np.ndarray]:
        return [a for a in (self.q, self.qd, self.qdd) if a is not None]

    def _motion_table(self) -> tuple[list[str], np.ndarray]:
        names, cols = motion_columns(self.body_names, self._levels())
        return ["t"] + names, np.hstack([self.t[:, None], cols])

    def _motion_derivative(self, k: int, what: str) -> tuple[list[str], np.ndarray]:
        """The sensitivity columns of the motion for parameter k: d(NAME.x)/d(P) ..."""
        require_sensitivities(self.dq_dp is not None, what)
        levels = [a[:, :, k] for a in (self.dq_dp, self.dqd_dp, self.dqdd_dp) if a is not None]
        cols, block = motion_columns(self.body_names, levels)
        return derivative_names(cols, self.parameter_names[k]), block

    def _motion_derivatives(self, what: str, measures: Any = None
                            ) -> tuple[list[str], list[np.ndarray]]:
        """The sensitivity columns of the motion, parameter after parameter, each followed
        by those of the measures."""
        require_sensitivities(self.dq_dp is not None, what)
        meas = measure_derivative_columns(self, measures)
        names: list[str] = []
        blocks: list[np.ndarray] = []
        for k in range(len(self.parameter_names)):
            n, b = self._motion_derivative(k, what)
            names += n + derivative_names(meas[0], self.parameter_names[k])
            blocks += [b, meas[1][:, :, k]]
        return names, blocks

    def _sensitivity_arrays(self, sensitivities: bool, what: str) -> dict[str, np.ndarray]:
        """The sensitivities for an .npz (always when the run has them)."""
        if sensitivities:
            require_sensitivities(self.dq_dp is not None, what)
        if self.dq_dp is None:
            return {}
        out = {k: v for k, v in (("dq_dp", self.dq_dp), ("dqd_dp", self.dqd_dp),
                                 ("dqdd_dp", self.dqdd_dp)) if v is not None}
        out["parameter_names"] = np.array(self.parameter_names)
        return out

    def _measure_arrays(self, specs: Any) -> dict[str, np.ndarray]:
        """The measures for an .npz: ``measures`` (n, k) and ``measure_names``; after a run
        with sensitivities also their derivatives ``dmeasures_dp`` (n, k, n_params) and
        ``dmeasure_names`` (the same names)."""
        names, cols = measure_columns(self, specs)
        if not names:
            return {}
        out = {"measures": np.hstack(cols), "measure_names": np.array(names)}
        dnames, d = measure_derivative_columns(self, specs)
        if dnames:
            out.update(dmeasures_dp=d, dmeasure_names=np.array(dnames))
        return out

    def to_csv(self, path: str | Path, **outputs: bool) -> None:
        """Write the CSV (the columns of :meth:`table`; every number with 17 significant
        digits, ``%.16e``, as ``mbd2d-solve`` writes them)."""
        header, rows = self.table(**outputs)
        write_csv(path, header, rows, "to_csv")

    def to_npz(self, path: str | Path, sensitivities: bool = False, measures: Any = None,
               **outputs: bool) -> None:
        """Write t, q, qd, qdd (q alone after a ``positions_only`` run) and the names to a
        NumPy .npz archive; after a run with ``sensitivities=[names]`` also ``dq_dp``,
        ``dqd_dp``, ``dqdd_dp`` (n, n_coordinates, n_params) and ``parameter_names``; with
        ``measures=[specs]`` (as :meth:`table`) ``measures`` (n, n_measures) and
        ``measure_names`` (and with sensitivities their ``dmeasures_dp``
        (n, k, n_params) with ``dmeasure_names``)."""
        check_outputs(outputs, (), "to_npz")
        motion = {k: v for k, v in (("q", self.q), ("qd", self.qd), ("qdd", self.qdd))
                  if v is not None}
        sens = self._sensitivity_arrays(sensitivities, "to_npz")
        sens.update(self._measure_arrays(measures))
        with writing(path, "to_npz") as p:
            np.savez(p, t=self.t, **motion, coordinate_names=np.array(self.coordinate_names),
                     body_names=np.array(self.body_names), **sens)

    def save(self, path: str | Path, **outputs: bool) -> None:
        """Write .csv or .npz by the file suffix (optional columns as :meth:`table`)."""
        if str(path).endswith(".npz"):
            self.to_npz(path, **outputs)
        else:
            self.to_csv(path, **outputs)

    def __repr__(self) -> str:
        span = f"t = {self.t[0]:g} .. {self.t[-1]:g}" if len(self.t) else "no rows"
        return (f"{type(self).__name__}({len(self.t)} rows, {span}, {len(self.coordinate_names)} "
                f"coordinates{'' if self.complete else ', incomplete'})")

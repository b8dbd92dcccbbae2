"""Dynamic results: a kinematic or dynamic run with multipliers, energies, drift, reactions
and driver efforts."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .contacts import (ContactEvent, ContactHistory, FrictionEvent, FrictionHistory, LiftOff,
                       history)
from .columns import constraint_columns, derivative_names
from .files import check_outputs, writing
from .kinematics import KinematicsResult
from .measures import measure_columns, measure_derivative_columns
from .reactions import Reaction, driver_row, reaction_arrays, reaction_of
from .sensitivities import parameter_index, reaction_dp_arrays, reaction_dp_of


#: columns of ``energy=True`` in a table
ENERGY_COLUMNS = ("kinetic", "potential", "energy", "drift_position", "drift_velocity")


@dataclass(repr=False)
class DynamicsResult(KinematicsResult):
    """A kinematic or dynamic run with multipliers, energies and constraint drift.

    Attributes
    ----------
    lam : numpy.ndarray
        Lagrange multipliers (n, neq), rows labelled by ``row_labels``; with redundant
        constraints the minimum-norm set.
    kinetic, potential : numpy.ndarray
        Kinetic energy q_dot^T M q_dot / 2 and potential energy (gravity and springs).
    drift_position, drift_velocity : numpy.ndarray
        ||Phi||_inf and ||J q_dot - nu||_inf at each output.
    contacts : list of ContactEvent
        Onsets and separations of the contacts (time, contact, kind, speed); forward
        dynamics locates them in time, inverse dynamics at the output times.
    friction_events : list of FrictionEvent
        Stick, slip and reversal of the stick-slip joints.
    lift_off : list of LiftOff
        Intervals where a cam joint would have to pull its follower onto the profile.
    elements : numpy.ndarray
        (n, number of force elements, 6) outputs of the forces, contacts and joint frictions
        (``element_names``); read them with :meth:`contact` and :meth:`friction`.
    dlam_dp : numpy.ndarray or None
        With ``sensitivities=[...]`` of inverse or forward dynamics: d lambda / d p (n, neq,
        n_params).
    """

    lam: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    kinetic: np.ndarray = field(default_factory=lambda: np.zeros(0))
    potential: np.ndarray = field(default_factory=lambda: np.zeros(0))
    drift_position: np.ndarray = field(default_factory=lambda: np.zeros(0))
    drift_velocity: np.ndarray = field(default_factory=lambda: np.zeros(0))
    row_labels: list[str] = field(default_factory=list)
    packed: Any = None
    elements: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 6)))
    element_names: list[tuple[str, str]] = field(default_factory=list)
    contacts: list[ContactEvent] = field(default_factory=list)
    friction_events: list[FrictionEvent] = field(default_factory=list)
    lift_off: list[LiftOff] = field(default_factory=list)
    dlam_dp: np.ndarray | None = None
    ptab: Any = None
    _reac: Any = None
    _reac_dp: Any = None

    @property
    def energy(self) -> np.ndarray:
        """Kinetic plus potential energy."""
        return self.kinetic + self.potential

    def _reactions(self) -> tuple[np.ndarray, np.ndarray]:
        if self._reac is None:
            self._reac = reaction_arrays(self.packed, self.q, self.t, self.lam)
        return self._reac

    def reaction(self, name: str) -> Reaction:
        """Reaction of the joint or driver called name on its two bodies.

        Raises
        ------
        KeyError
            If there is no such joint or driver.
        """
        return reaction_of(self.packed, self.model, name, self._reactions)

    def effort(self, name: str) -> np.ndarray:
        """What the driver called name supplies: the torque (angle drivers) or force
        (x, y or slide drivers) in the driven direction, -lambda of its row."""
        row = driver_row(self.packed, name)
        if row is None:
            raise KeyError(f"no driver {name!r}")
        return -self.lam[:, row]

    def effort_dp(self, name: str) -> np.ndarray:
        """Sensitivities of the effort of the driver called name to the design parameters,
        shape (n, n_params) (columns in the order of ``parameter_names``).

        Raises
        ------
        KeyError
            If there is no such driver or the run computed no multiplier sensitivities.
        """
        row = driver_row(self.packed, name)
        if row is None:
            raise KeyError(f"no driver {name!r}")
        if self.dlam_dp is None:
            raise KeyError("this result has no effort sensitivities: run the dynamics or "
                           "inverse dynamics with sensitivities=[names]")
        return -self.dlam_dp[:, row, :]

    def reaction_dp(self, name: str) -> Reaction:
        """Sensitivities of the reaction of the joint or driver called name: a Reaction
        whose arrays are (n, n_params), the changes of fx, fy, mz, ... per parameter.

        Raises
        ------
        KeyError
            If there is no such joint or driver, or no multiplier sensitivities.
        """
        if self.dlam_dp is None or self.dq_dp is None:
            raise KeyError("this result has no reaction sensitivities: run the dynamics or "
                           "inverse dynamics with sensitivities=[names]")
        return reaction_dp_of(self.packed, self.model, name, *self._reaction_dp_arrays())

    def _reaction_dp_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The reactions' sensitivities (n, nc, 6, n_params), global and local (cached)."""
        if self._reac_dp is None:
            self._reac_dp = reaction_dp_arrays(self.packed, self.ptab, self.q, self.t,
                                               self.lam, self.dq_dp, self.dlam_dp)
        return self._reac_dp

    def multiplier_dp(self, row: str, name: str) -> np.ndarray:
        """d lambda / d p of a row (by its label) for one parameter, over time.

        Raises
        ------
        KeyError
            If no row has that label, the run has no sensitivity to name, or none of the
            multipliers.
        """
        if self.dlam_dp is None:
            raise KeyError("this result has no multiplier sensitivities")
        if row not in self.row_labels:
            raise KeyError(f"no row {row!r}; rows: {', '.join(self.row_labels)}")
        return self.dlam_dp[:, self.row_labels.index(row),
                            parameter_index(self.parameter_names, name)]

    def multiplier(self, row: str) -> np.ndarray:
        """The multiplier of a row by its label (see ``model.constraint_rows()``).

        Raises
        ------
        KeyError
            If no row has that label.
        """
        if row not in self.row_labels:
            raise KeyError(f"no row {row!r}; rows: {', '.join(self.row_labels)}")
        return self.lam[:, self.row_labels.index(row)]

    def contact(self, name: str) -> ContactHistory:
        """Normal and friction force, penetration, sliding speed and contact point of the
        contact called name over the output times.

        Raises
        ------
        KeyError
            If there is no such contact.
        """
        return history(self.elements, self.element_names, name, "contact")

    def friction(self, name: str) -> FrictionHistory:
        """Normal load, friction force and moment, slip speed and sticking of the joint
        called name (a revolute or translational joint with friction).

        Raises
        ------
        KeyError
            If there is no such joint with friction.
        """
        return history(self.elements, self.element_names, name, "friction")

    def table(self, energy: bool = False, multipliers: bool = False, reactions: bool = False,
              efforts: bool = False, sensitivities: bool = False, measures: Any = None,
              **unknown: bool) -> tuple[list[str], np.ndarray]:
        """Header and rows of the CSV: the motion columns of
        :meth:`KinematicsResult.table`, then the optional columns asked for, in this order:

        * ``energy``: kinetic, potential, energy, drift_position, drift_velocity;
        * ``multipliers``: ``lambda.LABEL`` for every row of Phi (``row_labels``);
        * ``reactions``: ``NAME.fx``, ``NAME.fy``, ``NAME.mz`` (force and moment of the
          joint or driver on its first body, global, moment about its centre of mass) and
          ``NAME.fx_j``, ``NAME.fy_j``, ``NAME.mz_j`` (on its second body), every
          constraint in file order;
        * ``efforts``: ``NAME.effort``, what each driver supplies;

        and always, for each contact, NAME.normal_force, NAME.friction_force,
        NAME.penetration, NAME.sliding_speed, and for each joint with friction
        NAME.normal_load, NAME.friction_force, NAME.sliding_speed.

        Then a column per measure of ``measures`` (as :meth:`KinematicsResult.table`).
        With ``sensitivities=True`` (a run with ``sensitivities=[names]``) then, for each
        parameter P in turn, ``d(COLUMN)/d(P)`` of the motion columns and, when the run has
        the multipliers' sensitivities (dynamics), of the multiplier, reaction and
        effort columns asked for, then of the measures.

        ``mbd2d-solve`` writes the same columns for an exported file (``outputs``).
        """
        check_outputs(unknown, (), "table")
        header, rows = self._motion_table()
        blocks = [rows]
        if energy:
            header += list(ENERGY_COLUMNS)
            blocks.append(np.column_stack([self.kinetic, self.potential, self.energy,
                                           self.drift_position, self.drift_velocity]))
        names, cols = self._constraint_columns(self.lam,
                                               self._reactions()[0] if reactions else None,
                                               multipliers, efforts)
        header += names
        blocks += cols
        for k, (name, what) in enumerate(self.element_names):
            if what == "contact":
                words, idx = ("normal_force", "friction_force", "penetration",
                              "sliding_speed"), (0, 1, 2, 3)
            elif what == "friction":
                words, idx = ("normal_load", "friction_force", "sliding_speed"), (0, 1, 3)
            else:
                continue
            header += [f"{name}.{w}" for w in words]
            blocks.append(np.column_stack([self.elements[:, k, i] for i in idx]))
        names, cols = measure_columns(self, measures)
        header += names
        blocks += cols
        if sensitivities:
            names, cols = self._derivative_columns(multipliers, reactions, efforts, measures)
            header += names
            blocks += cols
        return header, np.hstack(blocks)

    def _constraint_columns(self, lam: np.ndarray, reac: np.ndarray | None, multipliers: bool,
                            efforts: bool) -> tuple[list[str], list[np.ndarray]]:
        p = self.packed
        return constraint_columns(p.constraint_names, p.driver_flags, p.row_owner,
                                  self.row_labels, lam, reac, multipliers, efforts)

    def _derivative_columns(self, multipliers: bool, reactions: bool, efforts: bool,
                            measures: Any = None) -> tuple[list[str], list[np.ndarray]]:
        """The sensitivity columns, parameter after parameter: the motion's, then (with
        the multipliers' sensitivities) those of the multiplier, reaction and effort
        columns asked for, then those of the measures."""
        lam_columns = self.dlam_dp is not None and (multipliers or reactions or efforts)
        if not lam_columns:
            return self._motion_derivatives("table", measures)
        dreac = self._reaction_dp_arrays()[0] if reactions else None
        meas = measure_derivative_columns(self, measures)
        names: list[str] = []
        blocks: list[np.ndarray] = []
        for k, prm in enumerate(self.parameter_names):
            mn, mb = self._motion_derivative(k, "table")
            cn, cb = self._constraint_columns(self.dlam_dp[:, :, k],
                                              None if dreac is None else dreac[..., k],
                                              multipliers, efforts)
            names += mn + derivative_names(cn, prm) + derivative_names(meas[0], prm)
            blocks += [mb] + cb + [meas[1][:, :, k]]
        return names, blocks

    def to_npz(self, path: str | Path, reactions: bool = False, efforts: bool = False,
               sensitivities: bool = False, measures: Any = None, **always: bool) -> None:
        """t, q, qd, qdd, the multipliers and energies, the force elements' outputs, and
        the names; with
        ``reactions=True`` also ``reactions`` (n, nc, 6: as the table's reaction columns)
        and with ``efforts=True`` ``efforts`` (n, n_drivers); after a run with
        ``sensitivities=[names]`` also ``dq_dp``, ``dqd_dp``, ``dqdd_dp``,
        ``parameter_names`` and (dynamics) ``dlam_dp`` (n, neq, n_params)."""
        check_outputs(always, ("energy", "multipliers"), "to_npz")
        extra = self._sensitivity_arrays(sensitivities, "to_npz")
        extra.update(self._measure_arrays(measures))
        if self.dlam_dp is not None:
            extra["dlam_dp"] = self.dlam_dp
        if reactions:
            extra["reactions"] = self._reactions()[0]
        if efforts:
            drivers = [n for n, d in zip(self.packed.constraint_names, self.packed.driver_flags)
                       if d]
            extra["efforts"] = np.column_stack([self.effort(n) for n in drivers]) if drivers \
                else np.zeros((len(self.t), 0))
            extra["driver_names"] = np.array(drivers)
        with writing(path, "to_npz") as p:
            np.savez(p, t=self.t, q=self.q, qd=self.qd, qdd=self.qdd, lam=self.lam,
                     kinetic=self.kinetic, potential=self.potential,
                     drift_position=self.drift_position, drift_velocity=self.drift_velocity,
                     coordinate_names=np.array(self.coordinate_names),
                     body_names=np.array(self.body_names), row_labels=np.array(self.row_labels),
                     elements=self.elements,
                     element_names=np.array([n for n, _ in self.element_names]), **extra)

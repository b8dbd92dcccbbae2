"""The frequency response about an equilibrium to design parameters varied harmonically."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import plots
from ..errors import ModelError
from ..validate import vector
from .columns import REACTION_WORDS
from .files import write_csv
from .modes import motion_settings, picture_amplitude
from .points import PointResult
from .reactions import Reaction, driver_row, driver_rows
from .sensitivities import reaction_dp_arrays, reaction_dp_of

COORDINATES = ("x", "y", "theta")


def _parts(h: np.ndarray) -> np.ndarray:
    """A complex (n, k) array as (n, 2 k) columns: re, im of each column in turn (+ 0.0: no
    -0.0, whose sign complex arithmetic does not keep)."""
    return np.stack([h.real, h.imag], axis=2).reshape(h.shape[0], 2 * h.shape[1]) + 0.0


@dataclass
class FrequencyResponseResult:
    """The steady response of the linearized motion about an equilibrium (drivers held at
    ``t``) to each input, a design parameter p varied as p0 + Re(P e^(i 2 pi f t)).

    ``response`` (n_frequencies, n_coordinates, n_inputs, complex) is H(f): the coordinates
    move as Re(H P e^(i 2 pi f t)), so ``abs(H)`` is the amplitude per unit amplitude of the
    input and ``np.angle(H)`` the phase (at f = 0, H is the statics sensitivity dq*/dp).
    ``frequencies`` in Hz, ``inputs`` the parameters' names; ``q``, ``lam``, ``stability``
    and ``residual`` are the equilibrium's, as :class:`StaticsResult`; ``lam_response``
    (n_frequencies, n_rows, n_inputs, complex) the multipliers' response, from which
    :meth:`reaction_response` gives the joints' dynamic loads.
    """

    t: float
    q: np.ndarray
    lam: np.ndarray
    stability: str
    residual: float
    frequencies: np.ndarray
    inputs: list[str]
    response: np.ndarray
    n_free: int
    body_names: list[str]
    coordinate_names: list[str]
    lam_response: Any = None
    ptab: Any = None
    model: Any = None
    packed: Any = None
    stats: dict = field(default_factory=dict)

    def _input(self, name: str | None) -> int:
        if name is None:
            if len(self.inputs) == 1:
                return 0
            raise ModelError(f"this response has {len(self.inputs)} inputs; name one of "
                             f"{', '.join(self.inputs)}", "frequency response")
        if name not in self.inputs:
            raise ModelError(f"no input {name!r}; the inputs are {', '.join(self.inputs)}",
                             "frequency response")
        return self.inputs.index(name)

    def _body(self, body: str) -> int:
        if body not in self.body_names:
            raise ModelError(f"no body {body!r}; bodies: {', '.join(self.body_names)}",
                             "frequency response")
        return self.body_names.index(body)

    def response_of(self, body: str, coordinate: str = "y", input: str | None = None
                    ) -> np.ndarray:
        """H(f) of one body coordinate ("x", "y" or "theta") to one input (n_frequencies,
        complex; the only input by default)."""
        if coordinate not in COORDINATES:
            raise ModelError(f"coordinate must be one of x, y, theta, not {coordinate!r}",
                             "frequency response")
        i = 3 * self._body(body) + COORDINATES.index(coordinate)
        return self.response[:, i, self._input(input)].copy()

    def point_response(self, body: str, s: Any, input: str | None = None) -> np.ndarray:
        """The response of a point fixed in a body (its body-frame coordinates s) to one
        input: (n_frequencies, 2) complex amplitudes of its global x and y, d r_P = d r_i +
        B(theta) s' d theta (:mod:`mbd2d.results.points`)."""
        sx, sy = vector(s, 2, "s", "point")
        j, i = self._input(input), 3 * self._body(body)
        level = np.tile(self.q[i:i + 3], (self.frequencies.size, 1))
        return PointResult.derivatives((sx, sy), [level],
                                       [self.response[:, i:i + 3, j:j + 1]])[0][:, :, 0]

    def reaction_response(self, name: str, input: str | None = None) -> Reaction:
        """The response of a joint's or driver's reaction to one input: a
        :class:`Reaction` whose arrays are complex amplitudes over the frequencies (the
        force on each body per unit amplitude of the input; ``abs`` the amplitude, e.g. the
        force transmitted to the ground, ``np.angle`` the phase). From the response of the
        coordinates and multipliers through the reactions' design derivatives (the input's
        own change of the joint, a moved pivot, counts once, in phase)."""
        g, loc = self._reactions(self._input(input))
        return reaction_dp_of(self.packed, self.model, name, g, loc)

    def effort_response(self, name: str, input: str | None = None) -> np.ndarray:
        """The response of what the driver called name supplies (-lambda of its row: its
        torque or force) to one input: (n_frequencies,) complex amplitudes per unit
        amplitude of the input (a sweep's ``effort_response``).

        Raises
        ------
        KeyError
            If there is no such driver.
        """
        row = driver_row(self.packed, name)
        if row is None:
            raise KeyError(f"no driver {name!r}")
        return -self.lam_response[:, row, self._input(input)]

    def _reactions(self, j: int) -> tuple[np.ndarray, np.ndarray]:
        """Every constraint's reaction response to input j, global and in the body frames:
        (n_frequencies, nc, 6) complex each. Re: the reactions' derivative along (Re H,
        Re dlambda) with the input's own term; Im: along (Im H, Im dlambda) without it."""
        nw = self.frequencies.size
        q, lam = np.tile(self.q, (nw, 1)), np.tile(self.lam, (nw, 1))
        t, ptab = np.full(nw, self.t), self.ptab[:, j:j + 1]
        hq, hl = self.response[:, :, j:j + 1], self.lam_response[:, :, j:j + 1]
        parts = [reaction_dp_arrays(self.packed, ptab, q, t, lam, hq.real, hl.real),
                 reaction_dp_arrays(self.packed, ptab, q, t, lam, hq.imag, hl.imag),
                 reaction_dp_arrays(self.packed, ptab, q[:1], t[:1], lam[:1],
                                    np.zeros_like(hq[:1].real), np.zeros_like(hl[:1].real))]
        (g_re, l_re), (g_im, l_im), (g_p, l_p) = parts     # g_p: the input's own term
        return (g_re + 1j * (g_im - g_p))[..., 0], (l_re + 1j * (l_im - l_p))[..., 0]

    def peak(self, body: str, coordinate: str = "y", input: str | None = None
             ) -> tuple[float, float]:
        """(frequency in Hz, |H|) where the magnitude of one coordinate's response is largest
        on the frequencies computed."""
        mag = np.abs(self.response_of(body, coordinate, input))
        k = int(np.argmax(mag)) if mag.size else 0
        return (float(self.frequencies[k]), float(mag[k])) if mag.size else (0.0, 0.0)

    def frequency_index(self, frequency: Any) -> int:
        """Index of the computed frequency nearest to ``frequency`` (Hz).

        Raises
        ------
        ModelError
            For a frequency that is not a finite number.
        """
        try:
            f = float(frequency)
        except (TypeError, ValueError):
            f = float("nan")
        if not np.isfinite(f):
            raise ModelError(f"frequency must be a finite number in Hz, got {frequency!r}",
                             "frequency response")
        return int(np.argmin(np.abs(self.frequencies - f)))

    def deflection(self, frequency: float, input: str | None = None,
                   amplitude: float | None = None, frames: int = 49) -> Any:
        """The operating deflection shape: the steady motion q = q* + Re(H a e^(i 2 pi f t))
        over one period at the computed frequency f nearest to ``frequency`` (Hz), for the
        input varied with amplitude a (default: the bodies' points move by about 15% of
        the mechanism's size), each coordinate at its own phase; at 0 Hz the static
        deflection a sin(2 pi t) H over 1 s. For the pictures (:func:`mbd2d.animate`,
        :func:`mbd2d.plot_mechanism`)."""
        j, k = self.frequency_index(frequency), self._input(input)
        amplitude, frames = motion_settings(amplitude, frames, "frequency response")
        h = self.response[j, :, k]
        a = picture_amplitude(self.q, np.abs(h), len(self.body_names)) \
            if amplitude is None else amplitude
        f = float(self.frequencies[j])
        period = 1.0 / f if f > 0 else 1.0
        t = np.linspace(0.0, period, frames)
        wave = np.exp(2j * np.pi * f * t) if f > 0 else np.sin(2 * np.pi * t) + 0j
        q = self.q[None, :] + a * (wave[:, None] * h[None, :]).real
        return plots.Configuration(self.model, q, t, note=f"{self.inputs[k]} at {f:.4g} Hz, "
                                   f"amplitude {a:.3g}")

    def animate(self, frequency: float, path: Any = None, input: str | None = None,
                amplitude: float | None = None, **kwargs: Any) -> Any:
        """The operating deflection shape at ``frequency`` (:meth:`deflection`) over one
        period, slowed to about 2 s: :func:`mbd2d.animate`."""
        mot = self.deflection(frequency, input, amplitude)
        kwargs.setdefault("speed", float(mot.t[-1]) / 2.0)
        kwargs.setdefault("title", f"{getattr(self.model, 'name', 'model')}: {mot.note}")
        return plots.animate(mot, path, **kwargs)

    def table(self, reactions: bool = False) -> tuple[list[str], np.ndarray]:
        """Header and rows of the CSV: one row per frequency, ``frequency_hz``, then for each
        input and body ``d(NAME.x)/d(INPUT).re``, ``d(NAME.x)/d(INPUT).im``, then y and
        theta, then each driver's effort ``d(effort.DRIVER)/d(INPUT).re``, ``.im``
        (:meth:`effort_response`; the columns of a frequency response sweep's CSV); with
        ``reactions=True`` after them every joint's and driver's reaction response
        ``d(JOINT.fx)/d(INPUT).re``, ``.im``, ... fy, mz, fx_j, fy_j, mz_j
        (:meth:`reaction_response`)."""
        nb, nw = len(self.body_names), self.frequencies.size
        rows_d, drivers = driver_rows(self.packed)
        header = ["frequency_hz"]
        blocks = [self.frequencies[:, None]]
        for j, name in enumerate(self.inputs):
            header += [f"d({b}.{c})/d({name}).{part}" for b in self.body_names
                       for c in COORDINATES for part in ("re", "im")]
            blocks.append(_parts(self.response[:, :3 * nb, j]))
            header += [f"d(effort.{d})/d({name}).{part}" for d in drivers
                       for part in ("re", "im")]
            blocks.append(_parts(-self.lam_response[:, rows_d, j]))
            if reactions:
                header += [f"d({c}.{w})/d({name}).{part}"
                           for c in self.packed.constraint_names for w in REACTION_WORDS
                           for part in ("re", "im")]
                blocks.append(_parts(self._reactions(j)[0].reshape(nw, -1)))
        return header, np.hstack(blocks).reshape(nw, len(header))

    def to_csv(self, path: Any, reactions: bool = False) -> None:
        """Write :meth:`table` as CSV, numbers as every mbd2d CSV."""
        header, rows = self.table(reactions=reactions)
        write_csv(path, header, rows, "to_csv")

    def summary(self) -> str:
        """A text table: for each input and body coordinate that moves, the peak amplitude
        and its frequency."""
        lines = [f"{getattr(self.model, 'name', 'model')}: frequency response about the "
                 f"equilibrium ({self.stability}) at t = {self.t:g}, {self.n_free} free "
                 f"motion(s), {self.frequencies.size} frequencies from "
                 f"{self.frequencies.min():g} to {self.frequencies.max():g} Hz"]
        scale = np.abs(self.response).max(initial=0.0)
        for name in self.inputs:
            lines.append(f"input {name}: {'coordinate':>18}  {'peak |H|':>12}  at f (Hz)")
            for b in self.body_names:
                for c in COORDINATES:
                    f, mag = self.peak(b, c, name)
                    if mag > 1e-12 * scale:
                        lines.append(f"{'':>8}{b + '.' + c:>20}  {mag:12.6g}  {f:.6g}")
        return "\n".join(lines)

    def plot(self, body: str, coordinates: Any = ("x", "y", "theta"), input: str | None = None,
             **kwargs: Any) -> Any:
        """A Bode plot of a body's coordinates' responses to one input: magnitude (log-log)
        over phase (:func:`mbd2d.plots.plot_bode`; returns the Figure)."""
        coords = [coordinates] if isinstance(coordinates, str) else list(coordinates)
        name = self.inputs[self._input(input)]
        hs = [self.response_of(body, c, name) for c in coords]
        kwargs.setdefault("title", f"{getattr(self.model, 'name', 'model')}: "
                          f"{body} per unit {name}")
        return plots.plot_bode(self.frequencies, hs, [f"{body}.{c}" for c in coords],
                               **kwargs)

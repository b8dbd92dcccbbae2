"""Small vibrations about an equilibrium: natural frequencies, damping and mode shapes."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import plots
from ..errors import ModelError
from ..validate import number, whole
from .files import write_csv

#: the core's kinds of modes (mbd_modes: |omega^2| at most 1e-9 of the largest is "rigid")
KINDS = {1: "vibration", 0: "rigid", -1: "unstable"}
#: a mode's picture moves the mechanism's points by about this fraction of its size
PICTURE_AMPLITUDE = 0.15


#: the most frames of a mode's or a response's motion
MAX_FRAMES = 100_000


def motion_settings(amplitude: Any, frames: Any, entry: str) -> tuple[float | None, int]:
    """A motion picture's amplitude (None: the default) and frame count, checked.

    Raises
    ------
    ModelError
        For an amplitude that is no finite number, or frames not a whole number in 3 ..
        MAX_FRAMES.
    """
    a = None if amplitude is None else number(amplitude, "amplitude", entry)
    return a, whole(frames, "frames", entry, 3, MAX_FRAMES)


def picture_amplitude(q: np.ndarray, phi: np.ndarray, n_bodies: int) -> float:
    """The factor a that moves the bodies' points by about PICTURE_AMPLITUDE of the
    mechanism's size at q when the coordinates change by a phi (phi: the changes' moduli);
    0 when phi moves nothing."""
    xy = q[:3 * n_bodies].reshape(n_bodies, 3)[:, :2]
    size = max(float(np.ptp(xy, axis=0).max(initial=0.0)),
               float(np.abs(xy).max(initial=0.0)), 1e-300)
    p = phi[:3 * n_bodies].reshape(n_bodies, 3)
    move = float((np.hypot(p[:, 0], p[:, 1]) + size * np.abs(p[:, 2])).max(initial=0.0))
    return PICTURE_AMPLITUDE * size / move if move > 0 else 0.0


@dataclass
class ModesResult:
    """The linearized motion about an equilibrium (drivers held at ``t``).

    ``omega2`` (n_modes,) are the undamped eigenvalues omega^2 (rad^2/s^2, ascending) of
    K_r v = omega^2 M_r v on the free motions, ``shapes`` (n_coordinates, n_modes) the mode
    shapes phi (phi^T M phi = 1, the largest entry positive); ``eigenvalues`` (2 n_modes,
    complex, by modulus) those of the damped first-order form, s = -zeta omega +-
    i omega sqrt(1 - zeta^2), and ``damped_shapes`` (n_coordinates, 2 n_modes, complex) their
    shapes psi, each scaled so that its largest entry is 1: the moduli and phases of the
    other entries are relative to it. ``n_free`` is the number of free motions (the modes past
    ``count`` were not asked for). ``q``, ``lam``, ``stability`` and ``residual`` are the
    equilibrium's, as :class:`StaticsResult`.
    """

    t: float
    q: np.ndarray
    lam: np.ndarray
    stability: str
    residual: float
    omega2: np.ndarray
    eigenvalues: np.ndarray
    shapes: np.ndarray
    damped_shapes: np.ndarray
    kind_codes: np.ndarray
    n_free: int
    body_names: list[str]
    coordinate_names: list[str]
    model: Any = None
    packed: Any = None
    stats: dict = field(default_factory=dict)

    @property
    def omega(self) -> np.ndarray:
        """Undamped natural angular frequencies (rad/s; 0 for a mode without stiffness or an
        unstable one, whose ``kinds`` entry says which)."""
        return np.sqrt(np.clip(self.omega2, 0.0, None))

    @property
    def frequency(self) -> np.ndarray:
        """Undamped natural frequencies in Hz (omega / 2 pi)."""
        return self.omega / (2 * np.pi)

    @property
    def kinds(self) -> list[str]:
        """Per mode: "vibration" (omega^2 > 0), "rigid" (no stiffness: a free motion; |omega^2|
        at most 1e-9 of the largest) or "unstable" (omega^2 < 0: the equilibrium is unstable
        along it)."""
        return [KINDS[int(c)] for c in self.kind_codes]

    @property
    def damping_ratio(self) -> np.ndarray:
        """zeta = -Re(s) / |s| of each damped eigenvalue (0 where s = 0)."""
        mod = self._modulus()
        zeta = np.divide(-self.eigenvalues.real, mod, out=np.zeros_like(mod), where=mod > 0)
        return zeta + 0.0               # (no -0.0)

    @property
    def damped_frequency(self) -> np.ndarray:
        """|Im(s)| / 2 pi of each damped eigenvalue (Hz; 0 for an overdamped one)."""
        return np.abs(self.eigenvalues.imag) / (2 * np.pi)

    def _modulus(self) -> np.ndarray:
        """|s| of each damped eigenvalue (hypot, as mbd2d-solve takes it)."""
        return np.hypot(self.eigenvalues.real, self.eigenvalues.imag)

    def _mode(self, k: int, damped: bool = False) -> int:
        n = self.eigenvalues.size if damped else self.omega2.size
        what = "damped eigenvalue" if damped else "mode"
        if not isinstance(k, (int, np.integer)) or isinstance(k, bool) or not -n <= k < n:
            has = f"{n} {what}(s), 0 .. {n - 1}" if n else f"no {what}s (no free motion)"
            raise ModelError(f"{what} {k!r} does not exist: this result has {has}", "modes")
        return int(k) % n

    def shape(self, k: int) -> np.ndarray:
        """The shape phi of mode k (n_coordinates), mass-normalized."""
        return self.shapes[:, self._mode(k)].copy()

    def damped_shape(self, j: int) -> np.ndarray:
        """The complex shape psi of damped eigenvalue j (n_coordinates), its largest entry 1:
        ``abs`` gives each coordinate's amplitude relative to it, ``np.angle`` its phase
        (a motion Re(psi e^(s t)); a real eigenvalue has a real shape)."""
        return self.damped_shapes[:, self._mode(j, damped=True)].copy()

    def body_shape(self, k: int, body: str) -> tuple[float, float, float]:
        """(x, y, theta) of a body in mode k's shape (KeyError if there is no such body)."""
        if body not in self.body_names:
            raise KeyError(f"no body {body!r}; bodies: {', '.join(self.body_names)}")
        i = self.body_names.index(body)
        return tuple(float(v) for v in self.shape(k)[3 * i:3 * i + 3])  # type: ignore

    def table(self, damped: bool = False) -> tuple[list[str], np.ndarray]:
        """Header and rows of the CSV: one row per mode (``mode``, ``omega2``,
        ``frequency_hz``, ``kind`` (1 vibration, 0 rigid, -1 unstable), then the shape,
        ``NAME.x``, ``NAME.y``, ``NAME.theta`` per body); with ``damped=True`` one row per
        damped eigenvalue (``s_real``, ``s_imag``, ``frequency_hz`` = |s| / 2 pi,
        ``damped_frequency_hz``, ``damping_ratio``, then its complex shape, ``NAME.x.re``,
        ``NAME.x.im``, ``NAME.y.re``, ... per body)."""
        nb = len(self.body_names)
        if damped:
            s = self.eigenvalues
            header = ["s_real", "s_imag", "frequency_hz", "damped_frequency_hz",
                      "damping_ratio"]
            header += [f"{b}.{c}.{part}" for b in self.body_names for c in ("x", "y", "theta")
                       for part in ("re", "im")]
            psi = self.damped_shapes[:3 * nb].T
            parts = np.stack([psi.real, psi.imag], axis=2).reshape(s.size, 6 * nb)
            rows = np.column_stack([s.real, s.imag, self._modulus() / (2 * np.pi),
                                    self.damped_frequency, self.damping_ratio, parts])
            return header, rows.reshape(s.size, len(header))
        header = ["mode", "omega2", "frequency_hz", "kind"]
        header += [f"{b}.{c}" for b in self.body_names for c in ("x", "y", "theta")]
        rows = np.column_stack([np.arange(self.omega2.size), self.omega2, self.frequency,
                                self.kind_codes, self.shapes[:3 * nb].T])
        return header, rows.reshape(self.omega2.size, len(header))

    def to_csv(self, path: Any, damped: bool = False) -> None:
        """Write :meth:`table` as CSV, numbers as every mbd2d CSV."""
        header, rows = self.table(damped=damped)
        write_csv(path, header, rows, "to_csv")

    def summary(self) -> str:
        """A text table of the modes (and of the damped eigenvalues when any is damped)."""
        lines = [f"{getattr(self.model, 'name', 'model')}: {self.n_free} free motion(s), "
                 f"equilibrium {self.stability} at t = {self.t:g}",
                 f"{'mode':>4}  {'f (Hz)':>12}  {'omega (rad/s)':>14}  kind"]
        for k, kind in enumerate(self.kinds):
            lines.append(f"{k:>4}  {self.frequency[k]:12.6g}  {self.omega[k]:14.6g}  {kind}")
        if np.any(self.eigenvalues.real != 0.0):
            lines.append(f"{'':>4}  {'s (1/s)':>26}  {'zeta':>9}  {'f_d (Hz)':>10}")
            for s, z, f in zip(self.eigenvalues, self.damping_ratio, self.damped_frequency):
                lines.append(f"{'':>4}  {s.real:12.6g} {s.imag:+12.6g}i  {z:9.4g}  {f:10.6g}")
        return "\n".join(lines)

    def motion(self, k: int = 0, amplitude: float | None = None, frames: int = 49,
               damped: bool = False) -> Any:
        """Mode k as a motion for the pictures: q = q* + a sin(omega t) phi over one period
        (1 s for a mode without a frequency), the linearized motion. ``amplitude`` a
        multiplies the mass-normalized shape; by default the points move by about 15% of
        the mechanism's size. With ``damped=True``, k is a damped eigenvalue s and the
        motion q* + a Re(psi e^(i Im(s) t)) over one damped period: each coordinate at its
        own phase, the decay e^(Re(s) t) left out so that the shape stays in view (a real
        s: a sin(2 pi t) psi over 1 s)."""
        k = self._mode(k, damped)
        amplitude, frames = motion_settings(amplitude, frames, "modes")
        shape = self.damped_shapes[:, k] if damped else self.shapes[:, k].astype(complex)
        a = picture_amplitude(self.q, np.abs(shape), len(self.body_names)) \
            if amplitude is None else amplitude
        w = abs(self.eigenvalues[k].imag) if damped else self.omega[k]
        period = 2 * np.pi / w if w > 0 else 1.0
        t = np.linspace(0.0, period, frames)
        if damped and w > 0:
            wave = np.exp(1j * self.eigenvalues[k].imag * t)
        else:
            wave = np.sin(2 * np.pi * t / period) + 0j
        q = self.q[None, :] + a * (wave[:, None] * shape[None, :]).real
        return plots.Configuration(self.model, q, t, note=self._label(k, damped))

    def _label(self, k: int, damped: bool) -> str:
        """mode k or damped eigenvalue k, with its frequency (and kind or damping ratio)."""
        if damped:
            return (f"damped mode {k}, {self.damped_frequency[k]:.4g} Hz, "
                    f"zeta {self.damping_ratio[k]:.3g}")
        return f"mode {k}, {self.frequency[k]:.4g} Hz ({self.kinds[k]})"

    def plot(self, k: int = 0, amplitude: float | None = None, damped: bool = False,
             **kwargs: Any) -> Any:
        """The mechanism at the equilibrium and at both extremes of mode k (``damped=True``:
        at a quarter and three quarters of damped mode k's period):
        :func:`mbd2d.plot_mechanism` (returns the Axes)."""
        mot = self.motion(k, amplitude, damped=damped)
        period = float(mot.t[-1])
        kwargs.setdefault("title", f"{getattr(self.model, 'name', 'model')}: "
                          f"{self._label(self._mode(k, damped), damped)}")
        kwargs.setdefault("times", [0.0, 0.75 * period, 0.25 * period])   # equilibrium lightest
        return plots.plot_mechanism(mot, **kwargs)

    def animate(self, k: int = 0, path: Any = None, amplitude: float | None = None,
                damped: bool = False, **kwargs: Any) -> Any:
        """Mode k (``damped=True``: damped mode k) moving over one period, slowed to about
        2 s: :func:`mbd2d.animate`."""
        mot = self.motion(k, amplitude, damped=damped)
        kwargs.setdefault("speed", float(mot.t[-1]) / 2.0)
        kwargs.setdefault("title", self._label(self._mode(k, damped), damped))
        return plots.animate(mot, path, **kwargs)

"""Animations of a run: GIF (Pillow), MP4 (ffmpeg, when installed) or an inline animation for
Jupyter.

The figure is drawn once without the moving parts (axes, ground, paths, legend); each frame
restores that background and draws only the moving artists (blitting), so a frame costs a
few milliseconds whatever the figure holds.
"""
from __future__ import annotations

import base64
import io
import shutil
import subprocess
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import ModelError
from ..validate import number
from .canvas import add_legend, new_figure
from .elements import Look
from .geometry import Motion, TracePoint, frame_rows
from .scene import Scene

#: file suffixes that can be written
SUFFIXES = (".gif", ".mp4")


class InlineAnimation:
    """An animation for notebooks: an animated GIF embedded in HTML (Jupyter shows it through
    ``_repr_html_``); ``.gif`` holds the GIF bytes, ``.save(path)`` writes them."""

    def __init__(self, gif: bytes, frames: int) -> None:
        self.gif = gif
        self.frames = frames

    @property
    def html(self) -> str:
        data = base64.b64encode(self.gif).decode("ascii")
        return f'<img src="data:image/gif;base64,{data}" alt="mbd2d animation"/>'

    def _repr_html_(self) -> str:
        return self.html

    def save(self, path: str | Path) -> str:
        """Write the GIF."""
        try:
            Path(str(path)).write_bytes(self.gif)
        except OSError as exc:
            raise ModelError(f"cannot write {str(path)!r}: {exc.strerror or exc}",
                             "animate") from None
        return str(path)

    def __repr__(self) -> str:
        return f"InlineAnimation({self.frames} frames, GIF of {len(self.gif)} bytes)"


def ffmpeg_available() -> bool:
    """Whether an ffmpeg executable is on the PATH (for MP4)."""
    return shutil.which("ffmpeg") is not None


def _settings(fps: Any, speed: Any, max_frames: Any, dpi: Any) -> tuple[float, float, int, int]:
    fps_v = number(fps, "fps", "animate")
    speed_v = number(speed, "speed", "animate")
    if not 0.1 <= fps_v <= 120:
        raise ModelError(f"fps must be from 0.1 to 120, got {fps!r}", "animate")
    if not 1e-9 <= speed_v <= 1e9:
        raise ModelError(f"speed (run time per second of animation) must be from 1e-9 to 1e9,"
                         f" got {speed!r}", "animate")
    for name, v, lo, hi in (("max_frames", max_frames, 2, 10000), ("dpi", dpi, 10, 600)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
            raise ModelError(f"{name} must be a whole number from {lo} to {hi}, got {v!r}",
                             "animate")
    return fps_v, speed_v, int(max_frames), int(dpi)


def _size(size: Any) -> tuple[float, float]:
    try:
        w, h = (float(v) for v in size)
    except (TypeError, ValueError):
        raise ModelError(f"size must be (width, height) in inches, got {size!r}",
                         "animate") from None
    if not (0.5 <= w <= 40 and 0.5 <= h <= 40):
        raise ModelError(f"size must be from 0.5 to 40 inches each way, got {size!r}",
                         "animate")
    return w, h


def render_frames(result: Motion, fps: float = 30, trace: Sequence[TracePoint] | None = None,
                  forces: bool = False, speed: float = 1.0, max_frames: int = 300,
                  size: tuple[float, float] = (6.4, 5.0), dpi: int = 80,
                  title: str | None = None, length_unit: str = "m") -> list[np.ndarray]:
    """The frames of an animation as RGB arrays (height, width, 3); arguments as
    :func:`animate`."""
    fps_v, speed_v, max_frames, dpi = _settings(fps, speed, max_frames, dpi)
    scene = Scene(result, trace, forces, what="animate")
    rows = frame_rows(result, fps_v, speed_v, max_frames)
    fig = new_figure(_size(size))
    fig.set_dpi(dpi)
    ax = fig.add_subplot()
    scene.draw_fixed(ax)
    before = set(ax.get_children())
    update = scene.make(ax, Look(scene.colour, 0.3, 2.0, True))
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, ha="left", va="top", fontsize=9,
                    family="monospace", zorder=20)
    # drawn as the Axes would: by zorder, in the order made within one
    moving = sorted((a for a in ax.get_children() if a not in before), key=_zorder)
    update(int(rows[0]))
    (xl, yl) = scene.limits()
    scene.dress(ax, length_unit, scene.model.name if title is None else title)
    ax.set_xlim(*xl)
    ax.set_ylim(*yl)
    ax.set_aspect("equal", adjustable="box")
    add_legend(ax, loc="upper right", fontsize=7, framealpha=0.85)
    for a in moving:
        a.set_animated(True)
    canvas = fig.canvas
    canvas.draw()                           # the background, with the layout done once
    fig.set_layout_engine("none")
    background = canvas.copy_from_bbox(fig.bbox)
    t = result.t
    frames = []
    for r in rows:
        update(int(r))
        clock.set_text(f"t = {t[int(r)]:.4f} s")
        canvas.restore_region(background)
        for a in moving:
            ax.draw_artist(a)
        frames.append(np.asarray(canvas.buffer_rgba())[:, :, :3].copy())
    return frames


def _zorder(a: Any) -> float:
    return float(a.get_zorder())


def gif_bytes(frames: list[np.ndarray], fps: float) -> bytes:
    """An animated GIF (looping) of RGB frames, written by Pillow."""
    from PIL import Image

    images = [Image.fromarray(f).quantize(colors=128, method=Image.Quantize.MEDIANCUT,
                                          dither=Image.Dither.NONE) for f in frames]
    buf = io.BytesIO()
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:],
                   duration=max(20, int(round(1000.0 / fps))), loop=0, disposal=1)
    return buf.getvalue()


def write_mp4(frames: list[np.ndarray], fps: float, path: str) -> None:
    """An H.264 MP4 of RGB frames through ffmpeg (raw frames on its standard input)."""
    h, w, _ = frames[0].shape
    cmd = [shutil.which("ffmpeg") or "ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo",
           "-pix_fmt", "rgb24", "-s", f"{w}x{h}", "-r", f"{fps:g}", "-i", "-",
           "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-vcodec",
           "libx264", path]
    proc = subprocess.run(cmd, input=b"".join(f.tobytes() for f in frames),
                          capture_output=True, timeout=600)
    if proc.returncode != 0:
        raise ModelError(f"ffmpeg could not write {path!r}: "
                         f"{proc.stderr.decode(errors='replace').strip()[:300]}", "animate")


def animate(result: Motion, path: str | Path | None = None, fps: float = 30,
            trace: Sequence[TracePoint] | None = None, forces: bool = False,
            speed: float = 1.0, max_frames: int = 300, size: tuple[float, float] = (6.4, 5.0),
            dpi: int = 80, title: str | None = None, length_unit: str = "m") -> Any:
    """Animate a run.

    Parameters
    ----------
    result : KinematicsResult or DynamicsResult
        The run (with its model).
    path : str or pathlib.Path, optional
        ``.gif`` (written with Pillow) or ``.mp4`` (needs ffmpeg on the PATH). Without a
        path, an :class:`InlineAnimation` is returned, which Jupyter shows inline.
    fps : float
        Frames per second of the animation (default 30).
    trace : sequence of (str, (float, float)), optional
        Body points whose paths are drawn.
    forces : bool
        Also draw the joints' reaction forces as arrows (results with multipliers).
    speed : float
        Seconds of the run per second of animation (default 1: real time; 0.25 is slow
        motion). The frames show the output rows nearest to their times.
    max_frames : int
        At most this many frames (evenly spaced over the run; default 300).
    size : (float, float)
        Figure size in inches (default 6.4 x 5).
    dpi : int
        Dots per inch (default 80: 512 x 400 pixels).
    title : str, optional
        Title (default: the model's name); the time is shown in the corner.
    length_unit : str
        Unit of length for the axis labels (default "m").

    Returns
    -------
    str or InlineAnimation
        The path written, or the inline animation.

    Raises
    ------
    ModelError
        If the suffix is not .gif or .mp4, ffmpeg is missing for .mp4, a setting is out of
        range, or the path cannot be written.

    Examples
    --------
    >>> import mbd2d
    >>> res = mbd2d.load("examples/fourbar_grashof.toml").kinematics(t_end=1.0, steps=60)
    >>> res.animate("/tmp/fourbar.gif", fps=15, trace=[("coupler", (0.0, 1.0))])
    '/tmp/fourbar.gif'
    """
    suffix = None
    if path is not None:
        if not isinstance(path, (str, Path)):
            raise ModelError(f"path must be a str or pathlib.Path, got {path!r}", "animate")
        suffix = Path(str(path)).suffix.lower()
        if suffix not in SUFFIXES:
            raise ModelError(f"the animation file must end in .gif or .mp4, got {str(path)!r}",
                             "animate")
        if suffix == ".mp4" and not ffmpeg_available():
            raise ModelError("writing .mp4 needs ffmpeg on the PATH (apt-get install ffmpeg);"
                             " write a .gif instead", "animate")
    frames = render_frames(result, fps, trace, forces, speed, max_frames, size, dpi, title,
                           length_unit)
    fps_v = float(fps)
    if path is None:
        return InlineAnimation(gif_bytes(frames, fps_v), len(frames))
    target = str(path)
    try:
        Path(target).parent.mkdir(parents=True, exist_ok=True)
        if suffix == ".mp4":
            write_mp4(frames, fps_v, target)
        else:
            Path(target).write_bytes(gif_bytes(frames, fps_v))
    except OSError as exc:
        raise ModelError(f"cannot write {target!r}: {exc.strerror or exc}", "animate") from None
    return target

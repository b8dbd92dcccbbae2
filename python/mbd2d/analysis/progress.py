"""A progress bar for long analyses, without slowing their loop.

The core runs the whole analysis in one call, as always, on a worker thread (the f2py call
releases the GIL). While it runs, the core writes the number of outputs done into a small
shared array (one integer store per output) and reads a stop flag from it; this thread reads
the count a few times a second and moves a tqdm bar. The results are those of the same
single call without a bar, bit for bit. Ctrl-C sets the stop flag: the core stops after its
next step and the KeyboardInterrupt is raised here.

``progress=None`` (the default) shows the bar only for a run that lasts longer than
:data:`DELAY` seconds, on a terminal or in a notebook; ``True`` shows it from the start;
``False`` makes the plain call (no thread).
"""
from __future__ import annotations

import sys
import threading
import time
from typing import Any, Callable

import numpy as np

from ..binding.core import new_ctl
from ..errors import ModelError

#: a run longer than this (seconds) shows its bar (progress=None)
DELAY = 2.0
#: runs smaller than this (output rows x numbers per row) make the plain call with
#: progress=None: they end well within DELAY
SMALL_WORK = 2.0e5
#: seconds between two reads of the count
POLL = 0.1


def _bar(total: int, label: str) -> Any:
    """A tqdm bar, or None when tqdm is missing."""
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(total=total, desc=label, unit="out", leave=False, dynamic_ncols=True,
                mininterval=POLL)


def _interactive() -> bool:
    """A terminal or a notebook is watching."""
    if "ipykernel" in sys.modules:
        return True
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):
        return False


def run_core(call: Callable[[np.ndarray], Any], total: int, label: str, progress: Any,
             work: float) -> Any:
    """``call(ctl)`` (one core call sharing the progress array ctl), with a progress bar.

    Parameters
    ----------
    call : callable
        Makes the core call with the given progress array.
    total : int
        The count ctl[0] reaches at the end.
    label : str
        The bar's description.
    progress : bool or None
        True: a bar from the start; False: the plain call; None: a bar when the run lasts
        longer than DELAY seconds and someone is watching (a terminal, a notebook).
    work : float
        Rough size of the run (output rows x numbers per row), for progress=None.

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C, after the core has stopped at its next step.
    """
    if progress is not None and not isinstance(progress, bool):
        raise ModelError(f"progress must be True, False or None, got {progress!r}", "progress")
    ctl = new_ctl()
    if progress is False or (progress is None and (work < SMALL_WORK or not _interactive())):
        return call(ctl)
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["out"] = call(ctl)
        except BaseException as exc:      # handed to the caller's thread below
            box["exc"] = exc

    worker = threading.Thread(target=target, name="mbd2d-core", daemon=True)
    start = time.monotonic()
    worker.start()
    bar = _bar(total, label) if progress is True else None
    try:
        alive = True
        while alive:
            worker.join(POLL)
            alive = worker.is_alive()
            if bar is None and alive and time.monotonic() - start >= DELAY:
                bar = _bar(total, label)
            if bar is not None:
                bar.update(max(0, min(int(ctl[0]), total) - bar.n))
    except KeyboardInterrupt:
        ctl[1] = 1                        # the core stops at its next step
        worker.join()
        raise
    finally:
        if bar is not None:
            bar.close()
    if "exc" in box:
        raise box["exc"]
    return box["out"]

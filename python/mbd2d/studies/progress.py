"""A progress bar of cases done (tqdm, an optional package), shown on sweeps that take more
than a couple of seconds."""
from __future__ import annotations

from typing import Any

from ..errors import ModelError

#: a bar appears once a sweep has run this long [s] (progress=None)
DELAY = 2.0


class _NoBar:
    """Stands in for a bar: counts nothing, shows nothing."""

    def update(self, n: int = 1) -> None:
        pass

    def __enter__(self) -> "_NoBar":
        return self

    def __exit__(self, *exc: Any) -> None:
        pass


def progress_bar(total: int, progress: Any = None, desc: str = "sweep") -> Any:
    """A context manager with ``update(n)``: a tqdm bar on stderr, or nothing.

    Parameters
    ----------
    progress : bool or None
        True: always a bar; False: never; None: a bar that appears after 2 s (none when
        tqdm is not installed).

    Raises
    ------
    ImportError
        For progress=True without tqdm.
    """
    if progress is not None and not isinstance(progress, bool):
        raise ModelError(f"progress must be True, False or None, got {progress!r}", desc)
    if progress is False:
        return _NoBar()
    try:
        from tqdm import tqdm
    except ImportError:
        if progress:
            raise ImportError("progress=True needs the package 'tqdm': pip install "
                              "'mbd2d[sweep]'") from None
        return _NoBar()

    class Bar(tqdm):  # type: ignore[misc, valid-type]
        monitor_interval = 0     # no monitor thread (worker processes are forked)

    return Bar(total=total, desc=desc, unit="case", delay=0.0 if progress else DELAY,
               leave=False)


__all__ = ["progress_bar", "DELAY"]

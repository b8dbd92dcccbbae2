"""Result files: written through one guard (a path that cannot be written is a ModelError
naming it), and read back."""
from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..errors import ModelError


@contextmanager
def writing(path: Any, what: str) -> Iterator[Path]:
    """The path to write, checked; an OSError while writing becomes a ModelError."""
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"the output file must be a path (str or pathlib.Path), got {path!r}",
                         what)
    try:
        yield Path(path)
    except OSError as exc:
        raise ModelError(f"cannot write {str(path)!r}: {exc.strerror or exc}", what) from None


def write_text(path: Any, text: str, what: str) -> None:
    """Write a text file through :func:`writing`."""
    with writing(path, what) as p:
        p.write_text(text)


def read_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a result CSV back: (header, rows)."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, rows

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


#: The number format of every CSV mbd2d writes (Python here, and mbd2d-solve): 17 significant
#: digits, so a number read back is the number written: -1.2345678901234567e+00.
CSV_FORMAT = "%.16e"

#: Optional columns of a result's table (see DynamicsResult.table).
OUTPUTS = ("energy", "multipliers", "reactions", "efforts")


def write_csv(path: Any, header: list[str], rows: np.ndarray, what: str) -> None:
    """Write a table as CSV: the header line, then one line per row in CSV_FORMAT."""
    with writing(path, what) as p:
        np.savetxt(p, np.atleast_2d(rows), delimiter=",", header=",".join(header),
                   comments="", fmt=CSV_FORMAT)


def check_outputs(options: dict[str, Any], allowed: tuple[str, ...], what: str) -> dict[str, bool]:
    """The optional columns asked for, checked: only known names, and only those the result
    can give."""
    unknown = sorted(set(options) - set(OUTPUTS))
    if unknown:
        raise ModelError(f"unknown output {unknown[0]!r}; the optional columns are "
                         f"{', '.join(OUTPUTS)}", what)
    asked = {k: bool(v) for k, v in options.items()}
    missing = [k for k, v in asked.items() if v and k not in allowed]
    if missing:
        raise ModelError(f"{', '.join(missing)} need multipliers: run inverse dynamics, "
                         "dynamics, or kinematics of a model with masses", what)
    return asked


def read_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a result CSV back: (header, rows)."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, rows

"""Result files read back."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def read_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a result CSV back: (header, rows)."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, rows

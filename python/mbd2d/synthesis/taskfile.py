"""Synthesis task files (TOML), the input of ``mbd2d synthesize TASK.toml --out best.toml``::

    model = "fourbar_start.toml"      # the starting model, relative to this file
    free = ["joint.A.points.0.0", "joint.B.points.0.0", "path.point.0", "path.point.1"]
    starts = 8                        # optional: local solves (default 8)
    seed = 0                          # optional: Latin-hypercube seed

    [bounds]                          # required for every free model parameter when starts > 1
    "joint.A.points.0.0" = [0.2, 2.0]

    [task]
    type = "path"                     # path | motion | function
    body = "coupler"
    point = [1.0, 0.5]
    targets = [[1.0, 2.0], [1.5, 2.2], [2.0, 2.3]]
    times = [0.0, 0.5, 1.0]           # optional (free timing without it)

    [[constraint]]
    type = "grashof"                  # grashof | link-ratio | transmission-angle | peak-effort
                                      # | measure (measure = "SPEC", min, max)
    kind = "crank-rocker"

The keys of [task] and [[constraint]] are the arguments of :class:`PathTask`,
:class:`MotionTask`, :class:`FunctionTask` and of the constraint classes.
"""
from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..errors import ModelError
from ..model import Model, load
from .tasks import Task, make_task
from .terms import Term, make_term

TOP_KEYS = {"model", "free", "starts", "seed", "bounds", "task", "constraint", "max_nfev",
            "resolution", "t_ref"}


@dataclass
class TaskFile:
    """A parsed task file: the starting model and the arguments of :func:`synthesize`."""

    model: Model
    free: list[str]
    task: Task
    bounds: dict[str, tuple[float, float]] = field(default_factory=dict)
    constraints: list[Term] = field(default_factory=list)
    options: dict[str, Any] = field(default_factory=dict)


def load_task(path: str | Path) -> TaskFile:
    """Read a synthesis task file.

    Raises
    ------
    ModelError
        If the file or its model cannot be read, or a key is unknown or malformed (the
        message names it).
    """
    p, data = read_toml(path, "task file", "synthesize")
    return task_from_dict(data, p.parent, str(p))


def read_toml(path: Any, what: str, entry: str) -> tuple[Path, dict[str, Any]]:
    """A TOML file's path and contents; a ModelError naming ``what`` (e.g. "task file") when
    it cannot be read or parsed."""
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"the {what} must be a path, got {path!r}", entry)
    p = Path(path)
    try:
        return p, tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ModelError(f"cannot read the {what}: {exc.strerror}", str(p)) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ModelError(f"not a valid TOML {what}: {exc}", str(p)) from None


def task_from_dict(data: Mapping[str, Any], base: Path, source: str) -> TaskFile:
    """A task file's parsed TOML; model paths are relative to ``base``."""
    unknown = set(data) - TOP_KEYS
    if unknown:
        raise ModelError(f"unknown key(s) {sorted(unknown)}; keys: {', '.join(sorted(TOP_KEYS))}",
                         source)
    for key in ("model", "free", "task"):
        if key not in data:
            raise ModelError(f"missing key {key!r}", source)
    if not isinstance(data["model"], str):
        raise ModelError("model must be the path of a model file", source)
    model = load(base / data["model"])
    free = data["free"]
    if not isinstance(free, list) or not all(isinstance(n, str) for n in free):
        raise ModelError("free must be a list of parameter names", source)
    spec = data["task"]
    if not isinstance(spec, Mapping) or "type" not in spec:
        raise ModelError("[task] needs type = 'path', 'motion' or 'function'", source)
    keys = {k: v for k, v in spec.items() if k != "type"}
    task = make_task(str(spec["type"]), **keys)
    bounds_in = data.get("bounds", {})
    if not isinstance(bounds_in, Mapping):
        raise ModelError("[bounds] must be a table name = [lo, hi]", source)
    bounds = {str(k): tuple(v) if isinstance(v, list) else v for k, v in bounds_in.items()}
    cons_in = data.get("constraint", [])
    if isinstance(cons_in, Mapping) or not isinstance(cons_in, list):
        raise ModelError("write [[constraint]] (an array of tables)", source)
    constraints = []
    for c in cons_in:
        if not isinstance(c, Mapping) or "type" not in c:
            raise ModelError("each [[constraint]] needs a type", source)
        constraints.append(make_term(str(c["type"]),
                                     **{k: v for k, v in c.items() if k != "type"}))
    options = {k: data[k] for k in ("starts", "seed", "max_nfev", "resolution", "t_ref")
               if k in data}
    return TaskFile(model, list(free), task, bounds, constraints, options)


__all__ = ["TaskFile", "load_task", "task_from_dict"]

"""Running a batch in chunks of cases: in this process, in a pool of worker processes on all
cores, or on a Dask cluster (futures gathered in case order). Every chunk is one core call
(:func:`mbd2d.binding.core.batch`) and every case is computed alone, so the results do not
depend on how the cases were split or where they ran: they are identical bit for bit.
"""
from __future__ import annotations

import math
import multiprocessing
import os
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any

import numpy as np

from ..binding import core
from ..binding.core import NINFO
from ..binding.tables import BatchTables
from ..errors import CoreError, ModelError
from ..validate import whole
from .progress import progress_bar

#: cases of the first chunk run in this process (the cost of a case is measured on them)
FIRST_CHUNK = 4
#: time run in this process before a process pool may take over [s]
PROBE_SECONDS = 0.2
#: estimated time of the remaining cases above which a process pool is started [s]
POOL_MIN_SECONDS = 1.0
#: chunks per worker (a pool or a Dask cluster): small enough to balance the load
CHUNKS_PER_WORKER = 4
#: length of a chunk run in this process [s] (progress updates)
SERIAL_CHUNK_SECONDS = 0.25

#: arrays of the core's batch output with the case along the last axis
CASE_ARRAYS = ("q", "qd", "qdd", "lam", "e", "iinfo", "rinfo", "qsing", "dep", "red", "m",
               "mbad", "sq", "sqd", "sqdd", "slam", "dm")


def cores() -> int:
    """CPU cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


class Outputs:
    """The whole batch's output arrays, filled chunk by chunk."""

    def __init__(self, b: BatchTables, ncase: int) -> None:
        nq, nr = b.nq, b.nrow
        shapes = {"q": (nq, nr), "qd": (nq, b.nd), "qdd": (nq, b.nd), "lam": (b.nlam, nr),
                  "e": (b.ne, nr), "iinfo": (NINFO,), "rinfo": (NINFO,), "qsing": (nq,),
                  "dep": (b.neq,), "red": (b.neq,), "m": (len(b.measures.specs), nr),
                  "mbad": (3,), "sq": (nq, b.npar, nr), "sqd": (nq, b.npar, nr),
                  "sqdd": (nq, b.npar, nr), "slam": (b.nsl, b.npar, nr),
                  "dm": (len(b.measures.specs), b.npar, nr)}
        ints = ("iinfo", "dep", "red", "mbad")
        self.arrays = {k: np.zeros(s + (ncase,), order="F",
                                   dtype=np.int32 if k in ints else np.float64)
                       for k, s in shapes.items()}
        self.status = np.zeros(ncase, dtype=np.int32)
        self.msg = [""] * ncase

    def store(self, lo: int, out: dict[str, Any]) -> int:
        """Put one chunk's outputs at cases lo, lo + 1, ...; its number of cases."""
        status = np.atleast_1d(out["status"])
        hi = lo + len(status)
        for k in CASE_ARRAYS:
            self.arrays[k][..., lo:hi] = out[k]
        self.status[lo:hi] = status
        self.msg[lo:hi] = list(out["msg"])
        return len(status)


def chunks(lo: int, hi: int, parts: int) -> list[tuple[int, int]]:
    """[lo, hi) in at most parts nearly equal contiguous pieces."""
    n = hi - lo
    if n <= 0:
        return []
    size = math.ceil(n / max(1, min(parts, n)))
    return [(a, min(a + size, hi)) for a in range(lo, hi, size)]


def run(b: BatchTables, vals: np.ndarray, client: Any = None, workers: Any = None,
        progress: Any = None) -> Outputs:
    """Every case (column) of vals through the batch b.

    Parameters
    ----------
    client : distributed.Client, optional
        Run the chunks on its cluster.
    workers : int, optional
        Local worker processes (default: every core); 1 runs in this process.
    progress : bool, optional
        A progress bar (tqdm): None shows one when the sweep takes more than 2 s.
    """
    ncase = vals.shape[1]
    out = Outputs(b, ncase)
    with progress_bar(ncase, progress) as bar:
        if client is not None:
            _dask(b, vals, client, out, bar)
        else:
            nw = cores() if workers is None else whole(workers, "workers", "sweep", 1, 4096)
            _local(b, vals, nw, out, bar)
    return out


def _local(b: BatchTables, vals: np.ndarray, workers: int, out: Outputs, bar: Any) -> None:
    """Chunks here, timed; once they have run PROBE_SECONDS, the rest goes to a process pool
    when it would take more than POOL_MIN_SECONDS here."""
    n = vals.shape[1]
    t0 = time.perf_counter()
    done, size = 0, FIRST_CHUNK
    while done < n:
        hi = min(n, done + size)
        bar.update(out.store(done, core.batch(b, vals[:, done:hi])))
        done = hi
        elapsed = time.perf_counter() - t0
        per_case = max(elapsed / done, 1e-7)
        if (workers > 1 and done < n and elapsed >= PROBE_SECONDS
                and per_case * (n - done) > POOL_MIN_SECONDS):
            _pool(b, vals, done, workers, out, bar)
            return
        size = max(1, int(SERIAL_CHUNK_SECONDS / per_case))


def _context() -> Any:
    """fork when this process runs no other thread (cheap and safe), else spawn."""
    if threading.active_count() == 1 and "fork" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("spawn")


def _pool(b: BatchTables, vals: np.ndarray, lo: int, workers: int, out: Outputs,
          bar: Any) -> None:
    parts = chunks(lo, vals.shape[1], CHUNKS_PER_WORKER * workers)
    try:
        with ProcessPoolExecutor(max_workers=min(workers, len(parts)),
                                 mp_context=_context()) as ex:
            futures = {ex.submit(core.batch, b, vals[:, a:z]): a for a, z in parts}
            for f in as_completed(futures):
                bar.update(out.store(futures[f], f.result()))
    except BrokenProcessPool as exc:
        raise CoreError(f"a worker process of the sweep died ({exc}); run with workers=1 to "
                        "see the failing case -- a bug; please report it with the model") \
            from None


def _dask(b: BatchTables, vals: np.ndarray, client: Any, out: Outputs, bar: Any) -> None:
    """The chunks as futures on the client's cluster, gathered as they finish."""
    if not (hasattr(client, "submit") and hasattr(client, "scatter")):
        raise ModelError(f"client must be a distributed.Client, got {type(client).__name__}",
                         "sweep")
    try:
        from distributed import as_completed as dask_completed
    except ImportError:
        raise ImportError("sweeps on a Dask cluster need the package 'distributed': "
                          "pip install 'mbd2d[sweep]'") from None
    info = client.scheduler_info()
    nworkers = max(1, len(info.get("workers", {})))
    parts = chunks(0, vals.shape[1], CHUNKS_PER_WORKER * nworkers)
    # a key of its own for each sweep (hash=False): with the content's hash, a sweep of the
    # same model right after another gets the same key while the scheduler still releases
    # the last sweep's copy, and its tasks are cancelled for "lost dependencies"
    shared = client.scatter(b, broadcast=True, hash=False)
    futures = [client.submit(core.batch, shared, vals[:, a:z], pure=False) for a, z in parts]
    start = {f.key: a for f, (a, _) in zip(futures, parts)}
    for f in dask_completed(futures):
        bar.update(out.store(start[f.key], f.result()))


def connect(address: str, timeout: float = 10.0) -> Any:
    """A distributed.Client of the Dask scheduler at address (``tcp://host:8786``).

    Raises
    ------
    ModelError
        When the scheduler cannot be reached.
    ImportError
        Without the package distributed.
    """
    try:
        from distributed import Client
    except ImportError:
        raise ImportError("a Dask scheduler needs the package 'distributed': pip install "
                          "'mbd2d[sweep]'") from None
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ModelError(f"cannot reach the Dask scheduler at {address!r}: {exc}",
                         "scheduler") from None


__all__ = ["Outputs", "run", "chunks", "cores", "connect"]

"""The machine and the versions a benchmark ran with, for the results files.

    python bench/environment.py
"""
from __future__ import annotations

import json
import os
import platform
import re
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def command_output(cmd: list[str], cwd: Path | None = None, strip: bool = True) -> str | None:
    """stdout of a command (stripped unless told); None when it cannot run or fails."""
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=30, cwd=cwd)
    except (OSError, subprocess.SubprocessError):
        return None
    if p.returncode != 0:
        return None
    return p.stdout.strip() if strip else p.stdout


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo), or platform.processor()."""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        text = ""
    m = re.search(r"^model name\s*:\s*(.+)$", text, re.MULTILINE)
    return m.group(1).strip() if m else (platform.processor() or "unknown")


def os_name() -> str:
    """PRETTY_NAME of /etc/os-release plus the kernel (platform.platform())."""
    pretty = None
    try:
        for line in Path("/etc/os-release").read_text(encoding="utf-8").splitlines():
            if line.startswith("PRETTY_NAME="):
                pretty = line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    return f"{pretty} ({platform.platform()})" if pretty else platform.platform()


def memory_gib() -> float | None:
    """Total memory (GiB) from /proc/meminfo."""
    try:
        text = Path("/proc/meminfo").read_text(encoding="utf-8")
    except OSError:
        return None
    m = re.search(r"^MemTotal:\s*(\d+)\s*kB", text, re.MULTILINE)
    return int(m.group(1)) / 2 ** 20 if m else None


def linked_libraries(path: str) -> list[str]:
    """The BLAS/LAPACK libraries a shared object loads (ldd), symlinks resolved."""
    out = command_output(["ldd", path]) or ""
    libs = []
    for line in out.splitlines():
        m = re.match(r"\s*(\S+)\s+=>\s+(\S+)", line)
        if m and re.search(r"blas|lapack|atlas|mkl|flexiblas", m.group(1), re.IGNORECASE):
            real = os.path.realpath(m.group(2))
            libs.append(f"{m.group(1)} -> {real}{owner_package(real)}")
    return libs


def owner_package(path: str) -> str:
    """' (Debian package version)' that installed a file, or '' (no dpkg, not packaged)."""
    owner = command_output(["dpkg", "-S", path])
    if not owner:
        return ""
    pkg = owner.split(":", 1)[0]
    version = command_output(["dpkg-query", "-W", "-f=${Version}", pkg])
    return f" ({pkg} {version})" if version else f" ({pkg})"


def mbd2d_info() -> dict[str, Any]:
    """mbd2d's version, the extension module's path and the BLAS/LAPACK it links to."""
    import mbd2d
    from mbd2d import _core
    core = getattr(_core, "__file__", None)
    return {"mbd2d": getattr(mbd2d, "__version__", "unknown"), "core_module": core,
            "blas_lapack": linked_libraries(core) if core else []}


def numpy_blas() -> str:
    """The BLAS numpy was built with (numpy.show_config), as one line."""
    try:
        cfg = np.show_config(mode="dicts")
        blas = cfg["Build Dependencies"]["blas"]
        return f"{blas.get('name')} {blas.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - older numpy, or no such entry
        return "unknown"


def git_commit() -> dict[str, Any]:
    """HEAD of the repository and whether files outside bench/ differ from it."""
    head = command_output(["git", "rev-parse", "HEAD"], ROOT)
    status = command_output(["git", "status", "--porcelain", "--untracked-files=no"], ROOT,
                            strip=False)
    changed = [ln[3:] for ln in (status or "").splitlines() if not ln[3:].startswith("bench/")]
    return {"commit": head, "subject": command_output(["git", "log", "-1", "--format=%s"], ROOT),
            "uncommitted_changes_outside_bench": changed}


def exudyn_info() -> dict[str, Any]:
    """Exudyn's version, or why it cannot be used."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from peers_exudyn import available
    ok, info = available()
    return {"exudyn": info if ok else None, "exudyn_unavailable_reason": None if ok else info}


def package_version(name: str) -> str | None:
    """Installed version of a distribution, or None."""
    from importlib import metadata
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def collect(quick: bool = False) -> dict[str, Any]:
    """Everything above as one record (`quick` is accepted for bench/run.py and unused).

    Returns
    -------
    dict
        date, cpu_model, cores, memory_gib, os, python, numpy, numpy_blas, scipy,
        matplotlib, gfortran, mbd2d (version, core module, BLAS/LAPACK), git, exudyn (or the
        reason it is unavailable) and the load average at the start.
    """
    gfortran = command_output(["gfortran", "--version"])
    env = {"date_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
           "cpu_model": cpu_model(), "cores": os.cpu_count(), "memory_gib": memory_gib(),
           "os": os_name(), "python": platform.python_version(),
           "python_executable": sys.executable, "numpy": np.__version__,
           "numpy_blas": numpy_blas(), "scipy": package_version("scipy"),
           "matplotlib": package_version("matplotlib"),
           "gfortran": gfortran.splitlines()[0] if gfortran else None,
           "load_average_start": os.getloadavg()}
    env.update(mbd2d_info())
    env["git"] = git_commit()
    env.update(exudyn_info())
    return env


if __name__ == "__main__":
    print(json.dumps(collect(), indent=1))

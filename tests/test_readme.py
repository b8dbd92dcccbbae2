"""README.md runs as written: every ```python block (in order, in one namespace, as a reader
pastes them into one session), every ```sh command (with the installed mbd2d and
mbd2d-solve) and every ```console block (its $ commands must print what the README shows),
all in a temporary directory that holds the examples. ``make`` commands are the targets
that run this suite; the test checks that the Makefile has them.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)


def blocks(lang: str) -> list[tuple[int, str]]:
    """(line number, text) of the README's fenced blocks in a language."""
    text = README.read_text()
    out = []
    for m in FENCE.finditer(text):
        if m.group(1) == lang:
            out.append((text[:m.start()].count("\n") + 1, m.group(2)))
    return out


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("readme")
    shutil.copytree(ROOT / "examples", d / "examples",
                    ignore=shutil.ignore_patterns("output", "__pycache__"))
    return d


def _env() -> dict[str, str]:
    env = dict(os.environ)
    bindir = str(Path(sys.executable).parent)
    env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    return env


def test_the_readme_has_what_this_test_runs() -> None:
    assert len(blocks("python")) >= 10
    assert len(blocks("sh")) >= 4
    assert len(blocks("console")) >= 1
    langs = {m.group(1) for m in FENCE.finditer(README.read_text())}
    assert langs <= {"python", "sh", "console", "toml", ""}, langs


def test_python_blocks_run_as_written(workdir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(workdir)
    namespace: dict[str, object] = {"__name__": "__readme__"}
    with warnings.catch_warnings():
        # a reader sees warnings, they do not stop the session
        warnings.simplefilter("ignore")
        for line, code in blocks("python"):
            try:
                exec(compile(code, f"README.md:{line}", "exec"), namespace)
            except Exception as exc:
                pytest.fail(f"the python block at README.md line {line} fails: "
                            f"{type(exc).__name__}: {exc}")
    assert (workdir / "motion.gif").is_file() and (workdir / "mechanism.png").is_file()


def _commands(code: str) -> list[str]:
    """The commands of a sh block: one per line, comments and continuations kept."""
    lines, cmd = [], ""
    for raw in code.splitlines():
        cmd += raw
        if raw.rstrip().endswith("\\"):
            cmd = cmd.rstrip()[:-1] + " "
            continue
        if cmd.strip() and not cmd.lstrip().startswith("#"):
            lines.append(cmd.strip())
        cmd = ""
    return lines


def test_shell_commands_run_as_written(workdir: Path) -> None:
    make = (ROOT / "Makefile").read_text()
    ran = 0
    for line, code in blocks("sh"):
        for cmd in _commands(code):
            if cmd.startswith("make "):
                target = cmd.split()[1]
                assert re.search(rf"^{re.escape(target)}:", make, re.M), \
                    f"README.md line {line}: no Makefile target {target!r}"
                continue
            r = subprocess.run(cmd, shell=True, cwd=workdir, env=_env(), capture_output=True,
                               text=True, timeout=300, executable="/bin/bash")
            assert r.returncode == 0, (f"README.md line {line}: {cmd!r} exited "
                                       f"{r.returncode}:\n{r.stdout}\n{r.stderr}")
            ran += 1
    assert ran >= 8


def test_console_blocks_print_what_the_readme_shows(workdir: Path) -> None:
    for line, code in blocks("console"):
        parts = re.split(r"^\$ (.*)\n", code, flags=re.M)
        # ['', cmd1, out1, cmd2, out2, ...]
        assert parts[0] == "", f"README.md line {line}: a console block starts with '$ '"
        for cmd, shown in zip(parts[1::2], parts[2::2]):
            r = subprocess.run(cmd, shell=True, cwd=workdir, env=_env(), capture_output=True,
                               text=True, timeout=300, executable="/bin/bash")
            assert r.returncode == 0, r.stderr
            assert r.stdout.strip() == shown.strip(), \
                f"README.md line {line}: {cmd!r} prints\n{r.stdout}"

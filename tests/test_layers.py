"""The package's imports run one way: each module of python/mbd2d has a layer from the one
table below, and no module imports a module of a higher layer anywhere in its file (at module
level, inside a function, or under TYPE_CHECKING); no import cycle exists, even within a
layer. The compiled core is imported by one module only, matplotlib by the pictures only, and
meson.build installs every module.

The check reads the source with ``ast``; it imports nothing.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "python" / "mbd2d"
MESON = PACKAGE.parent.parent / "meson.build"

#: THE layer table, low to high. A module belongs to the longest prefix listed; a new module
#: that matches no entry fails the test (give it a layer here).
LAYERS: dict[str, int] = {
    # 1. foundations: exceptions and argument checks
    "mbd2d.errors": 1,
    "mbd2d.validate": 1,
    # 2. model description: bodies, joints, drivers, forces, functions, builder, TOML format
    "mbd2d.description": 2,
    # 3. core binding: packing, calls into the compiled core, status codes
    "mbd2d._core": 3,
    "mbd2d.binding": 3,
    # 4. pictures (matplotlib lives here only)
    "mbd2d.plots": 4,
    # 5. results: data, views, files, reactions
    "mbd2d.results": 5,
    # 6. analysis front doors
    "mbd2d.analysis": 6,
    # 7. design studies: sweeps and tolerance analysis (xarray, dask live here only)
    "mbd2d.studies": 7,
    # 8. the public Model (description + analyses) and its readers
    "mbd2d.model": 8,
    # 9. design studies on whole models: synthesis (builds and returns Models, multi-start
    #    through the studies' runners)
    "mbd2d.synthesis": 9,
    # 10. command line
    "mbd2d.cli": 10,
    "mbd2d.__main__": 10,
    # 11. the package's public face
    "mbd2d": 11,
}

#: Only this module may import the compiled core.
CORE_IMPORTER = "mbd2d.binding.core"
#: Third-party packages allowed only in some layers.
RESTRICTED = {"matplotlib": {4}, "PIL": {4}, "xarray": {7}, "dask": {7}, "distributed": {7},
              "pandas": {7}, "h5netcdf": {7}, "netCDF4": {7}}


def _modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the package."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def layer_of(name: str) -> int:
    """Layer of a dotted module name, by the longest prefix in LAYERS."""
    best = ""
    for prefix in LAYERS:
        if (name == prefix or name.startswith(prefix + ".")) and len(prefix) > len(best):
            best = prefix
    if not best:
        raise KeyError(name)
    return LAYERS[best]


def _is_package(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def _resolve(name: str) -> str | None:
    """The longest prefix of a dotted name that is a module of the package (or the compiled
    core); None outside the package."""
    if name == "mbd2d._core" or name.startswith("mbd2d._core."):
        return "mbd2d._core"
    parts = name.split(".")
    while parts:
        cand = ".".join(parts)
        if cand in MODULES:
            return cand
        parts.pop()
    return None


def imports_of(name: str) -> list[tuple[int, str, str]]:
    """(line, imported dotted name, how it was written) for every import in the module's
    file, wherever it stands; relative imports are made absolute. ``from X import Y`` names
    X.Y when that is a module, else X."""
    tree = ast.parse(MODULES[name].read_text(), filename=str(MODULES[name]))
    base = name if _is_package(name) else name.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                out.append((node.lineno, a.name, f"import {a.name}"))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split(".")
                up = parts[:len(parts) - node.level + 1]
                mod = ".".join(up + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            text = f"from {'.' * node.level}{node.module or ''} import " \
                   + ", ".join(a.name for a in node.names)
            for a in node.names:
                sub = f"{mod}.{a.name}"
                out.append((node.lineno, sub if _resolve(sub) == sub else mod, text))
    return out


def _graph() -> dict[str, set[str]]:
    g: dict[str, set[str]] = {m: set() for m in MODULES}
    for m in MODULES:
        for _, target, _ in imports_of(m):
            r = _resolve(target)
            if r is not None and r != m and r != "mbd2d._core":
                g[m].add(r)
    return g


def test_every_module_has_a_layer():
    missing = []
    for m in MODULES:
        try:
            layer_of(m)
        except KeyError:
            missing.append(m)
    assert not missing, f"modules without a layer (add them to LAYERS): {missing}"


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_import_of_a_higher_layer(module):
    mine = layer_of(module)
    bad = []
    for line, target, text in imports_of(module):
        r = _resolve(target)
        if r is None or r == module:
            continue
        if layer_of(r) > mine:
            bad.append(f"line {line}: {text!r} imports {r} (layer {layer_of(r)})")
    assert not bad, f"{module} (layer {mine}) imports upward:\n" + "\n".join(bad)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_restricted_imports(module):
    bad = []
    for line, target, text in imports_of(module):
        if _resolve(target) == "mbd2d._core" and module != CORE_IMPORTER:
            bad.append(f"line {line}: {text!r}: only {CORE_IMPORTER} imports the core")
        top = target.split(".")[0]
        if top in RESTRICTED and layer_of(module) not in RESTRICTED[top]:
            bad.append(f"line {line}: {text!r}: {top} only in layer(s) {RESTRICTED[top]}")
    assert not bad, f"{module}:\n" + "\n".join(bad)


def _cycle(g: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of the graph, or None (iterative depth-first search)."""
    state: dict[str, int] = {}
    for start in sorted(g):
        if state.get(start):
            continue
        stack = [(start, iter(sorted(g[start])))]
        path = [start]
        state[start] = 1
        while stack:
            node, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                stack.pop()
                path.pop()
                state[node] = 2
            elif state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            elif not state.get(nxt):
                state[nxt] = 1
                stack.append((nxt, iter(sorted(g[nxt]))))
                path.append(nxt)
    return None


def test_no_import_cycle():
    cycle = _cycle(_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_the_checks_catch_what_they_should():
    """The checker itself: a cycle and an upward import are found in made-up graphs."""
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) is None
    assert layer_of("mbd2d.results.kinematics") > layer_of("mbd2d.plots.mechanism")
    assert layer_of("mbd2d.description.joints") == 2
    assert layer_of("mbd2d") == max(LAYERS.values())


def test_meson_installs_every_module():
    text = MESON.read_text()
    listed = set(re.findall(r"'python/(mbd2d/[\w/]+\.py)'", text))
    files = {str(p.relative_to(PACKAGE.parent)) for p in PACKAGE.rglob("*.py")}
    assert files - listed == set(), f"not installed by meson.build: {sorted(files - listed)}"
    assert listed - files == set(), f"listed in meson.build but missing: {sorted(listed - files)}"
    for sub in {str(Path(f).parent) for f in files}:
        assert f"subdir: '{sub}'" in text, f"meson.build has no install_sources for {sub}"

"""The architecture's rules, checked on the source: imports point downward only (the import-linter contract in
pyproject.toml, the layers of docs/architecture.md), and no module imports another module's private names."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

import linkwork

SRC = Path(linkwork.__file__).resolve().parent
ROOT = SRC.parents[1]


def _module_name(file: Path) -> str:
    parts = list(file.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_module(dotted: str) -> bool:
    path = SRC.parent / dotted.replace(".", "/")
    return path.with_suffix(".py").exists() or (path / "__init__.py").exists()


def private_imports(file: Path, own: str | None = None) -> list[str]:
    """Every private name (``_x``, not ``__x__``) of another linkwork module that ``file`` (the module ``own``)
    imports or reads: ``from linkwork.a import _x``, and ``m._x`` where ``m`` names another linkwork module."""
    own = own or _module_name(file)
    tree = ast.parse(file.read_text(encoding="utf-8"))
    modules: dict[str, str] = {}  # local name -> linkwork module it is bound to
    found = []
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.ImportFrom)
            and node.level == 0
            and (node.module or "").startswith("linkwork")
        ):
            for alias in node.names:
                target = f"{node.module}.{alias.name}"
                if _is_module(target):
                    modules[alias.asname or alias.name] = target
                elif alias.name.startswith("_") and not alias.name.startswith("__") and node.module != own:
                    found.append(f"line {node.lineno}: from {node.module} import {alias.name}")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("linkwork.") and alias.asname:
                    modules[alias.asname] = alias.name
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in modules
            and modules[node.value.id] != own
            and node.attr.startswith("_")
            and not node.attr.startswith("__")
        ):
            found.append(f"line {node.lineno}: {node.value.id}.{node.attr} ({modules[node.value.id]})")
    return found


def test_no_module_imports_another_modules_private_names() -> None:
    offenders = {
        str(file.relative_to(SRC)): found
        for file in sorted(SRC.rglob("*.py"))
        if (found := private_imports(file))
    }
    assert offenders == {}


def test_the_scan_finds_a_private_import(tmp_path: Path) -> None:
    # The scan itself, on a module written for it: both spellings are caught, a module's own names are not.
    probe = tmp_path / "probe.py"
    probe.write_text(
        "from linkwork.io.curves import _hidden, bounding_size\nfrom linkwork.io import curves\n"
        "curves._other\ncurves.bounding_size\nfrom linkwork.kinematics.march import _mine\n"
    )
    found = private_imports(probe, own="linkwork.kinematics.march")
    assert [f.split(": ", 1)[1] for f in found] == [
        "from linkwork.io.curves import _hidden",
        "curves._other (linkwork.io.curves)",
    ]


def test_imports_point_downward_only() -> None:
    """import-linter's layers contract (pyproject.toml), function-level imports included."""
    lint = shutil.which("lint-imports")
    if lint is None:
        pytest.fail("lint-imports (import-linter, in the test extra) is not installed")
    done = subprocess.run([lint], cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stdout[-3000:]
    assert "1 kept, 0 broken" in done.stdout


def _dispatchers() -> list[tuple[str, str, Any]]:
    """Every numba dispatcher defined in a linkwork module: (module, name, dispatcher)."""
    from numba.core.registry import CPUDispatcher

    found = []
    for info in pkgutil.walk_packages(linkwork.__path__, "linkwork."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ == info.name:
                found.append((info.name, name, value))
    return found


def test_no_compiled_kernel_takes_more_than_twelve_parameters() -> None:
    """A mechanism is one tuple, settings are tuples: signatures stay short enough to change safely."""
    found = _dispatchers()
    assert len(found) >= 30  # the scan sees the kernels (tracing, normalisation, misfit, synthesis search)
    counts = {f"{module}.{name}": len(inspect.signature(d.py_func).parameters) for module, name, d in found}
    assert {k: n for k, n in counts.items() if n > 12} == {}
    assert counts["linkwork.kinematics.march.march"] <= 6


def test_every_kernel_lives_in_a_listed_kernel_module() -> None:
    """Editing a kernel changes the cache's key only when its module is listed (linkwork.kernel_cache)."""
    from linkwork.kernel_cache import KERNEL_MODULES

    for module, name, _ in _dispatchers():
        path = module.removeprefix("linkwork.").replace(".", "/") + ".py"
        assert path in KERNEL_MODULES, f"{module}.{name}"

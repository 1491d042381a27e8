"""No module of ehm reaches into another's ``_private`` names.

A name with a leading underscore belongs to the module that defines it: the module may change or drop it without
notice. A helper that two modules share is public (no underscore; a docstring; out of ``__all__`` unless users
need it) or lives in the module that uses it. The check reads every module of ``src/ehm`` with :mod:`ast` and
reports, by file, line and name:

(a) an import of a ``_private`` name from an ehm module (``from .x import _y``, ``from ehm.x import _y``);
(b) ``mod._name`` where ``mod`` is an imported ehm module (``from . import control as c``; ``c._gain``);
(c) ``obj._name`` where ``_name`` is not defined in the module itself, as a function or method, a class
    attribute or an attribute assignment (``self._name = ...``): objects of the module's own classes may use
    their privates, an object from elsewhere may not.

Dunder names (``__init__``, ``__version__``) are not private. Imports inside functions count like those at the
top of a file.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import NamedTuple

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"

# (file under src/ehm, name): reaches that another piece of work removes; nothing else belongs here.
ALLOWED: set[tuple[str, str]] = set()  # (file name, private name) pairs allowed on purpose: none


class Reach(NamedTuple):
    """One reach into another module's private name."""

    path: str
    line: int
    name: str
    kind: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.name} ({self.kind})"


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    """The absolute dotted name an ``import from`` reads from."""
    if not node.level:
        return node.module or ""
    parts = module.split(".")
    base = parts if is_package else parts[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _dotted(node: ast.expr) -> str | None:
    """``a.b.c`` for a chain of names and attributes, else None."""
    words = []
    while isinstance(node, ast.Attribute):
        words.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    words.append(node.id)
    return ".".join(reversed(words))


def _defined(tree: ast.Module) -> set[str]:
    """Private names the module defines itself: functions, methods, classes, class attributes, attribute stores."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                targets = item.targets if isinstance(item, ast.Assign) else (
                    [item.target] if isinstance(item, ast.AnnAssign) else [])
                names.update(t.id for t in targets if isinstance(t, ast.Name))
                if any(isinstance(t, ast.Name) and t.id == "__slots__" for t in targets):
                    names.update(c.value for c in ast.walk(item.value)
                                 if isinstance(c, ast.Constant) and isinstance(c.value, str))
        if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
    return names


def private_reaches(source: str, module: str, path: str, modules: set[str], is_package: bool = False) -> list[Reach]:
    """Every reach of ``source`` (the module ``module``, read from ``path``) into another module's private names.

    ``modules`` holds the dotted names of all ehm modules and packages (to tell ``mod._name`` from ``obj._name``).
    """
    tree = ast.parse(source, filename=path)
    reaches = []
    bound = {}  # local name -> ehm module it stands for
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            origin = _resolve(module, is_package, node)
            if origin != "ehm" and not origin.startswith("ehm."):
                continue
            for alias in node.names:
                # a package's face may load its own private submodule (ehm/__init__.py: from . import _compat)
                own_submodule = is_package and origin == module and f"{origin}.{alias.name}" in modules
                if _private(alias.name) and not own_submodule:
                    reaches.append(Reach(path, node.lineno, alias.name, f"imported from {origin}"))
                if f"{origin}.{alias.name}" in modules:
                    bound[alias.asname or alias.name] = f"{origin}.{alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in modules:
                    if alias.asname:
                        bound[alias.asname] = alias.name
                    else:
                        bound[alias.name.split(".")[0]] = alias.name.split(".")[0]
    defined = _defined(tree)
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and _private(node.attr)):
            continue
        owner = _dotted(node.value)
        if owner is not None:
            head, _, rest = owner.partition(".")
            target = bound.get(head)
            if target is not None and (f"{target}.{rest}" if rest else target) in modules:
                full = f"{target}.{rest}" if rest else target
                if full != module:
                    reaches.append(Reach(path, node.lineno, node.attr, f"private member of module {full}"))
                continue
        if node.attr not in defined and not isinstance(node.ctx, ast.Store):
            reaches.append(Reach(path, node.lineno, node.attr, "private member of an object defined elsewhere"))
    return sorted(set(reaches), key=lambda r: (r.line, r.name))


def _ehm_modules() -> dict[str, Path]:
    found = {}
    for path in sorted((SRC / "ehm").rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def all_reaches() -> list[Reach]:
    """The reaches of every module of ``src/ehm``, the allowed ones left out."""
    found = _ehm_modules()
    modules = set(found)
    reaches = []
    for module, path in found.items():
        relative = path.relative_to(SRC / "ehm").as_posix()
        reaches += [r for r in private_reaches(path.read_text(encoding="utf-8"), module, relative, modules,
                                               is_package=path.name == "__init__.py")
                    if (r.path, r.name) not in ALLOWED]
    return reaches


def test_no_module_reaches_into_another_modules_private_names():
    reaches = all_reaches()
    assert not reaches, "private names reached from another module:\n" + "\n".join(map(str, reaches))


def test_the_allowed_reaches_still_exist():
    """An allow-list entry whose reach is gone is stale: remove it."""
    found = _ehm_modules()
    modules = set(found)
    seen = set()
    for module, path in found.items():
        relative = path.relative_to(SRC / "ehm").as_posix()
        seen |= {(r.path, r.name) for r in private_reaches(path.read_text(encoding="utf-8"), module, relative,
                                                           modules, is_package=path.name == "__init__.py")}
    assert ALLOWED <= seen, f"stale allow-list entries: {sorted(ALLOWED - seen)}"


MODULES = {"ehm", "ehm.engine", "ehm.engine.control", "ehm.routes", "ehm.routes.linear", "ehm.simulation"}

SOURCE = '''
from . import linear
from .linear import _modes, state_of
from ehm.routes.linear import _scan
from ..engine import control as ctl
import ehm.simulation as sim
from numpy import _private_numpy_thing


class Mine:
    _table = {}

    def __init__(self, other):
        self._cache = None
        self.__dict__["x"] = 1

    def _own(self):
        return self._cache, Mine._table, self._own


def use(human, m: Mine):
    from ..engine import control

    m._own()
    linear.__name__
    human.__class__
    human._stream_span()
    ctl._gain
    control._gain
    sim._helper
    return linear._block_form
'''


def test_the_check_finds_each_kind_of_reach_by_line_and_name():
    reaches = private_reaches(SOURCE, "ehm.routes.hybrid", "hybrid.py", MODULES)
    assert [(r.line, r.name) for r in reaches] == [
        (3, "_modes"), (4, "_scan"),
        (27, "_stream_span"), (28, "_gain"), (29, "_gain"), (30, "_helper"), (31, "_block_form")]
    assert str(reaches[0]) == "hybrid.py:3: _modes (imported from ehm.routes.linear)"
    assert reaches[2].kind == "private member of an object defined elsewhere"
    assert reaches[3].kind == "private member of module ehm.engine.control"


def test_relative_imports_resolve_from_a_package_and_from_a_module():
    source = "from .base import _Source\nfrom ...errors import _x\n"
    in_package = private_reaches(source, "ehm.inputs.readers", "readers/__init__.py", {"ehm"}, is_package=True)
    in_module = private_reaches(source, "ehm.inputs.readers.read", "readers/read.py", {"ehm"})
    assert [r.kind for r in in_package] == ["imported from ehm.inputs.readers.base", "imported from ehm.errors"]
    assert [r.kind for r in in_module] == ["imported from ehm.inputs.readers.base", "imported from ehm.errors"]


def test_a_module_without_reaches_passes():
    assert private_reaches("import os\nfrom .linear import state_of\nos.path\n", "ehm.x", "x.py", MODULES) == []


@pytest.mark.parametrize("name, private", [("_x", True), ("__init__", False), ("__x", True), ("x", False)])
def test_what_counts_as_private(name, private):
    assert _private(name) is private

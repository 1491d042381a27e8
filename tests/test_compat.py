"""Old import paths (``ehm._compat``): every module moved into a folder keeps its old dotted name for one release.

The old name is the SAME module object as the new one (monkeypatching through either patches one module) and its
first import warns with a :class:`DeprecationWarning` naming the new path; the names of ``ehm.__all__`` never warn.
The table is written by ``tools/restructure.py``; this file reads it and names no old path itself.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
import subprocess
import sys
import warnings

import pytest

import ehm

_compat = pytest.importorskip("ehm._compat", reason="the modules are not in their folders yet (tools/restructure.py)")

OLD = sorted(_compat.MOVED)


def _forget(old: str) -> None:
    """Drop the aliases of ``old`` (and of its modules) from ``sys.modules``; the real modules stay."""
    for name in [n for n in sys.modules if n == old or n.startswith(old + ".")]:
        if _compat.new_name(name) is not None:
            del sys.modules[name]


@pytest.mark.parametrize("old", OLD)
def test_an_old_path_imports_the_same_module_with_a_warning(old):
    new = _compat.MOVED[old]
    _forget(old)
    with pytest.warns(DeprecationWarning, match=rf"{old} is deprecated, import {new}\b") as record:
        module = importlib.import_module(old)
    assert module is importlib.import_module(new)
    assert module.__name__ == new and module.__spec__.name == new
    assert record[0].filename == __file__  # the warning points at the importing line
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert importlib.import_module(old) is module  # once: a second import does not warn


def test_a_name_from_an_old_path_is_the_same_object():
    old = next(o for o in OLD if o.count(".") == 1)
    new_module = importlib.import_module(_compat.MOVED[old])
    name = next(n for n in vars(new_module) if not n.startswith("_") and callable(getattr(new_module, n)))
    _forget(old)
    with pytest.warns(DeprecationWarning, match=_compat.MOVED[old]):
        exec(f"from {old} import {name} as found", namespace := {})
    assert namespace["found"] is getattr(new_module, name)


def test_a_module_of_an_old_package_is_the_module_of_the_new_one():
    packages = [o for o in OLD if hasattr(importlib.import_module(_compat.MOVED[o]), "__path__")]
    assert packages, "the table moves no package"
    old = packages[0]
    new = importlib.import_module(_compat.MOVED[old])
    sub = next(m.name for m in pkgutil.iter_modules(new.__path__) if not m.name.startswith("_"))
    _forget(old)
    with pytest.warns(DeprecationWarning):
        module = importlib.import_module(f"{old}.{sub}")
    assert module is importlib.import_module(f"{_compat.MOVED[old]}.{sub}")


def test_an_old_module_as_an_attribute_of_ehm_warns_and_is_the_module():
    old = next(o for o in OLD if o.count(".") == 1)
    _forget(old)
    ehm.__dict__.pop(old.split(".")[1], None)
    with pytest.warns(DeprecationWarning):
        module = getattr(ehm, old.split(".")[1])
    assert module is importlib.import_module(_compat.MOVED[old])
    with pytest.raises(AttributeError):
        ehm.no_such_module  # noqa: B018


def test_the_public_names_import_without_a_warning():
    code = "import ehm\nfor name in ehm.__all__:\n    getattr(ehm, name)\nfrom ehm import *\n"
    run = subprocess.run([sys.executable, "-W", "error::DeprecationWarning", "-c", code], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr


def test_every_new_path_exists():
    for old, new in _compat.MOVED.items():
        assert importlib.util.find_spec(new) is not None, f"{old} -> {new}: {new} does not exist"


def test_python_dash_m_with_the_old_command_line_path_runs_it():
    # 'python -m ehm.cli' (the command line's old path) runs ehm.interfaces.cli's __main__, with the warning
    run = subprocess.run([sys.executable, "-W", "default::DeprecationWarning", "-m", "ehm.cli", "--version"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith(f"ehm {ehm.__version__}")
    assert "ehm.cli is deprecated, import ehm.interfaces.cli" in run.stderr

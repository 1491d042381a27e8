"""The import layers of ehm (``[tool.importlinter]`` in pyproject.toml, docs/development.md) hold: every import,
inside functions too, points down; MuJoCo, matplotlib and the outside-data libraries come in through one module each.

A broken contract fails with lint-imports' own report: which import, on which line, breaks which layer."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("importlinter", reason="the layer contracts need import-linter (pip install 'ehm[test]')")

ROOT = Path(__file__).resolve().parents[1]

_RUN = "from importlinter.cli import lint_imports; raise SystemExit(lint_imports(no_cache=True, no_logo=True))"


def lint_imports(src: Path = ROOT / "src") -> subprocess.CompletedProcess:
    """``lint-imports`` at the repository root, on the sources in ``src`` (this checkout's by default)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(src), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    return subprocess.run([sys.executable, "-c", _RUN], cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)


def test_import_contracts_are_kept():
    run = lint_imports()
    assert run.returncode == 0, f"lint-imports found a broken import contract:\n{run.stdout}\n{run.stderr}"
    assert "0 broken" in run.stdout


# The module by its dotted name and the import added to it (absolute), so that neither depends on where files lie;
# the words are the line of lint-imports' report that names the import.
@pytest.mark.parametrize("module, line, words", [
    ("ehm.outputs.results",
     "from ehm.simulation import SeatedHuman  # an import up",
     "ehm.outputs.results -> ehm.simulation"),
    ("ehm.inputs.motion",
     "from ehm.inputs.readers import read_motion  # the old loop",
     "ehm.inputs.motion -> ehm.inputs.readers"),
    ("ehm.routes.linear",
     "import mujoco  # MuJoCo outside the engine",
     "Illegal imports of protected package mujoco"),
    ("ehm.routes.hybrid",
     "from ehm.simulation import SeatedHuman  # a route back into the door",
     "ehm.routes.hybrid -> ehm.simulation"),
    ("ehm.routes.nonlinear",
     "from ehm.routes.hybrid import stream_checked  # a route up a floor inside routes",
     "ehm.routes.nonlinear -> ehm.routes.hybrid"),
])
def test_an_import_that_breaks_a_contract_fails_with_its_report(tmp_path, module, line, words):
    import importlib.util
    import shutil

    shutil.copytree(ROOT / "src" / "ehm", tmp_path / "ehm", ignore=shutil.ignore_patterns("__pycache__", "data"))
    path = tmp_path / Path(importlib.util.find_spec(module).origin).relative_to(ROOT / "src")
    path.write_text(path.read_text() + f"\n\ndef _added():\n    {line}\n")
    run = lint_imports(tmp_path)
    assert run.returncode != 0 and "BROKEN" in run.stdout
    assert words in run.stdout, run.stdout

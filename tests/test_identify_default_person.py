"""The identification script (tools/identify_default_person.py) writes a new file and leaves the shipped parameters
alone unless their path is named.  No identification runs here: the refusals come before any work, and the writer
is run on the shipped file's own values."""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path

import pytest

from ehm.body.params import Parameters, default_params_path

SCRIPT = Path(__file__).resolve().parents[1] / "tools" / "identify_default_person.py"


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("identify_default_person", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_write_defaults_needs_the_path_named(script, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:  # the old flag alone, without a path
        script.main(["--out", str(tmp_path / "out"), "--write-defaults"])
    assert exc.value.code == 2 and "--write-defaults: expected one argument" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        script.main(["--out", str(tmp_path / "out"), "--write-defaults", str(tmp_path / "none.toml")])
    assert exc.value.code == 2 and "which is no parameter file" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # refused before any work


def test_an_existing_out_folder_is_refused(script, tmp_path, capsys):
    (tmp_path / "out").mkdir()
    with pytest.raises(SystemExit) as exc:
        script.main(["--out", str(tmp_path / "out")])
    assert exc.value.code == 2 and "name a new folder" in capsys.readouterr().err


def test_the_identified_person_is_a_new_file_and_the_shipped_one_is_kept(script, tmp_path):
    shipped = Path(default_params_path())
    before = _digest(shipped)
    target = tmp_path / "identified_params.toml"
    script.write_into_defaults(Parameters.load(), shipped, target)
    assert _digest(shipped) == before
    written = Parameters.load(target)
    for name in script.FREE:
        for dotted in script.paths(name):
            assert written.value(dotted) == pytest.approx(Parameters.load().value(dotted), rel=1e-3), dotted
    name = script.paths(next(iter(script.FREE)))[0]
    assert written.provenance(name)[0] == "identified", name

"""pytest's setup for the whole repository: the docstring examples of ``src/ehm`` (collected with
``--doctest-modules``, pyproject.toml) run each in a fresh temporary folder, so that the files an example writes
(a parameter file, an FMU) land there and not in the working folder.  The tests' own fixtures are in
``tests/conftest.py``."""

import pytest


@pytest.fixture(autouse=True)
def _docstring_examples_in_a_temporary_folder(request):
    if type(request.node).__name__ == "DoctestItem":
        request.getfixturevalue("monkeypatch").chdir(request.getfixturevalue("tmp_path"))
    yield

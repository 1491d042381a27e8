"""What the test files share: the default person as a fixture, and the ``requires_*`` markers.

Fixtures
--------
``human``
    The default person (``ehm.SeatedHuman()``: the paper's parameters, erect, on the paper's seat with a high back
    support), settled once per test file.  Module scope: a test that changes the person it is given (locks, a
    parameter, its seat) builds its own instead; a file that needs another person overrides ``human``.

Markers
-------
A test that needs an optional package or tool says so with a marker, registered in pyproject.toml::

    @pytest.mark.requires_fmpy
    def test_the_unit_runs_in_fmpy(...):

and is skipped, with the install command in the reason, where that package or tool is missing.  ``pytest -m "not
requires_dask"`` deselects them.  :data:`REQUIREMENTS` lists the markers and what each needs.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

import ehm


def _modules(*names: str):
    """A check that every module named can be imported (found without importing it)."""
    def check() -> bool:
        try:
            return all(importlib.util.find_spec(name) is not None for name in names)
        except ModuleNotFoundError:  # a parent package of a dotted name is missing
            return False
    return check


def _c_compiler() -> bool:
    from ehm.errors import InputError
    from ehm.interfaces.fmu_native import find_compiler

    try:
        find_compiler()
    except InputError:
        return False
    return True


def _native_fmu() -> bool:
    from ehm.interfaces.fmu_native import native_platform_supported

    return _modules("fmpy")() and native_platform_supported() and _c_compiler()


#: marker: (check, why a test is skipped when the check fails)
REQUIREMENTS = {
    "requires_fmpy": (_modules("fmpy"), "needs fmpy (pip install -e '.[fmu]')"),
    "requires_pythonfmu": (_modules("pythonfmu"), "needs pythonfmu (pip install -e '.[fmu]')"),
    "requires_dask": (_modules("dask", "distributed"), "needs dask.distributed (pip install -e '.[batch]')"),
    "requires_pyarrow": (_modules("pyarrow"), "needs pyarrow (pip install -e '.[parquet]')"),
    "requires_asammdf": (_modules("asammdf"), "needs asammdf (pip install -e '.[logs]')"),
    "requires_h5py": (_modules("h5py", "pymatreader"), "needs h5py and pymatreader (pip install -e '.[logs]')"),
    "requires_imufusion": (_modules("imufusion"), "needs imufusion (pip install -e '.[logs]')"),
    "requires_xarray": (_modules("xarray"), "needs xarray (pip install -e '.[xarray]')"),
    "requires_ffmpeg": (_modules("imageio", "imageio_ffmpeg"), "needs imageio-ffmpeg (pip install -e '.[animate]')"),
    "requires_importlinter": (_modules("importlinter"), "needs import-linter (pip install -e '.[test]')"),
    "requires_cc": (_c_compiler, "needs a C compiler (cc, gcc or clang on PATH, or CC)"),
    "requires_native_fmu": (_native_fmu, "needs 64-bit Linux on x86, a C compiler and fmpy (the native FMU)"),
}

_answers: dict[str, bool] = {}


def pytest_runtest_setup(item):
    """Skip a test whose ``requires_*`` marker names something this machine lacks (each asked once per run)."""
    for marker in item.iter_markers():
        if marker.name in REQUIREMENTS:
            check, reason = REQUIREMENTS[marker.name]
            if marker.name not in _answers:
                _answers[marker.name] = bool(check())
            if not _answers[marker.name]:
                pytest.skip(reason)


@pytest.fixture(scope="module")
def human() -> ehm.SeatedHuman:
    """The default person, settled; one per test file."""
    h = ehm.SeatedHuman()
    h.settle()
    return h


def _session_processes(sid: int) -> list[int]:
    """The live processes of the session ``sid`` (Linux /proc): a command's own and every child it started."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2:].split()
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(stat.parent.name))
    return out


@pytest.fixture
def session_processes():
    """``session_processes(sid)``: the live processes of a session (Linux /proc); skips where there is no /proc."""
    if not Path("/proc/self/stat").exists():
        pytest.skip("reads the processes from /proc (Linux)")
    return _session_processes


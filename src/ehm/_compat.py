"""Old import paths of ehm's modules, kept for one release.

ehm's modules moved into folders named after their layers (``docs/development.md``).  A module imported by its
old name, ``import ehm.io`` or ``from ehm.io import ...``, is the module at its new name,
the SAME object (monkeypatching through either name patches one module), and the import warns once with a
:class:`DeprecationWarning` naming the new path.  Names of ``ehm.__all__`` never warn: import them from ``ehm``.

The table is written by ``tools/restructure.py``; this module imports nothing of ehm.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import inspect
import sys
import warnings

#: Old dotted name -> new dotted name, modules and packages (a package's modules follow it).
MOVED: dict[str, str] = {
    "ehm.io":           "ehm.files",
    "ehm.tables":       "ehm.body.tables",
    "ehm.posture":      "ehm.body.posture",
    "ehm.seat":         "ehm.body.supports",
    "ehm.params":       "ehm.body.params",
    "ehm.timestep":     "ehm.body.timestep",
    "ehm.references":   "ehm.standards.references",
    "ehm.transfer":     "ehm.standards.transfer",
    "ehm.comfort":      "ehm.standards.comfort",
    "ehm.sickness":     "ehm.standards.sickness",
    "ehm.engine.seat":  "ehm.engine.seat_geometry",
    "ehm.resampling":   "ehm.inputs.resampling",
    "ehm.kinematics":   "ehm.inputs.kinematics",
    "ehm.attitude":     "ehm.inputs.attitude",
    "ehm.motion":       "ehm.inputs.motion",
    "ehm.imu":          "ehm.inputs.imu",
    "ehm.drives":       "ehm.inputs.drives",
    "ehm.readers":      "ehm.inputs.readers",
    "ehm.scaling":      "ehm.person.scaling",
    "ehm.dataframes":   "ehm.outputs.dataframes",
    "ehm.outdir":       "ehm.outputs.outdir",
    "ehm.runfiles":     "ehm.outputs.runfiles",
    "ehm.results":      "ehm.outputs.results",
    "ehm.plotting":     "ehm.outputs.plotting",
    "ehm.animation":    "ehm.outputs.animation",
    "ehm.report":       "ehm.outputs.report",
    "ehm.linear":       "ehm.routes.linear",
    "ehm.linear_poses": "ehm.routes.poses",
    "ehm.hybrid":       "ehm.routes.hybrid",
    "ehm.segments":     "ehm.routes.parallel",
    "ehm.frf":          "ehm.analysis.frf",
    "ehm.criterion":    "ehm.analysis.criterion",
    "ehm.convergence":  "ehm.analysis.convergence",
    "ehm.stepping":     "ehm.analysis.stepping",
    "ehm.study":        "ehm.analysis.study",
    "ehm.assessment":   "ehm.analysis.assessment",
    "ehm.validation":   "ehm.analysis.validation",
    "ehm.fit":          "ehm.analysis.fit",
    "ehm.cluster":      "ehm.interfaces.cluster",
    "ehm.fmu_native":   "ehm.interfaces.fmu_native",
    "ehm.fmu":          "ehm.interfaces.fmu",
    "ehm.batch":        "ehm.interfaces.batch",
    "ehm.cli":          "ehm.interfaces.cli",
}


def new_name(name: str) -> str | None:
    """The new dotted name of an old one (``None``: not moved)."""
    parts = name.split(".")
    for i in range(len(parts), 1, -1):
        head = ".".join(parts[:i])
        if head in MOVED:
            return ".".join([MOVED[head], *parts[i:]])
    return None


def _caller_stacklevel() -> int:
    """The stack level, for ``warnings.warn`` in :meth:`_OldPaths.find_spec`, of the line that imported: frames of
    this module and of ``importlib`` are passed (``warnings`` itself passes the import system's frozen frames)."""
    def internal(frame):
        name = frame.f_code.co_filename
        return "importlib" in name and "_bootstrap" in name

    frame, level = inspect.currentframe().f_back, 1
    while frame is not None and frame.f_code.co_filename in (__file__, importlib.__file__):
        frame = frame.f_back
        while frame is not None and internal(frame):
            frame = frame.f_back
        level += 1
    return level


class _Alias(importlib.abc.Loader):
    """Loads an old name as the module at its new name (the same object)."""

    def __init__(self, new: str):
        self.new = new
        self.spec = None

    def create_module(self, spec):
        module = importlib.import_module(self.new)
        self.spec = module.__spec__
        return module

    def exec_module(self, module):
        module.__spec__ = self.spec  # the import system set the alias's spec on the module; the real one back

    def is_package(self, fullname) -> bool:
        """Whether the module at the new name is a package (``python -m`` of an old package name runs its
        ``__main__``)."""
        return importlib.util.find_spec(self.new).submodule_search_locations is not None

    def get_code(self, fullname):
        """The code of the module at the new name (``python -m`` with an old name runs it)."""
        spec = importlib.util.find_spec(self.new)
        return spec.loader.get_code(self.new)


class _OldPaths(importlib.abc.MetaPathFinder):
    """Finds old names of moved modules (first on ``sys.meta_path``, so a moved package's old name is never
    loaded a second time from its files)."""

    def find_spec(self, fullname, path=None, target=None):
        new = new_name(fullname)
        if new is None:
            return None
        warnings.warn(f"{fullname} is deprecated, import {new} (the old path goes in the next release)",
                      DeprecationWarning, stacklevel=_caller_stacklevel())
        return importlib.util.spec_from_loader(fullname, _Alias(new))


_FINDER = _OldPaths()


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _OldPaths) for f in sys.meta_path):
        sys.meta_path.insert(0, _FINDER)


def old_attribute(name: str):
    """``ehm.<old module>`` as an attribute (``ehm.frf`` without importing it): the module, with the warning."""
    if f"ehm.{name}" in MOVED:
        return importlib.import_module(f"ehm.{name}")
    raise AttributeError(f"module 'ehm' has no attribute {name!r}")

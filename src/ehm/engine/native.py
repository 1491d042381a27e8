"""The nonlinear route's stepping loop in compiled code (``native/ehm_steps.c``), so that Python stays outside the
per-step loop: :func:`advancer` gives :func:`ehm.engine.stepper.run` a compiled ``advance(lo, hi)`` that does exactly
what its Python loop does (gravity from the seat load, the rotating seat's drive, ``mj_step``, the head control, the
sensors copied), on the same ``mjModel`` and ``mjData`` (the Python bindings' own, by address), so outputs are
identical.

The C file is compiled at first use with the system C compiler (``$CC``, else ``cc``, ``gcc`` or ``clang``) against
the headers and the library of the installed ``mujoco`` wheel, and kept in a cache folder (``$EHM_CACHE_DIR``, else
``$XDG_CACHE_HOME/ehm`` or ``~/.cache/ehm``) under a name that holds a hash of the source, the MuJoCo version and the
platform, so that a new version compiles anew and concurrent processes never see a half-written file.  Where no
compiler is found, or the build or the loading fails, the Python loop runs (the same numbers, about 6 % slower)
after one :class:`NativeStepWarning` per process naming why; a cache folder that cannot be written gives a build for
the process alone.  Linux only: elsewhere the Python loop runs without a warning.  ``EHM_NATIVE_STEPS=0`` in the
environment keeps the Python loop without a warning (for comparisons).  A MuJoCo error inside the loop is raised as
:class:`mujoco.FatalError`, as the Python loop's ``mj_step`` raises it.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import platform
import shlex
import shutil
import subprocess
import sys
import tempfile
from importlib import resources
from pathlib import Path

import mujoco
import numpy as np

from ..errors import EhmWarning, warn
from .export import c_library

#: The C source of the loop, in the package's ``native`` folder, and the header it shares with the native FMU.
SOURCE = "ehm_steps.c"
SHARED = "ehm_head_control.h"
#: Environment variable that turns the compiled loop off when set to ``0``.
SWITCH = "EHM_NATIVE_STEPS"
#: Longest a build may take [s].
COMPILE_TIMEOUT_S = 120.0


class NativeStepWarning(EhmWarning):
    """The compiled stepping loop is not available; the Python loop runs instead (same numbers, slower)."""


def compiler_command() -> tuple[list[str] | None, str]:
    """The C compiler command (``$CC``, which may carry words such as ``ccache gcc``, else ``cc``, ``gcc`` or
    ``clang`` on ``PATH``), or None and the reason none is found."""
    words = shlex.split(os.environ.get("CC", ""))
    if words:
        found = shutil.which(words[0])
        if found is None:
            return None, f"the C compiler named by CC ({' '.join(words)!r}) was not found"
        return [found, *words[1:]], ""
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return [found], ""
    return None, "no C compiler was found (cc, gcc or clang on PATH, or CC set)"


def cache_dir() -> Path:
    """Where compiled loops are kept: ``$EHM_CACHE_DIR``, else ``$XDG_CACHE_HOME/ehm``, else ``~/.cache/ehm``."""
    if os.environ.get("EHM_CACHE_DIR"):
        return Path(os.environ["EHM_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "ehm"


class _BuildFailed(OSError):
    """The compiler ran and failed (not: the cache could not be written)."""


def _build(cc: list[str], source: bytes, shared: bytes, out: Path) -> None:
    """Compile ``source`` (including the header ``shared``) into the shared library ``out`` (written whole: built
    beside it, then renamed), linked to the wheel's MuJoCo library; raises :class:`_BuildFailed` with the compiler's
    first error line, and OSError where ``out``'s folder cannot be written."""
    lib = c_library()
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="ehm_steps_", dir=out.parent) as tmp:
        src, built = Path(tmp) / SOURCE, Path(tmp) / out.name
        src.write_bytes(source)
        (Path(tmp) / SHARED).write_bytes(shared)
        cmd = [*cc, "-std=c11", "-O2", "-fPIC", "-shared", "-pthread", "-I", str(lib["include_dir"]), str(src), "-o",
               str(built), str(lib["library"]), f"-Wl,-rpath,{lib['library'].parent}"]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=COMPILE_TIMEOUT_S)
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise _BuildFailed(f"the C compiler {cc[0]} could not be run ({exc})") from None
        if done.returncode != 0 or not built.is_file():
            text = (done.stderr or done.stdout or "no message").strip().splitlines()
            first = next((ln for ln in text if "error" in ln.lower()), text[0] if text else "no message")
            raise _BuildFailed(f"the C compiler {cc[0]} could not build it: {first.strip()}")
        os.replace(built, out)


#: Why the compiled loop is not used where that is by design, not a fault to tell about (no warning).
_QUIET = ("EHM_NATIVE_STEPS=0", "not built on")


@functools.lru_cache(maxsize=1)
def _loaded() -> tuple[ctypes.CDLL | None, str]:
    """The compiled loop's library (built at the first call in a process if the cache does not hold it yet), or None
    and why not."""
    if os.environ.get(SWITCH, "").strip() == "0":
        return None, f"{SWITCH}=0"
    if not sys.platform.startswith("linux"):
        return None, f"not built on {sys.platform} (Linux only)"
    folder = resources.files("ehm").joinpath("native")
    source, shared = folder.joinpath(SOURCE).read_bytes(), folder.joinpath(SHARED).read_bytes()
    key = hashlib.sha256(source + shared + mujoco.mj_versionString().encode() + sys.platform.encode()
                         + platform.machine().encode() + str(Path(mujoco.__file__).resolve()).encode()).hexdigest()
    out = cache_dir() / f"ehm_steps-{key[:16]}.so"
    try:
        if out.is_file():
            lib = ctypes.CDLL(str(out))
        else:
            cc, why = compiler_command()
            if cc is None:
                return None, f"{why}: install one (e.g. 'apt install gcc')"
            lib = _built_and_loaded(cc, source, shared, out)
    except _BuildFailed as exc:
        return None, f"{exc}: set CC to a working C compiler"
    except Exception as exc:  # noqa: BLE001 - whatever keeps it from loading, the Python loop runs
        return None, f"it could not be loaded ({exc})"
    fn = lib.ehm_advance
    fn.restype = ctypes.c_long
    fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_long, ctypes.c_long,
                   ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p]
    lib.ehm_last_error.restype = ctypes.c_char_p
    lib.ehm_last_error.argtypes = []
    return lib, ""


def _built_and_loaded(cc: list[str], source: bytes, shared: bytes, out: Path) -> ctypes.CDLL:
    """Build into the cache ``out`` and load it; where the cache folder cannot be written (read-only, not a folder,
    full), build in a temporary folder, load, and remove it (a loaded library needs no file)."""
    try:
        _build(cc, source, shared, out)
        return ctypes.CDLL(str(out))
    except _BuildFailed:
        raise
    except OSError:
        pass  # the cache could not be written: a build for this process alone
    with tempfile.TemporaryDirectory(prefix="ehm_steps_") as tmp:
        here = Path(tmp) / out.name
        _build(cc, source, shared, here)
        return ctypes.CDLL(str(here))


def available() -> bool:
    """True when the compiled loop runs in this process (built or found in the cache, and loaded)."""
    return _loaded()[0] is not None


_warned: list[str] = []


def _note(why: str) -> None:
    """One warning per process that the Python loop runs, and why (none where that is by design)."""
    if why and not why.startswith(_QUIET) and not _warned:
        _warned.append(why)
        warn(f"the compiled stepping loop is not available ({why}; or set {SWITCH}=0 to run the Python loop "
             "without this warning); the nonlinear route runs its Python loop, with the same results about 6 % "
             "slower.", NativeStepWarning, stacklevel=4)


def _address(a: np.ndarray | None) -> int | None:
    if a is None:
        return None
    if not (a.flags.c_contiguous and a.dtype == np.float64):
        raise ValueError("the compiled loop takes C-contiguous float64 arrays")
    return a.ctypes.data


def advancer(mj: mujoco.MjModel, d: mujoco.MjData, gravity: np.ndarray, sens: np.ndarray, drive: dict | None,
             control_constants: np.ndarray | None):
    """The compiled ``advance(lo, hi)`` of :func:`ehm.engine.stepper.run`'s loop, or None when it is not available
    (after one :class:`NativeStepWarning` per process, unless ``EHM_NATIVE_STEPS=0``).

    ``gravity`` (n, 3) and ``sens`` (n, nsensordata): the run's gravity per step and its sensor record; ``drive``: the
    rotating seat's ``ctrl`` (n, 6) and ``ff`` (n, 3) with the first addresses ``ctrl_adr`` and ``ff_adr`` they are
    written to in ``d.ctrl`` and ``d.qfrc_applied``; ``control_constants``: the head control's
    :data:`ehm.engine.control.NUMERIC_FIELDS` values (None: no control).  The arrays must outlive the advancer."""
    lib, why = _loaded()
    if lib is None:
        _note(why)
        return None
    if sens.shape[1] != mj.nsensordata:
        raise ValueError("the sensor record's width is not the model's nsensordata")
    fn = lib.ehm_advance
    try:  # the bindings' own structures, by address (the same library: the mujoco wheel's)
        m_adr, d_adr = int(mj._address), int(d._address)
    except (AttributeError, TypeError):
        _note(f"this mujoco {mujoco.__version__} gives no addresses of its model and data")
        return None
    g_adr, s_adr = _address(gravity), _address(sens)
    if drive is not None:
        c_adr, f_adr = _address(drive["ctrl"]), _address(drive["ff"])
        c_first, f_first = int(drive["ctrl_adr"]), int(drive["ff_adr"])
    else:
        c_adr, f_adr, c_first, f_first = None, None, 0, 0
    k_adr = _address(control_constants)
    held = (mj, d, gravity, sens, drive, control_constants)  # what the addresses point into, kept alive

    def advance(lo: int, hi: int, _held=held) -> None:  # the default argument keeps them alive with the closure
        if fn(m_adr, d_adr, g_adr, s_adr, lo, hi, c_adr, c_first, f_adr, f_first, k_adr) < 0:
            raise mujoco.FatalError(lib.ehm_last_error().decode(errors="replace"))  # as the bindings' mj_step

    return advance

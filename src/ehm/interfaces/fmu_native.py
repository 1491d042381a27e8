"""Native FMI 2.0 co-simulation export: the seated person as a C unit on the MuJoCo C library.

>>> from ehm import SeatedHuman
>>> export_native_fmu("person.fmu", SeatedHuman(lock=["lower_neck"]))
PosixPath('person.fmu')

The unit's binary is ``native/ehm_fmu.c`` (shipped with ehm), compiled at export time with the system C
compiler against the MuJoCo that the ``mujoco`` wheel installed (its headers and ``libmujoco``, which is
copied into ``binaries/linux64/`` and found there through an ``$ORIGIN`` run path).  The FMI 2.0 headers
come from fmpy (``fmpy/c-code``, 2-clause BSD, Modelica Association).  Nothing in the unit needs Python.

What the unit holds:

* ``resources/ehm_model.mjb``: the compiled MuJoCo model (:func:`ehm.engine.save_binary`) of the person as
  exported: parameters, locks, body size and time step are fixed;
* ``resources/ehm_state.txt``: the settled state (MuJoCo qpos, qvel, act), the settled pose of each output
  point, the seat surfaces of each support group, the divergence and input limits (plain text);
* ``resources/ehm_params.toml`` and ``resources/ehm_fmu.json``: the parameter set and what was exported
  (for people; the binary does not read them);
* ``binaries/linux64/``: ``EhmSeatedHuman.so`` and ``libmujoco.so.<version>``;
* ``sources/``: the C source, its generated configuration header and a CMake build description, to build
  the binary on another platform; ``documentation/licenses/``: MuJoCo's licence files.

Variables (all Real; value references in this order): the inputs :data:`INPUTS`, then :data:`OUTPUTS`.
Timing and output definitions are those of :class:`ehm.simulation.SeatedHuman`; see the C file's header.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import uuid
import xml.etree.ElementTree as ET
import zipfile
from importlib import resources as importlib_resources
from importlib.util import find_spec
from pathlib import Path

from .. import engine
from ..errors import InputError

MODEL_IDENTIFIER = "EhmSeatedHuman"
PLATFORM = "linux64"
MODEL_RESOURCE = "ehm_model.mjb"
STATE_RESOURCE = "ehm_state.txt"
PARAMS_RESOURCE = "ehm_params.toml"
SETUP_RESOURCE = "ehm_fmu.json"
C_SOURCE = "ehm_fmu.c"
#: The header it shares with ehm's compiled stepping loop (the head control after each step).
C_SHARED = "ehm_head_control.h"
C_CONFIG = "ehm_fmu_config.h"
#: Seat accelerations beyond this are refused (fmi2Discard) [m/s^2]: the person sits unbelted, held by contact
#: and friction only; 10 g is far beyond ride and handling motion.
MAX_SEAT_ACC_MPS2 = 100.0
COMPILE_TIMEOUT_S = 300.0

INPUTS = ("seat_ax_mps2", "seat_ay_mps2", "seat_az_mps2", "seat_wx_radps", "seat_wy_radps", "seat_wz_radps")
#: Outputs of each point, in the order the C code fills them: (suffix, unit, description).
POINT_OUTPUTS = (
    ("ax_mps2", "m/s2", "absolute acceleration over the model step, seat x (forward)"),
    ("ay_mps2", "m/s2", "absolute acceleration over the model step, seat y (left)"),
    ("az_mps2", "m/s2", "absolute acceleration over the model step, seat z (up)"),
    ("roll_rad", "rad", "roll from the settled posture (intrinsic z-y-x angles, seat axes)"),
    ("pitch_rad", "rad", "pitch from the settled posture (intrinsic z-y-x angles, seat axes)"),
    ("yaw_rad", "rad", "yaw from the settled posture (intrinsic z-y-x angles, seat axes)"),
    ("x_m", "m", "displacement from the settled posture, seat x"),
    ("y_m", "m", "displacement from the settled posture, seat y"),
    ("z_m", "m", "displacement from the settled posture, seat z"),
    ("wx_radps", "rad/s", "angular velocity about the segment's own x axis"),
    ("wy_radps", "rad/s", "angular velocity about the segment's own y axis"),
    ("wz_radps", "rad/s", "angular velocity about the segment's own z axis"),
    ("roll_acc_radps2", "rad/s2", "angular acceleration over the model step about seat x"),
    ("pitch_acc_radps2", "rad/s2", "angular acceleration over the model step about seat y"),
    ("yaw_acc_radps2", "rad/s2", "angular acceleration over the model step about seat z"),
)
POINTS = tuple(engine.POINTS)
SUPPORTS = tuple(engine.SUPPORT_GROUPS)
OUTPUTS = (tuple(f"{p}_{s}" for p in POINTS for s, _, _ in POINT_OUTPUTS)
           + tuple(f"{g}_f{a}_N" for g in SUPPORTS for a in "xyz") + ("output_time_s",))
#: FMI unit definitions: name -> SI base-unit exponents.
_UNITS = {"m/s2": {"m": 1, "s": -2}, "rad": {"rad": 1}, "m": {"m": 1}, "rad/s": {"rad": 1, "s": -1},
          "rad/s2": {"rad": 1, "s": -2}, "N": {"kg": 1, "m": 1, "s": -2}, "s": {"s": 1}}


def native_platform_supported() -> bool:
    """True on 64-bit Linux on x86 (FMI 2.0's ``linux64``), the platform the native build targets."""
    return sys.platform.startswith("linux") and platform.machine().lower() in ("x86_64", "amd64")


def find_compiler() -> list[str]:
    """The C compiler command to build with: ``$CC`` (it may carry words, e.g. ``ccache gcc``), else ``cc``,
    ``gcc`` or ``clang`` on ``PATH`` (:func:`ehm.engine.compiler_command`)."""
    cc, why = engine.compiler_command()
    if cc is not None:
        return cc
    if os.environ.get("CC", "").strip():
        raise InputError(f"{why}; set CC to an installed compiler.")
    raise InputError("building the native FMU needs a C compiler (cc, gcc or clang on PATH, or CC set), and none "
                     "was found: install one (e.g. 'apt install gcc') or export with --python.")


def fmi_headers() -> Path:
    """The folder with the FMI 2.0 headers that fmpy ships (``fmpy/c-code``)."""
    spec = find_spec("fmpy")
    if spec is None or not spec.submodule_search_locations:
        raise InputError("building the native FMU needs the FMI 2.0 headers that fmpy ships: install ehm[fmu] "
                         "(pip install \"ehm[fmu]\").")
    for loc in spec.submodule_search_locations:
        folder = Path(loc) / "c-code"
        if (folder / "fmi2Functions.h").is_file():
            return folder
    raise InputError(f"the installed fmpy ({list(spec.submodule_search_locations)[0]}) has no c-code/fmi2Functions.h; "
                     "install fmpy 0.3.32 or later.")


def _native_file(name: str) -> bytes:
    return importlib_resources.files("ehm").joinpath("native", name).read_bytes()


# ------------------------------------------------------------------------------------------- resources
def _state_text(human) -> str:
    """``resources/ehm_state.txt``: what the C unit needs besides the MJB (read by ``read_state`` in the C)."""
    from .. import __version__

    model = human.model
    poses = engine.settled_point_poses(model)  # settles the person if needed
    s = model.settled
    num = lambda v: repr(float(v))  # noqa: E731 - shortest text that reads back to the same double
    vec = lambda name, a: f"{name} {len(a)} " + " ".join(num(v) for v in a)  # noqa: E731
    lines = [
        f"# ehm native FMU state, written by ehm {__version__}: the settled state (MuJoCo qpos, qvel, act), the",
        "# divergence limit (largest pelvis coordinate [m]) and input limit [m/s2], the output points with their",
        "# settled position [m] and orientation (w x y z), and the seat surfaces (bodies) of each support group.",
        "ehm_native_fmu_state 1",
        f"dt_s {num(model.mj.opt.timestep)}",
        vec("qpos", s["qpos"]), vec("qvel", s["qvel"]), vec("act", s["act"]),
        f"diverged_m {num(engine.DIVERGED_M)}",
        f"max_seat_acc_mps2 {num(MAX_SEAT_ACC_MPS2)}",
    ]
    for p in POINTS:
        pos, quat = poses[p]
        lines.append(f"point {p} " + " ".join(num(v) for v in list(pos) + list(quat)))
    for g, surfaces in engine.SUPPORT_GROUPS.items():
        present = [srf for srf in surfaces if srf in model.surface_bodies]
        lines.append(f"group {g} {len(present)} " + " ".join(present))
    if model.seat is not None:  # the seat's moment of inertia about its hinges [kg m^2] and its pivot [m]
        lines.append(f"rotating_seat {num(engine.SEAT_INERTIA_KGM2)} " + " ".join(num(v) for v in model.seat["pivot"]))
    lines.append("end")
    return "\n".join(lines) + "\n"


def _guid(*parts: bytes) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(hashlib.sha256(part).digest())
    return "{" + str(uuid.UUID(bytes=h.digest()[:16])) + "}"


def _config_header(guid: str) -> str:
    names = ",\n    ".join(json.dumps(n) for n in INPUTS + OUTPUTS)
    return (f"/* Generated by ehm.interfaces.fmu_native at export: this unit's GUID and variables "
            f"(value reference = index). */\n"
            f"#define EHM_GUID \"{guid}\"\n#define EHM_N_INPUTS {len(INPUTS)}\n#define EHM_N_OUTPUTS {len(OUTPUTS)}\n"
            f"static const char *const ehm_variable_names[] = {{\n    {names}\n}};\n")


def _model_description(guid: str, dt_s: float, description: str, rotating_seat: bool = False) -> bytes:
    from .. import __version__

    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": "ehm seated human", "guid": guid, "description": description,
        "generationTool": f"ehm {__version__} (native, MuJoCo {engine.c_library()['version']})",
        "version": __version__, "license": "MIT (MuJoCo: Apache-2.0, see documentation/licenses)",
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0"})
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": MODEL_IDENTIFIER, "needsExecutionTool": "false",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
        "providesDirectionalDerivative": "false"})
    units = ET.SubElement(root, "UnitDefinitions")
    for name, exps in _UNITS.items():
        ET.SubElement(ET.SubElement(units, "Unit", {"name": name}), "BaseUnit", {k: str(v) for k, v in exps.items()})
    cats = ET.SubElement(root, "LogCategories")
    for name, what in (("logStatusError", "errors: bad calls, bad resources, divergence"),
                       ("logStatusDiscard", "refused steps: bad inputs"),
                       ("logStatusWarning", "warnings, MuJoCo's included"),
                       ("logEvents", "information (with debug logging on)")):
        ET.SubElement(cats, "Category", {"name": name, "description": what})
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0", "stepSize": repr(float(dt_s))})
    variables = ET.SubElement(root, "ModelVariables")
    for vr, name in enumerate(INPUTS):
        angular = name.startswith("seat_w")
        if angular:
            desc = (f"seat angular velocity about seat {name[6]}, held over the step" if rotating_seat
                    else f"seat angular velocity about {name[6]}; must stay 0 (seat translation only)")
        else:
            desc = f"seat acceleration along seat {name[6]} (x forward, y left, z up), held over the step"
        sv = ET.SubElement(variables, "ScalarVariable", {"name": name, "valueReference": str(vr), "description": desc,
                                                         "causality": "input", "variability": "continuous"})
        ET.SubElement(sv, "Real", {"unit": "rad/s" if angular else "m/s2", "start": "0"})
    point_desc = {f"{p}_{s}": (u, f"{p}: {d}") for p in POINTS for s, u, d in POINT_OUTPUTS}
    for g in SUPPORTS:
        for a in "xyz":
            point_desc[f"{g}_f{a}_N"] = ("N", f"force of the {g.replace('_', ' ')} on the body, seat {a}")
    point_desc["output_time_s"] = ("s", "model time of the sample the outputs belong to (t + h - model step)")
    for k, name in enumerate(OUTPUTS):
        unit, desc = point_desc[name]
        sv = ET.SubElement(variables, "ScalarVariable", {
            "name": name, "valueReference": str(len(INPUTS) + k), "description": desc, "causality": "output",
            "variability": "continuous", "initial": "calculated"})
        ET.SubElement(sv, "Real", {"unit": unit})
    structure = ET.SubElement(root, "ModelStructure")
    outs = ET.SubElement(structure, "Outputs")
    init = ET.SubElement(structure, "InitialUnknowns")
    for k in range(len(OUTPUTS)):
        ET.SubElement(outs, "Unknown", {"index": str(len(INPUTS) + k + 1)})
        ET.SubElement(init, "Unknown", {"index": str(len(INPUTS) + k + 1)})
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


# ------------------------------------------------------------------------------------------------ build
def compile_binary(cc: list, sources: Path, fmi_dir: Path, mujoco_include: Path, libmujoco: Path, out: Path) -> None:
    """Compile ``sources/ehm_fmu.c`` into the shared library ``out``, linked to ``libmujoco`` (a file in the same
    folder as ``out``) with an ``$ORIGIN`` run path; raises :class:`InputError` with the compiler's first error."""
    cmd = [*cc, "-std=c11", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-Wall", "-Wextra",
           "-I", str(sources), "-I", str(fmi_dir), "-I", str(mujoco_include), str(sources / C_SOURCE),
           "-o", str(out), str(libmujoco), "-Wl,-rpath,$ORIGIN", "-Wl,--disable-new-dtags", "-lm", "-pthread"]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=COMPILE_TIMEOUT_S, cwd=out.parent)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise InputError(f"the C compiler {cc[0]} could not be run to build the FMU binary ({exc}).") from None
    if done.returncode != 0 or not out.is_file():
        lines = [ln for ln in (done.stderr or done.stdout).splitlines() if "error" in ln.lower()] or \
            (done.stderr or done.stdout or "no message").splitlines()
        raise InputError(f"the C compiler {cc[0]} could not build the FMU binary: {lines[0].strip()}")


def export_native_fmu(out_path, human=None) -> Path:
    """Write a native FMI 2.0 co-simulation FMU of ``human`` (a :class:`ehm.SeatedHuman`; default: the default
    person) to ``out_path`` (a ``.fmu`` file), whole or not at all.  A person built with ``rotating_seat=True``
    gives a unit whose seat turns with its angular velocity inputs (seat axes); otherwise those must stay 0.

    Needs 64-bit Linux, a C compiler and fmpy (``pip install ehm[fmu]``) at export time; the unit then runs
    in any FMI 2.0 host on 64-bit Linux without Python.
    """
    from .. import __version__
    from ..files import replace_atomically
    from ..outputs.outdir import check_file_destination
    from ..simulation import SeatedHuman

    out = Path(out_path)
    check_file_destination(out, ".fmu", "an FMU")
    if not native_platform_supported():
        raise InputError(f"the native FMU is built for 64-bit Linux on x86 (FMI 'linux64'), not {sys.platform} "
                         f"{platform.machine()}: build its binary from the sources/ of a unit exported on Linux "
                         "(see the README), or export with --python.")
    cc = find_compiler()
    fmi_dir = fmi_headers()
    lib = engine.c_library()
    if human is None:
        human = SeatedHuman()
    model = human.model
    rotating = model.seat is not None
    state = _state_text(human)
    c_source = _native_file(C_SOURCE)
    c_shared = _native_file(C_SHARED)
    dt = float(model.mj.opt.timestep)
    setup = {"format": 1, "ehm_version": __version__, "mujoco_version": lib["version"], "platform": PLATFORM,
             "params_origin": human.params.origin, "posture": human.params.posture,
             "back_support": human.params.back_support, "locked": sorted(human.locked), "dt_s": dt,
             "mass_kg": human.mass_kg, "dof": human.dof,
             "size": None if human.size is None else {k: float(v) for k, v in vars(human.size).items()
                                                      if isinstance(v, (int, float))},
             "rotating_seat": rotating, "inputs": list(INPUTS), "outputs": list(OUTPUTS),
             "max_seat_acc_mps2": MAX_SEAT_ACC_MPS2}
    description = (f"Seated human (ehm {__version__}, 12-segment efficient human model on MuJoCo {lib['version']}): "
                   "body motion and support forces from seat "
                   f"{'translation and rotation' if rotating else 'translation'}; "
                   f"{human.mass_kg:.1f} kg, "
                   f"{human.dof} degrees of freedom, model step {dt:g} s. Native C, no Python needed.")

    with tempfile.TemporaryDirectory(prefix="ehm_fmu_") as tmp:
        root = Path(tmp) / "fmu"
        res, binaries, sources = root / "resources", root / "binaries" / PLATFORM, root / "sources"
        for folder in (res, binaries, sources, root / "documentation" / "licenses"):
            folder.mkdir(parents=True)
        engine.save_binary(model, res / MODEL_RESOURCE)
        (res / STATE_RESOURCE).write_text(state, encoding="utf-8")
        (res / PARAMS_RESOURCE).write_text(human.params.to_toml(), encoding="utf-8")
        (res / SETUP_RESOURCE).write_text(json.dumps(setup, indent=2) + "\n", encoding="utf-8")
        guid = _guid((res / MODEL_RESOURCE).read_bytes(), state.encode(), c_source + c_shared,
                     "\n".join(INPUTS + OUTPUTS).encode())
        (sources / C_SOURCE).write_bytes(c_source)
        (sources / C_SHARED).write_bytes(c_shared)
        (sources / C_CONFIG).write_text(_config_header(guid), encoding="utf-8")
        (sources / "CMakeLists.txt").write_bytes(_native_file("CMakeLists.txt"))
        for f in lib["licenses"]:
            shutil.copyfile(f, root / "documentation" / "licenses" / f"mujoco-{f.name}")
        libcopy = binaries / lib["library"].name
        shutil.copyfile(lib["library"], libcopy)
        compile_binary(cc, sources, fmi_dir, lib["include_dir"], libcopy, binaries / f"{MODEL_IDENTIFIER}.so")
        (root / "modelDescription.xml").write_bytes(_model_description(guid, dt, description, rotating))

        def write(tmp_zip: str) -> None:
            with zipfile.ZipFile(tmp_zip, "w", zipfile.ZIP_DEFLATED) as z:
                for path in sorted(root.rglob("*")):
                    if path.is_file():
                        z.write(path, path.relative_to(root).as_posix())

        replace_atomically(out, write, "the FMU")
    return out

"""FMI 2.0 co-simulation export: the seated person as an FMU for vehicle and driving-simulator tools.

>>> import shutil
>>> from ehm.body.params import default_params_path
>>> _ = shutil.copy(default_params_path(), "my.toml")                            # a parameter file of one's own
>>> export_fmu("ehm.fmu", params="my.toml", lock=["lower_neck"])               # native C unit (default)
PosixPath('ehm.fmu')
>>> export_fmu("ehm-py.fmu", params="my.toml", lock=["lower_neck"], python=True)  # pythonfmu unit
PosixPath('ehm-py.fmu')

The default unit is native: C on the MuJoCo C library, built at export time (``ehm.interfaces.fmu_native``); it
needs no Python when it runs.  The rest of this module is the older pythonfmu route, kept behind
``python=True`` (``ehm export-fmu --python``) for Python hosts that want to choose the parameter file at
run time (its ``params_file`` parameter).

The pythonfmu unit is built with the PyPI builder `pythonfmu` (``pip install ehm[fmu]``); ehm writes no FMI
code of its own for it.  Its slave is a few lines generated from ``SLAVE_TEMPLATE`` that import this module and
delegate to :class:`SlaveCore`, which runs :class:`ehm.Simulator`.  The parameter set (its TOML
text) and the joint locks are embedded in the FMU's ``resources`` folder.

The unit runs its Python inside the host's interpreter: the host process must be able to import ``ehm``
(with mujoco, numpy and scipy).  A Python host (fmpy, PyFMI, ...) in an environment with ehm installed
works as is; a host that is not Python needs that interpreter's library loaded (see the README).

Interface (all Real unless noted; seat axes x forward, y left, z up):

* inputs ``seat_a{x,y,z}_mps2``: seat acceleration [m/s^2]; ``seat_w{x,y,z}_radps``: seat angular
  velocity [rad/s], which must stay 0 (step-by-step runs support seat translation only);
* parameter ``params_file`` (String, fixed): a parameter file to use instead of the embedded one;
* outputs for ``pelvis``, ``trunk``, ``head`` and ``lumbar`` (the L4-L5 joint centre): absolute acceleration
  ``<p>_a{x,y,z}_mps2``, rotation from the settled posture ``<p>_{roll,pitch,yaw}_rad``, displacement from the
  settled posture ``<p>_{x,y,z}_m`` and angular velocity in the segment's own axes ``<p>_w{x,y,z}_radps``; and
  ``output_time_s``, the model time of the sample the outputs belong to.

Timing: ``doStep(t, h)`` runs round(h / dt) model steps (dt from the parameter file) with the inputs held at
their values at t.  Each model step reports the sample at its start (the response to that step's input,
as a whole run reports its row), so after ``doStep(t, h)`` the outputs are the sample at t + h - dt, and
``output_time_s`` says so.  Before the first step they are the response at the start time to the start
inputs.

Refusals: a non-zero seat angular velocity or a non-finite input makes ``doStep`` return fmi2Discard (the
unit stays where it was; fmpy ends the run there), and so does a divergence of the model (after which the
unit refuses every step).  A parameter file that cannot be read or used makes
``fmi2ExitInitializationMode`` fail with the reason logged (status error); the call itself returns fmi2Fatal,
because pythonfmu's wrapper turns every Python exception into fmi2Fatal and gives Python code no way to return
fmi2Error (the native unit, the default of ``ehm export-fmu``, fixes its parameters at export and reports its
errors as fmi2Error).  pythonfmu passes the unit's messages to the host only with debug
logging on (``loggingOn``; fmpy ``debug_logging=True``).  A set-up this ehm cannot use, or a host that cannot
import ehm, is said at ``fmi2ExitInitializationMode`` too, never at instantiation (a null instance crashed hosts
that terminate it); and a slave whose call raised is kept alive, because pythonfmu 0.7 releases it once at the
error and again at ``fmi2FreeInstance`` (a host that went on after the error and then freed the unit crashed).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from ..body.params import Parameters
from ..errors import EhmError, InputError
from ..outputs.outdir import check_file_destination
from ..person.person import Person, as_person

#: Class name of the slave = the FMU's model identifier (names its binaries).
MODEL_IDENTIFIER = "EhmSeatedHuman"
#: Module name of the generated slave script inside the FMU.
SLAVE_MODULE = "ehm_seated_human_fmu"
PARAMS_RESOURCE = "ehm_params.toml"
SETUP_RESOURCE = "ehm_fmu.json"
SETUP_FORMAT = 1

INPUTS = ("seat_ax_mps2", "seat_ay_mps2", "seat_az_mps2", "seat_wx_radps", "seat_wy_radps", "seat_wz_radps")
POINTS = ("pelvis", "trunk", "head", "lumbar")  #: as ``ehm.engine.POINTS`` (its order: value references)
#: (suffix, StepState field, index, description) of the outputs of each point.
_POINT_OUTPUTS = (
    ("ax_mps2", "acc_mps2", 0, "absolute acceleration, seat x (forward) [m/s2]"),
    ("ay_mps2", "acc_mps2", 1, "absolute acceleration, seat y (left) [m/s2]"),
    ("az_mps2", "acc_mps2", 2, "absolute acceleration, seat z (up) [m/s2]"),
    ("roll_rad", "rot_rad", 0, "roll from the settled posture (z-y-x Euler angles, seat axes) [rad]"),
    ("pitch_rad", "rot_rad", 1, "pitch from the settled posture (z-y-x Euler angles, seat axes) [rad]"),
    ("yaw_rad", "rot_rad", 2, "yaw from the settled posture (z-y-x Euler angles, seat axes) [rad]"),
    ("x_m", "disp_m", 0, "displacement from the settled posture, seat x [m]"),
    ("y_m", "disp_m", 1, "displacement from the settled posture, seat y [m]"),
    ("z_m", "disp_m", 2, "displacement from the settled posture, seat z [m]"),
    ("wx_radps", "angvel_radps", 0, "angular velocity about the segment's own x axis [rad/s]"),
    ("wy_radps", "angvel_radps", 1, "angular velocity about the segment's own y axis [rad/s]"),
    ("wz_radps", "angvel_radps", 2, "angular velocity about the segment's own z axis [rad/s]"),
)
OUTPUTS = tuple(f"{p}_{s}" for p in POINTS for s, *_ in _POINT_OUTPUTS) + ("output_time_s",)

SLAVE_TEMPLATE = '''"""FMI 2.0 co-simulation slave of ehm {version} (written by ehm.interfaces.fmu.export_fmu, built by
pythonfmu).

All the work is done by ehm.interfaces.fmu.SlaveCore, which needs the ehm package in the host's Python.
"""
import ctypes
import functools

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status

try:
    from ehm.interfaces.fmu import SlaveCore
    MISSING = None
except ImportError as exc:  # said when the unit starts: a unit that fails to instantiate crashes hosts
    SlaveCore = None
    MISSING = ("this FMU runs the ehm package inside the host's Python interpreter, which cannot "
               f"import it ({{exc}}); install ehm (with mujoco, numpy, scipy) in that environment.")

#: Slaves whose call raised (fmi2Fatal), kept alive for good: pythonfmu 0.7 releases the slave, its class and its
#: log queue once when a call raises and again when the host frees the instance.  A reference held in a list
#: balanced that second release but was itself released when the interpreter shut down, which freed them
#: a last time while the garbage collector still walked them (a crash at the host's exit); a reference taken with
#: Py_IncRef is never released, so they outlive the interpreter (a few objects, once per failed call).
KEPT = []


def _kept_on_failure(method):
    @functools.wraps(method)
    def call(self, *args):
        try:
            return method(self, *args)
        except BaseException:
            for obj in (self, type(self), self.log_queue):
                ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            KEPT.append(id(self))
            raise
    return call


class {cls}(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.core = None if SlaveCore is None else SlaveCore(self)

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        if self.core is not None:
            self.core.setup_experiment(start_time)

    def exit_initialization_mode(self):
        if self.core is None:
            self.log(MISSING, Fmi2Status.error)
            raise ImportError(MISSING)
        self.core.start()

    def do_step(self, current_time, step_size):
        return self.core is not None and self.core.do_step(current_time, step_size)

    def terminate(self):
        if self.core is not None:
            self.core.stop()


for _name in ("setup_experiment", "enter_initialization_mode", "exit_initialization_mode", "do_step", "terminate",
              "get_integer", "get_real", "get_boolean", "get_string", "set_integer", "set_real", "set_boolean",
              "set_string", "_get_fmu_state", "_set_fmu_state"):
    setattr({cls}, _name, _kept_on_failure(getattr({cls}, _name)))
'''


class SlaveCore:
    """What the FMU's slave delegates to: its variables, the model and the stepping.

    ``slave`` is the :class:`pythonfmu.Fmi2Slave` instance (it holds the resources folder and the log).
    """

    def __init__(self, slave):
        from pythonfmu import Fmi2Causality, Fmi2Variability, Real, String
        from pythonfmu.default_experiment import DefaultExperiment

        from .. import __version__

        self.slave = slave
        self.resources = Path(slave.resources)
        # A set-up this ehm cannot use is said when the unit starts (fmi2ExitInitializationMode), not here: a unit
        # that fails to instantiate gives the host a null instance, and pythonfmu crashes the host when it is then
        # terminated.
        self.setup, self.problem = _read_setup(self.resources / SETUP_RESOURCE)
        slave.description = ("Seated human (ehm, 12-segment efficient human model on MuJoCo): body motion "
                             "from seat acceleration. Needs the ehm package in the host's Python.")
        slave.version = self.setup.get("ehm_version", __version__)
        slave.license = "MIT"
        slave.default_experiment = DefaultExperiment(start_time=0.0, step_size=self.setup.get("dt_s"))
        exported = self.setup.get("ehm_version")
        self._version_note = (None if exported == __version__ else
                              f"this FMU was exported by ehm {exported} and runs ehm {__version__}")

        self.u = np.zeros(len(INPUTS))
        self.y = np.zeros(len(OUTPUTS))
        self.params_file = ""
        self.sim = None
        self.t0 = 0.0
        self.steps = 0
        self.failed = None  # why the model cannot go on (a divergence), once it happened
        self._warned_step = False

        for i, name in enumerate(INPUTS):
            angular = name.startswith("seat_w")
            desc = (f"seat angular velocity about {name[6]} [rad/s]; must be 0 (seat translation only)" if angular
                    else f"seat acceleration along {name[6]} (x forward, y left, z up) [m/s2]")
            slave.register_variable(Real(name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                                         start=0.0, description=desc, getter=lambda i=i: self.u[i],
                                         setter=lambda v, i=i: self.u.__setitem__(i, v)))
        slave.register_variable(String(
            "params_file", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed, start="",
            description="parameter file (TOML) to use instead of the embedded set; empty: embedded",
            getter=lambda: self.params_file, setter=self._set_params_file))
        point_outputs = [(p, suffix, desc) for p in POINTS for suffix, _, _, desc in _POINT_OUTPUTS]
        for k, (p, suffix, desc) in enumerate(point_outputs):  # y[k] in OUTPUTS order
            slave.register_variable(Real(f"{p}_{suffix}", causality=Fmi2Causality.output,
                                         variability=Fmi2Variability.continuous, description=f"{p}: {desc}",
                                         getter=lambda k=k: self.y[k]))
        slave.register_variable(Real("output_time_s", causality=Fmi2Causality.output,
                                     variability=Fmi2Variability.continuous,
                                     description="model time of the sample the outputs belong to [s] "
                                                 "(end of the communication step minus one model step)",
                                     getter=lambda: self.y[-1]))

    def _set_params_file(self, value) -> None:
        self.params_file = str(value)

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time: float) -> None:
        self.t0 = float(start_time)

    def start(self) -> None:
        """Build and settle the person (parameters as the host set them) and set the outputs at t0."""
        from ..analysis.stepping import Simulator
        from ..body.params import Parameters

        try:
            if self.problem:
                raise InputError(self.problem)
            path = self.params_file.strip()
            params = Parameters.load(path if path else self.resources / PARAMS_RESOURCE)
            if not path:
                params = Parameters(params.data, self.setup.get("params_origin", "embedded"))
            self.sim = Simulator(params=params, lock=self.setup["lock"], unlock=self.setup["unlock"], comfort=False)
            self.steps = 0
            snap = self.sim.save_state()
            state = self.sim.step(self.u[:3])
            self.sim.restore_state(snap)
        except EhmError as exc:
            self._log(f"ehm: {exc}", error=True)
            raise
        self._outputs(state)
        if self._version_note:
            self._log(self._version_note)

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Advance to current_time + step_size with the inputs held; False (fmi2Discard) on an ehm error."""
        if self.sim is None:
            self._log("doStep before initialization: call fmi2ExitInitializationMode first.", error=True)
            return False
        if self.failed:
            self._log(f"ehm: the model cannot go on ({self.failed}); reset or instantiate the unit again.",
                      error=True)
            return False
        dt = self.sim.dt_s
        end = (current_time + step_size - self.t0) / dt
        target = int(round(end))
        if abs(end - target) > 1e-6 and not self._warned_step:
            self._log(f"communication step {step_size:g} s is not a multiple of the model step {dt:g} s; "
                      "the unit runs whole model steps (to the nearest one).")
            self._warned_step = True
        n = target - self.steps
        if n < 0:
            self._log(f"doStep at t = {current_time:g} s goes back in time (the unit is at "
                      f"{self.t0 + self.steps * dt:g} s); it cannot.", error=True)
            return False
        acc = self.u[:3].copy()
        if np.any(self.u[3:] != 0):
            self._log("seat_wx_radps, seat_wy_radps and seat_wz_radps must stay 0: this unit runs the person step "
                      "by step, which supports seat translation only (a rotating seat needs the whole drive in "
                      "advance: 'ehm assess').", error=True)
            return False
        if not np.all(np.isfinite(acc)):
            self._log(f"seat acceleration inputs must be finite numbers [m/s2], got {acc.tolist()}.", error=True)
            return False
        state = None
        try:
            for _ in range(n):
                state = self.sim.step(acc)
                self.steps += 1
        except EhmError as exc:  # a divergence: the state is lost
            self.failed = str(exc)
            self._log(f"ehm: {exc}", error=True)
            return False
        finally:
            if state is not None:
                self._outputs(state)
        return True

    def stop(self) -> None:
        self.sim = None

    # ------------------------------------------------------------------ helpers
    def _outputs(self, state) -> None:
        self.y[:-1] = [getattr(getattr(state, p), field)[j] for p in POINTS for _, field, j, _ in _POINT_OUTPUTS]
        self.y[-1] = self.t0 + state.time_s

    def _log(self, msg: str, error: bool = False) -> None:
        from pythonfmu.enums import Fmi2Status

        self.slave.log(msg, Fmi2Status.error if error else Fmi2Status.warning)


def _read_setup(path: Path) -> tuple[dict, str | None]:
    """The unit's set-up (``SETUP_RESOURCE``), and None; or an empty set-up and the sentence why it cannot be used."""
    try:
        setup = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return {}, f"{path}: cannot read the FMU set-up ({exc})."
    if not isinstance(setup, dict) or setup.get("format") != SETUP_FORMAT:
        found = setup.get("format") if isinstance(setup, dict) else None
        return {}, (f"this FMU was written by a different ehm (set-up format {found!r}, this ehm reads "
                    f"{SETUP_FORMAT}); export it again with this ehm.")
    return setup, None


# ---------------------------------------------------------------------- export
def _with_initial_unknowns(xml: bytes) -> bytes:
    """The model description with ``ModelStructure/InitialUnknowns`` listing the outputs.

    FMI 2.0 requires every output with initial = calculated among the initial unknowns; pythonfmu 0.7
    writes only ``Outputs`` (fmpy's validate_fmu and strict importers reject that).  Dependencies are left
    out: each output may depend on every input and parameter, which is true here.
    """
    import xml.etree.ElementTree as ET

    root = ET.fromstring(xml)
    structure = root.find("ModelStructure")
    if structure is None or structure.find("InitialUnknowns") is not None:
        return xml
    indices = [i for i, v in enumerate(root.iter("ScalarVariable"), start=1)
               if v.get("causality") == "output" and v.get("initial") in (None, "approx", "calculated")]
    text = xml.decode("utf-8")
    block = "\t\t<InitialUnknowns>\n" + "".join(f'\t\t\t<Unknown index="{i}"/>\n' for i in indices) + \
        "\t\t</InitialUnknowns>\n\t"
    at = text.rfind("</ModelStructure>")
    if not indices or at < 0:
        return xml
    return (text[:at] + block + text[at:]).encode("utf-8")


def _install_atomic(built: Path, out: Path) -> None:
    """Write the built FMU (model description completed) next to ``out``, then rename it over ``out``."""
    import zipfile

    from ..files import replace_atomically

    def write(tmp: str) -> None:
        with zipfile.ZipFile(built) as zin, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zout:
            for info in zin.infolist():
                data = zin.read(info)
                if info.filename == "modelDescription.xml":
                    data = _with_initial_unknowns(data)
                zout.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)

    replace_atomically(out, write, "the FMU")


def export_fmu(out_path, params: Person | Parameters | str | None = None, lock=(), unlock=(), python: bool = False,
               size=None, dt_s: float | None = None, rotating_seat: bool = False, posture: str | None = None,
               back_support: str | None = None, head_control=None) -> Path:
    """Write an FMI 2.0 co-simulation FMU of the seated person to ``out_path`` (a ``.fmu`` file).

    Parameters
    ----------
    out_path : str or Path
        Destination file; written whole or not at all (built in a temporary folder, then renamed).
    params : Person, Parameters, path or None
        The person (:class:`ehm.Person`), or the parameter set to embed (default: the shipped defaults).  The
        pythonfmu unit's host may select another file with the FMU's ``params_file`` parameter.  The other
        person arguments (``lock``, ``unlock``, ``size``, ``dt_s``, ``posture``, ``back_support``,
        ``head_control``) are shortcuts that build (or change) the Person.
    lock, unlock : iterable of str
        Joints to lock or unlock, as for :class:`ehm.SeatedHuman`; embedded in the FMU.
    python : bool
        Build the pythonfmu unit (its host must run ehm in Python) instead of the native C unit.
    size : ehm.person.scaling.BodySize, optional
        Body size of the person (native unit only).
    dt_s : float, optional
        Model step [s] instead of the parameter file's (native unit only).
    rotating_seat : bool
        The seat turns with the unit's angular velocity inputs (native unit only; each model step costs
        about half as much again, see the README).
    posture, back_support : str, optional
        How the person sits, as for :class:`ehm.SeatedHuman` (default: the parameter file's); embedded in
        the unit (the native unit's ``resources/ehm_fmu.json`` names them).
    head_control : bool or dict, optional
        Head-in-space control, as for :class:`ehm.SeatedHuman` (default: the parameter file's); embedded in the
        unit's parameters (both units run it: the native one reads its gains from the compiled model).

    Returns the path written.  The native unit needs a C compiler and fmpy at export time
    (:func:`ehm.interfaces.fmu_native.export_native_fmu`); the pythonfmu unit needs the ``pythonfmu`` package
    (``pip install ehm[fmu]``), and the host that runs it needs ehm importable in its Python.
    """
    from .. import __version__
    from ..simulation import SeatedHuman

    person = as_person(params, lock=lock, unlock=unlock, size=size, dt_s=dt_s, posture=posture,
                       back_support=back_support, head_control=head_control)

    if not python:
        from .fmu_native import export_native_fmu

        check_file_destination(out_path, ".fmu", "an FMU")
        return export_native_fmu(out_path, SeatedHuman(person, rotating_seat=rotating_seat))
    if person.size is not None or person.dt_s is not None or rotating_seat:
        raise InputError("the pythonfmu unit (--python) takes no body size, time step or rotating seat; set the size "
                         "and step in the parameter file, or export the native unit.")
    if person.body is not None:
        raise InputError("the pythonfmu unit (--python) runs the shipped body tables; export the native unit for a "
                         "person with their own tables.")

    builder = _pythonfmu_builder()
    out = Path(out_path)
    check_file_destination(out, ".fmu", "an FMU")
    lock, unlock = list(person.lock), list(person.unlock)
    p = person.seated_params()
    human = SeatedHuman(person)  # builds the model once
    setup = {"format": SETUP_FORMAT, "ehm_version": __version__, "params_origin": p.origin, "lock": lock,
             "unlock": unlock, "locked": sorted(human.locked), "dt_s": float(human.model.mj.opt.timestep),
             "inputs": list(INPUTS), "outputs": list(OUTPUTS)}
    _build_python_unit(builder, p, setup, out)
    return out


def _pythonfmu_builder():
    """pythonfmu's ``FmuBuilder``, or one sentence on what is missing (the package, or its binary for this platform)."""
    try:
        from pythonfmu.builder import FmuBuilder
    except ImportError:
        raise InputError("exporting an FMU needs the pythonfmu package: install ehm[fmu] "
                         "(pip install \"ehm[fmu]\" or pip install \"pythonfmu>=0.7,<0.8\").") from None
    if not FmuBuilder.has_binary():
        raise InputError(f"pythonfmu has no FMU binary for this platform ({sys.platform}); it builds units for "
                         "64-bit Linux and Windows.")
    return FmuBuilder


def _build_python_unit(builder, params, setup: dict, out: Path) -> None:
    """Build the pythonfmu unit (slave script, parameter file, setup) in a temporary folder and move it to ``out``."""
    from .. import __version__

    with tempfile.TemporaryDirectory(prefix="ehm_fmu_") as tmp:
        src = Path(tmp) / "src"
        src.mkdir()
        script = src / f"{SLAVE_MODULE}.py"
        script.write_text(SLAVE_TEMPLATE.format(version=__version__, cls=MODEL_IDENTIFIER), encoding="utf-8")
        (src / PARAMS_RESOURCE).write_text(params.to_toml(), encoding="utf-8")
        (src / SETUP_RESOURCE).write_text(json.dumps(setup, indent=2) + "\n", encoding="utf-8")
        built = Path(tmp) / "out" / f"{MODEL_IDENTIFIER}.fmu"
        built.parent.mkdir()
        path_before = list(sys.path)
        sys.modules.pop(SLAVE_MODULE, None)  # a unit loaded earlier in this process must not stand in for it
        try:
            builder.build_FMU(script, dest=built, project_files=[src / PARAMS_RESOURCE, src / SETUP_RESOURCE])
        except EhmError:
            raise
        except Exception as exc:  # noqa: BLE001 - the builder's own failures, in one sentence
            raise InputError(f"{out}: pythonfmu could not build the FMU ({type(exc).__name__}: {exc}).") from None
        finally:  # the builder imports the slave from the temporary folder: leave no trace of it
            sys.path[:] = path_before
            sys.modules.pop(SLAVE_MODULE, None)
        _install_atomic(built, out)

"""The model handed to other tools: the compiled model as a MuJoCo binary file and the installed MuJoCo C library
(both for the native FMU), and the geometry a picture of the model draws."""

from __future__ import annotations

import mujoco
import numpy as np

from ..errors import InputError
from .model import Model


def save_binary(model: Model, path) -> None:
    """Write the compiled model as a MuJoCo binary model file (MJB) at ``path``, for the native FMU.

    The MJB holds the model exactly as compiled here (solver, contact pairs and their solref set after
    compilation, sensors), with gravity G0: the C unit loads it with ``mj_loadModel`` and steps it as
    :func:`step` does.
    """
    mujoco.mj_saveModel(model.mj, str(path), None)


def c_library() -> dict:
    """Where the installed MuJoCo keeps its C library and headers, for building the native FMU.

    Returns ``version`` (e.g. ``"4.0.0"``), ``include_dir`` (holding ``mujoco/mujoco.h``), ``library``
    (the shared library ``libmujoco.so.<version>`` on Linux) and ``licenses`` (the wheel's licence files, to
    ship with the library), or raises :class:`InputError` naming what is missing.
    """
    from importlib import metadata
    from pathlib import Path

    root = Path(mujoco.__file__).resolve().parent
    version = mujoco.mj_versionString()
    include = root / "include"
    libs = sorted(root.glob("libmujoco.so*"))
    if not (include / "mujoco" / "mujoco.h").is_file():
        raise InputError(f"the installed mujoco package ({root}) ships no C headers (include/mujoco/mujoco.h).")
    if not libs:
        raise InputError(f"the installed mujoco package ({root}) ships no shared library libmujoco.so for this "
                         "platform.")
    try:
        licenses = [Path(f.locate()) for f in metadata.distribution("mujoco").files or ()
                    if "LICENSE" in f.name.upper()]
    except metadata.PackageNotFoundError:
        licenses = []
    return {"version": version, "include_dir": include, "library": libs[-1],
            "licenses": [p for p in licenses if p.is_file()]}


def drawing_geometry(model: Model) -> dict:
    """What a picture of the model needs, from the compiled model: per segment its drawn ellipsoid (semi-axes,
    position and orientation in the segment body's frame) and per seat surface its shape and pose at rest.

    Returns a dict of arrays: ``segments`` (names), ``segment_body`` (body ids), ``shape_size_m`` (k, 3),
    ``shape_pos_m`` (k, 3), ``shape_quat`` (k, 4); ``surfaces`` (names), ``surface_type`` ("plane"/"box"),
    ``surface_size_m`` (s, 3), ``surface_pos_m`` (s, 3), ``surface_quat`` (s, 4) in world axes at rest.
    """
    mj = model.mj
    segs = [s.name for s in model.body.segments]
    gids = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, f"{s}_shape") for s in segs]
    d = mujoco.MjData(mj)
    mujoco.mj_forward(mj, d)
    surf = list(model.surface_bodies)
    sg = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, s) for s in surf]
    quats = np.empty((len(sg), 4))
    for i, g in enumerate(sg):
        mujoco.mju_mat2Quat(quats[i], d.geom_xmat[g])
    return {
        "segments": np.array(segs), "segment_body": np.array([mj.geom_bodyid[g] for g in gids]),
        "shape_size_m": mj.geom_size[gids].copy(), "shape_pos_m": mj.geom_pos[gids].copy(),
        "shape_quat": mj.geom_quat[gids].copy(),
        "surfaces": np.array(surf),
        "surface_type": np.array(["plane" if mj.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE else "box" for g in sg]),
        "surface_size_m": mj.geom_size[sg].copy(), "surface_pos_m": d.geom_xpos[sg].copy(), "surface_quat": quats,
    }

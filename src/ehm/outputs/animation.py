"""Animations of a run: the person and the seat drawn from the model's own ellipsoids.

A run folder written with ``ehm simulate ... --out RUN_DIR`` holds ``poses.npz``: the world pose of every
segment body at the pose rate (25 Hz) and the drawing geometry of the compiled model (each segment's
ellipsoid, each seat surface).  This module draws them offscreen with matplotlib's Agg renderer (no
display and no OpenGL are needed) in two orthographic views side by side:

* a side view, the x-z plane seen from the person's left (+y), so the person faces left, and
* a front view, the y-z plane seen from the front (+x), so the person's left is on the right.

Each ellipsoid is drawn as its exact orthographic outline: an ellipsoid with centre c and matrix
``M = R diag(a**2) R^T`` projects onto a plane as the ellipse whose matrix is the 2x2 block of M for the
plane's two axes.  Ellipses are stacked by their out-of-plane coordinate (nearer ones on top); the seat
surfaces are drawn behind the body as thin translucent shapes.

Motion can be exaggerated by a factor F: each segment's displacement from the first pose (t = 0, the
settled posture) is scaled by F, and its rotation from the first pose by F through the rotation vector.
With a rotating seat the exaggeration applies to the body's motion relative to the seat, the seat's pitch
and roll are drawn true to scale, and the views turn with the seat's heading (yaw), so that the side view
stays the person's side.

``.gif`` files are written with Pillow (always available); ``.mp4`` files need the optional packages
``imageio`` and ``imageio-ffmpeg`` (``pip install 'ehm[animate]'``; the wheel bundles ffmpeg).  Files are
written whole or not at all.
"""

from __future__ import annotations

import json
import math
import os
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import InputError
from ..files import replace_atomically
from .outdir import record_in_manifest

__all__ = ["animate", "render_frames", "load_poses", "auto_exaggeration", "pick_exaggeration"]

_POSE_KEYS = ("time_s", "pos", "quat")
_GEOMETRY_KEYS = ("geometry_segments", "geometry_shape_size_m", "geometry_shape_pos_m", "geometry_shape_quat",
                  "geometry_surfaces", "geometry_surface_type", "geometry_surface_size_m", "geometry_surface_pos_m",
                  "geometry_surface_quat")
#: Drawn half-sizes [m] of seat surfaces that the model holds as large boxes (rotating seat); others: 0.25.
_BOX_DRAW_HALF_M = {"seat_pan": (0.25, 0.25), "floor": (0.5, 0.4), "backrest_lower": (0.08, 0.18),
                    "backrest_upper": (0.10, 0.20), "bolster_r": (0.15, 0.04), "bolster_l": (0.15, 0.04),
                    "back_bolster_r": (0.12, 0.04), "back_bolster_l": (0.12, 0.04)}
_FLOOR_HALF_M = 1.5  #: The floor is drawn wider than any view (the axes clip it).
_FORMATS = (".gif", ".mp4")
_MP4_MISSING = ("writing .mp4 needs the packages imageio and imageio-ffmpeg: install them with "
                "pip install 'ehm[animate]', or write a .gif instead.")

#: The views' lower edge (a share of the figure's height): the axis labels above a band that holds the clock and
#: the motion's scale, so that no text is drawn over another.
_AXES_BOTTOM = 0.17
#: ``exaggerate="auto"`` scales the motion so that the segment that moves most travels this share of a view's
#: width (a 960 x 480 picture: about 20 pixels) ...
AUTO_SHARE = 0.04
#: ... turning no segment by more than this [deg] from its settled pose ...
AUTO_MAX_TURN_DEG = 30.0
#: ... with a factor of at most this, one of 1, 2, 5 times a power of ten.
AUTO_MAX = 1000.0
#: A run whose segments move less than this [m] holds no motion to show (a person at rest moves by micrometres of
#: round-off and settling): ``"auto"`` draws it true to scale.
AUTO_MIN_MOTION_M = 2e-5

# Views: (horizontal axis, vertical axis, depth axis towards the viewer, invert horizontal, label).
_VIEWS = ((0, 2, 1, True, "side view (from the left)", "x forward [m]"),
          (1, 2, 0, False, "front view", "y (person's left) [m]"))
_SEGMENT_COLORS = {"head": "#e8b796", "neck": "#e0a987", "upper_torso": "#5b8fc9", "middle_torso": "#4f82bd",
                   "lower_torso": "#4676ae", "pelvis": "#3f5f8f", "thigh": "#6d7f99", "leg": "#7d8ea6",
                   "foot": "#4a4a4a"}


# ------------------------------------------------------------------------------------------------ input
def load_poses(source) -> dict:
    """The arrays of a ``poses.npz`` (a run folder, the file itself, or an already loaded dict).

    Raises :class:`InputError` with one sentence when the file is missing, unreadable or incomplete.
    """
    if isinstance(source, dict):
        poses, where = dict(source), "the poses"
    else:
        path = Path(source)
        if path.is_dir() or path.suffix.lower() != ".npz":
            path = path / "poses.npz"
            if not path.is_file():
                run_dir = path.parent
                raise InputError(f"{run_dir} has no poses.npz (not a run folder, or a run written by an earlier ehm on "
                                 f"the linear or hybrid route); write one with 'ehm simulate ... --out {run_dir}'.")
        elif not path.is_file():
            raise InputError(f"{path}: no such file; write a run with 'ehm simulate ... --out RUN_DIR'.")
        where = str(path)
        try:
            # the file opened here, so that it is closed also when numpy refuses a damaged archive half-way
            with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as npz:
                poses = {k: npz[k] for k in npz.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
            raise InputError(f"{path}: cannot read it as a pose file: it is truncated, damaged or of another kind "
                             f"({_first_line(exc)}); write the run again with 'ehm simulate ... --out RUN_DIR'."
                             ) from None
    missing = [k for k in _POSE_KEYS + _GEOMETRY_KEYS if k not in poses]
    if missing:
        raise InputError(f"{where}: missing {', '.join(missing)}; write the run again with "
                         "'ehm simulate ... --out RUN_DIR'.")
    t = np.asarray(poses["time_s"], dtype=float)
    pos, quat = np.asarray(poses["pos"], dtype=float), np.asarray(poses["quat"], dtype=float)
    k = len(poses["geometry_segments"])
    m = t.shape[0] if t.ndim == 1 else -1
    if (m < 1 or pos.shape[:1] != (m,) or quat.shape[:1] != (m,) or pos.ndim != 3 or quat.ndim != 3
            or pos.shape[1] not in (k, k + 1) or pos.shape[2] != 3 or quat.shape[1:] != (pos.shape[1], 4)):
        raise InputError(f"{where}: time_s, pos and quat do not fit together (time_s {t.shape}, pos {pos.shape}, "
                         f"quat {quat.shape}, {k} segments).")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(pos)) and np.all(np.isfinite(quat))):
        raise InputError(f"{where}: the poses hold a value that is not a finite number.")
    if m > 1 and not np.all(np.diff(t) > 0):
        raise InputError(f"{where}: time_s does not increase.")
    poses.update(time_s=t, pos=pos, quat=quat)
    return poses


def _first_line(exc: Exception) -> str:
    text = str(exc).strip().splitlines()
    if not text:
        return type(exc).__name__
    if "pickled" in text[0] or "allow_pickle" in text[0]:
        return "it is not a NumPy .npz archive of plain arrays"
    return text[0].rstrip(".")


def _run_title(source) -> str | None:
    """The run's input description from ``summary.json`` next to the poses, if there is one."""
    if isinstance(source, dict):
        return None
    path = Path(source)
    folder = path if path.is_dir() else path.parent
    try:
        text = (folder / "summary.json").read_text(encoding="utf-8")
        title = json.loads(text).get("input")
    except (OSError, ValueError, AttributeError):
        return None
    return str(title) if title else None


def _check_number(name: str, value, low: float, low_ok: bool) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, not {value!r}.") from None
    if not math.isfinite(v) or v < low or (v == low and not low_ok):
        bound = f"at least {low:g}" if low_ok else f"above {low:g}"
        raise InputError(f"{name} must be a finite number {bound}, not {value!r}.")
    return v


# ------------------------------------------------------------------------------------------- geometry
def _quat_to_rot(q: np.ndarray) -> Rotation:
    return Rotation.from_quat(np.asarray(q, dtype=float).reshape(-1, 4), scalar_first=True)


def _scene(poses: dict, idx: np.ndarray, exaggerate: float) -> dict:
    """World geometry of the chosen pose frames: ellipsoid centres and matrices, surface corners."""
    k = len(poses["geometry_segments"])
    pos, quat = poses["pos"][idx], poses["quat"][idx]
    n = len(idx)
    seat = pos.shape[1] == k + 1
    body_pos, body_rot = pos[:, :k], _quat_to_rot(quat[:, :k])
    pos0, rot0 = poses["pos"][0, :k], _quat_to_rot(poses["quat"][0, :k])
    if seat:  # express the body in the seat frame, exaggerate there, draw with the true seat pose
        s_pos, s_rot = pos[:, k], _quat_to_rot(quat[:, k])
        body_pos = np.einsum("nji,nkj->nki", s_rot.as_matrix(), body_pos - s_pos[:, None, :])
        body_rot = _quat_to_rot(np.repeat(quat[:, k], k, axis=0)).inv() * body_rot
        s0_pos, s0_rot = poses["pos"][0, k], _quat_to_rot(poses["quat"][0, k])[0]
        pos0 = s0_rot.inv().apply(pos0 - s0_pos)
        rot0 = s0_rot.inv() * rot0
    rot0_n = Rotation.from_quat(np.tile(rot0.as_quat(), (n, 1)))
    if exaggerate != 1.0:
        body_pos = pos0[None] + exaggerate * (body_pos - pos0[None])
        rel = body_rot * rot0_n.inv()
        body_rot = Rotation.from_rotvec(exaggerate * rel.as_rotvec()) * rot0_n
    Rb = body_rot.as_matrix().reshape(n, k, 3, 3)
    if seat:  # the views turn with the seat's heading: draw the seat's pitch and roll, not its yaw
        S = _without_yaw(s_rot).as_matrix()
        body_pos = s_pos[:, None, :] + np.einsum("nij,nkj->nki", S, body_pos)
        Rb = np.einsum("nij,nkjl->nkil", S, Rb)
    Rs = _quat_to_rot(poses["geometry_shape_quat"]).as_matrix()  # (k, 3, 3)
    centres = body_pos + np.einsum("nkij,kj->nki", Rb, np.asarray(poses["geometry_shape_pos_m"], dtype=float))
    Rw = np.einsum("nkij,kjl->nkil", Rb, Rs)
    a2 = np.asarray(poses["geometry_shape_size_m"], dtype=float) ** 2
    M = np.einsum("nkij,kj,nklj->nkil", Rw, a2, Rw)

    corners = _surface_corners(poses)  # (s, c, 3) world, at rest
    if seat:  # the surfaces ride on the seat frame; at rest the seat frame is unrotated at its pivot
        pivot = poses["pos"][0, k]
        corners = s_pos[:, None, None, :] + np.einsum("nij,scj->nsci", S, corners - pivot)
    else:
        corners = np.broadcast_to(corners, (n,) + corners.shape)
    return {"centres": centres, "M": M, "corners": corners, "time_s": poses["time_s"][idx],
            "surfaces": list(poses["geometry_surfaces"])}


def _without_yaw(r: Rotation) -> Rotation:
    """The seat rotation (intrinsic yaw-pitch-roll, as the seat's hinges) with its yaw set to zero."""
    e = r.as_euler("ZYX")
    e[:, 0] = 0.0
    return Rotation.from_euler("ZYX", e)


def _surface_corners(poses: dict) -> np.ndarray:
    """Corners (s, 8, 3) of every seat surface's drawn shape in world axes at rest (planes repeat 4 corners)."""
    names = [str(s) for s in poses["geometry_surfaces"]]
    kinds = [str(s) for s in poses["geometry_surface_type"]]
    size = np.asarray(poses["geometry_surface_size_m"], dtype=float)
    R = _quat_to_rot(poses["geometry_surface_quat"]).as_matrix()
    centre = np.asarray(poses["geometry_surface_pos_m"], dtype=float)
    out = np.empty((len(names), 8, 3))
    signs = np.array([[1, 1], [1, -1], [-1, -1], [-1, 1]], dtype=float)
    for i, (name, kind) in enumerate(zip(names, kinds)):
        if kind == "box":  # a large box whose top face is the surface: draw that face at a drawing size
            draw = (_FLOOR_HALF_M,) * 2 if name == "floor" else _BOX_DRAW_HALF_M.get(name, (0.25, 0.25))
            hx, hy = (min(s, d) for s, d in zip(size[i, :2], draw))
            local = np.column_stack([signs * [hx, hy], np.full(4, size[i, 2])])
        else:  # a plane: finite drawing half-sizes, normal along local z; the floor spans the whole view
            half = size[i, :2] if name != "floor" else np.full(2, _FLOOR_HALF_M)
            local = np.column_stack([signs * half, np.zeros(4)])
        world = centre[i] + local @ R[i].T
        out[i] = np.vstack([world, world])
    return out


def _ellipse_params(S: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Widths, heights (full axes) and angles [deg] of ellipses with 2x2 matrices S (..., 2, 2)."""
    a, b, c = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    mean, half = (a + c) / 2, np.sqrt(((a - c) / 2) ** 2 + b ** 2)
    major, minor = np.sqrt(np.maximum(mean + half, 0)), np.sqrt(np.maximum(mean - half, 0))
    angle = np.degrees(0.5 * np.arctan2(2 * b, a - c))
    return 2 * major, 2 * minor, angle


def _limits(scene: dict) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Fixed axis limits per view (equal scale in both views), from every frame's ellipses and surfaces."""
    c, M, corners = scene["centres"], scene["M"], scene["corners"]
    floor = np.array([str(s) == "floor" for s in scene["surfaces"]], dtype=bool)
    lo, hi = {}, {}
    for ax in range(3):
        ext = np.sqrt(np.maximum(M[..., ax, ax], 0))
        shapes = corners[:, ~floor, :, ax] if ax < 2 else corners[..., ax]  # the floor only counts for height
        lo[ax] = min(float((c[..., ax] - ext).min()), float(shapes.min(initial=np.inf)))
        hi[ax] = max(float((c[..., ax] + ext).max()), float(shapes.max(initial=-np.inf)))
    half = 0.5 * max(max(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]) * 1.06 + 0.02
    out = []
    for h, v, *_ in _VIEWS:
        ch, cv = 0.5 * (lo[h] + hi[h]), 0.5 * (lo[v] + hi[v])
        out.append(((ch - half, ch + half), (cv - half, cv + half)))
    return out


# -------------------------------------------------------------------------------------------- drawing
class _Renderer:
    """One Agg figure whose artists are moved from frame to frame (no display needed)."""

    def __init__(self, poses: dict, scene: dict, exaggerate: float, size_px: tuple[int, int], title: str | None):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.colors import to_rgb
        from matplotlib.figure import Figure
        from matplotlib.patches import Ellipse, Polygon

        w, h = size_px
        dpi = 100
        self.fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi)
        self.canvas = FigureCanvasAgg(self.fig)
        self.scene = scene
        names = [str(s) for s in poses["geometry_segments"]]
        limits = _limits(scene)
        top = 0.86 if title else 0.92
        self.axes, self.ellipses, self.surfaces = [], [], []
        rest = scene["centres"][0]
        for v, ((_h_ax, _v_ax, d_ax, invert, label, xlabel), (xlim, ylim)) in enumerate(zip(_VIEWS, limits)):
            ax = self.fig.add_axes((0.06 + 0.5 * v, _AXES_BOTTOM, 0.42, top - _AXES_BOTTOM))
            ax.set_xlim(*(xlim[::-1] if invert else xlim))
            ax.set_ylim(*ylim)
            ax.set_aspect("equal", adjustable="box")
            ax.set_title(label, fontsize=9)
            ax.set_xlabel(xlabel, fontsize=8)
            ax.set_ylabel("z up [m]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, color="0.92", linewidth=0.6)
            ax.set_axisbelow(True)
            surf = []
            for _ in range(scene["corners"].shape[1]):
                p = Polygon(np.zeros((8, 2)), closed=True, facecolor="#b8b8c4", edgecolor="#6a6a78",
                            linewidth=1.2, alpha=0.75, zorder=1.0, joinstyle="round")
                ax.add_patch(p)
                surf.append(p)
            ells = []
            depth_rest = rest[:, d_ax]
            for i, name in enumerate(names):
                base = next((c for key, c in _SEGMENT_COLORS.items() if name.startswith(key)), "#8899aa")
                shade = 0.78 if d_ax == 1 and depth_rest[i] < -0.03 else 1.0  # the far (right) side darker
                face = tuple(min(1.0, ch * shade) for ch in to_rgb(base))
                e = Ellipse((0, 0), 0, 0, angle=0, facecolor=face, edgecolor="#1e2430", linewidth=0.8, zorder=2.0)
                ax.add_patch(e)
                ells.append(e)
            self.axes.append(ax)
            self.ellipses.append(ells)
            self.surfaces.append(surf)
        if title:
            self.fig.text(0.5, 0.965, title, ha="center", va="top", fontsize=10)
        self.clock = self.fig.text(0.015, 0.015, "", ha="left", va="bottom", fontsize=11, family="monospace")
        self.fig.text(0.985, 0.015, motion_label(exaggerate), ha="right", va="bottom", fontsize=10,
                      color="#a02020" if exaggerate != 1 else "0.2")
        for artist in [self.clock, *sum(self.ellipses, []), *sum(self.surfaces, [])]:
            artist.set_animated(True)  # left out of the background
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)
        # Per view and frame: ellipse parameters and stacking order, computed for all frames at once.
        self.params = []
        for h_ax, v_ax, d_ax, *_ in _VIEWS:
            S = scene["M"][..., [h_ax, v_ax], :][..., [h_ax, v_ax]]
            wdt, hgt, ang = _ellipse_params(S)
            order = np.argsort(np.argsort(scene["centres"][..., d_ax], axis=1), axis=1)
            self.params.append((scene["centres"][..., [h_ax, v_ax]], wdt, hgt, ang, 2.0 + 0.01 * order,
                                scene["corners"][..., [h_ax, v_ax]]))

    def frame(self, j: int) -> np.ndarray:
        for v in range(len(_VIEWS)):
            centres, wdt, hgt, ang, z, corners = self.params[v]
            for i, e in enumerate(self.ellipses[v]):
                e.set_center(centres[j, i])
                e.set_width(wdt[j, i])
                e.set_height(hgt[j, i])
                e.set_angle(ang[j, i])
                e.set_zorder(z[j, i])
            for s, p in enumerate(self.surfaces[v]):
                p.set_xy(_hull(corners[j, s]))
        self.clock.set_text(f"t = {self.scene['time_s'][j]:.2f} s")
        # Blitting: the axes, ticks and labels are drawn once; per frame only the moving artists.
        self.canvas.restore_region(self.background)
        for v, ax in enumerate(self.axes):
            for artist in sorted(self.surfaces[v] + self.ellipses[v], key=lambda a: a.get_zorder()):
                ax.draw_artist(artist)
        self.fig.draw_artist(self.clock)
        rgba = np.asarray(self.canvas.buffer_rgba())
        return np.ascontiguousarray(rgba[..., :3])

    def close(self) -> None:
        self.fig.clear()


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise) of 2-D points; a degenerate set gives its extreme points."""
    pts = sorted(set(map(tuple, np.round(points, 6))))  # to a micrometre: no slivers from round-off
    if len(pts) <= 2:
        return np.array(pts if pts else [(0.0, 0.0)])

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def motion_label(exaggerate: float) -> str:
    """What the picture says of its scale: ``motion x20 (exaggerated; --exaggerate 1: true scale)`` or
    ``motion true scale``."""
    if exaggerate == 1:
        return "motion true scale (x1)"
    return f"motion x{exaggerate:g} (exaggerated; --exaggerate 1 for true scale)"


def auto_exaggeration(poses: dict, idx: np.ndarray | None = None) -> float:
    """The factor that makes a run's motion visible: the segment that moves most (its drawn centre, from the first
    pose) travels :data:`AUTO_SHARE` of a view's width, no segment turns by more than :data:`AUTO_MAX_TURN_DEG`;
    one of 1, 2, 5 times a power of ten, from 1 (the motion is visible at true scale, or there is none:
    :data:`AUTO_MIN_MOTION_M`) to :data:`AUTO_MAX`."""
    return _auto(poses, idx)[0]


def _auto(poses: dict, idx: np.ndarray | None) -> tuple[float, str]:
    """:func:`auto_exaggeration`'s factor and why, in words."""
    idx = np.arange(len(poses["time_s"])) if idx is None else np.asarray(idx, dtype=int)
    idx = np.union1d([0], idx)  # the first pose is the reference of the motion
    k = len(poses["geometry_segments"])
    pos, quat = np.asarray(poses["pos"], float)[idx], np.asarray(poses["quat"], float)[idx]
    n = len(idx)
    body_pos, body_rot = pos[:, :k], _quat_to_rot(quat[:, :k].reshape(-1, 4))
    if pos.shape[1] == k + 1:  # a rotating seat: the body's motion in the seat's frame, as it is exaggerated
        s_rot = _quat_to_rot(quat[:, k])
        body_pos = np.einsum("nji,nkj->nki", s_rot.as_matrix(), body_pos - pos[:, k][:, None, :])
        body_rot = _quat_to_rot(np.repeat(quat[:, k], k, axis=0)).inv() * body_rot
    R = body_rot.as_matrix().reshape(n, k, 3, 3)
    centres = body_pos + np.einsum("nkij,kj->nki", R, np.asarray(poses["geometry_shape_pos_m"], dtype=float))
    moved = float(np.max(np.linalg.norm(centres - centres[0][None], axis=-1)))
    rel = body_rot * Rotation.from_quat(np.tile(body_rot[:k].as_quat(), (n, 1))).inv()
    turn_deg = float(np.degrees(np.max(rel.magnitude())))
    (xlim, _), _ = _limits(_scene(poses, idx[:1], 1.0))  # the view's width at rest
    width = xlim[1] - xlim[0]
    if moved < AUTO_MIN_MOTION_M:
        return 1.0, f"the body hardly moves ({1e3 * moved:.2g} mm at most): nothing to exaggerate"
    want = AUTO_SHARE * width / moved
    if turn_deg > 0:
        want = min(want, AUTO_MAX_TURN_DEG / turn_deg)
    if want <= 1.0:
        return 1.0, f"the motion ({1e3 * moved:.3g} mm at most) is visible as it is"
    nice = [m * 10 ** e for e in range(4) for m in (1, 2, 5)]
    factor = float(max([f for f in nice if f <= min(want, AUTO_MAX)], default=1.0))
    return factor, (f"chosen to make the motion visible: the largest, {1e3 * moved:.3g} mm, drawn as "
                    f"{factor * 1e3 * moved:.3g} mm")


def _frame_indices(t: np.ndarray, times_s) -> np.ndarray:
    """Index of the pose nearest each requested time."""
    ts = np.atleast_1d(np.asarray(times_s, dtype=float))
    if ts.ndim != 1 or not np.all(np.isfinite(ts)):
        raise InputError("times_s must be finite times in seconds.")
    j = np.clip(np.searchsorted(t, ts), 1, max(1, len(t) - 1)) if len(t) > 1 else np.zeros(len(ts), int)
    if len(t) > 1:
        j = np.where(np.abs(ts - t[j - 1]) <= np.abs(t[j] - ts), j - 1, j)
    return j.astype(int)


def _iter_frames(source, idx: np.ndarray | None = None, times_s=None, exaggerate: float = 1.0,
                 size_px=(960, 480), title: str | None = None) -> Iterator[np.ndarray]:
    poses = load_poses(source)
    exaggerate = _check_number("the exaggeration factor", exaggerate, 0.0, True)
    try:
        w, h = (int(v) for v in size_px)
    except (TypeError, ValueError):
        raise InputError(f"size_px must be (width, height) in pixels, not {size_px!r}.") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise InputError(f"size_px {size_px!r} is out of range (16 to 8192 pixels each way).")
    if idx is None:
        idx = np.arange(len(poses["time_s"])) if times_s is None else _frame_indices(poses["time_s"], times_s)
    if len(idx) == 0:
        return
    if title is None:
        title = _run_title(source)
    scene = _scene(poses, np.asarray(idx, dtype=int), exaggerate)
    renderer = _Renderer(poses, scene, exaggerate, (w, h), title)
    try:
        for j in range(len(idx)):
            yield renderer.frame(j)
    finally:
        renderer.close()


def render_frames(poses_npz_path_or_dict, times_s=None, exaggerate: float = 1.0, size_px=(960, 480),
                  title: str | None = None) -> list[np.ndarray]:
    """Draw the person and the seat at the given times; returns RGB frames, (height, width, 3) uint8 each.

    Parameters
    ----------
    poses_npz_path_or_dict : path or dict
        A run folder, its ``poses.npz``, or the arrays of one (``RunResult.poses``).
    times_s : array of float, optional
        Times to draw [s]; each picks the nearest pose (default: every pose).
    exaggerate : float
        Factor on each segment's displacement and rotation from the first pose (default 1: true scale).
    size_px : (width, height)
        Frame size in pixels (default 960 x 480).
    title : str, optional
        Caption over the views (default: the run's input from ``summary.json`` next to the poses).

    Axis limits are fixed over the frames of one call.
    """
    return list(_iter_frames(poses_npz_path_or_dict, times_s=times_s, exaggerate=exaggerate, size_px=size_px,
                             title=title))


# --------------------------------------------------------------------------------------------- output
def _select(t: np.ndarray, fps: float, start_s, end_s, max_frames) -> np.ndarray:
    """Pose indices of an animation at ``fps`` over the window (nearest pose per frame time)."""
    t0, t1 = float(t[0]), float(t[-1])
    start = t0 if start_s is None else _check_number("--start", start_s, -math.inf, True)
    end = t1 if end_s is None else _check_number("--end", end_s, -math.inf, True)
    if start_s is not None and end_s is not None and not end > start:
        raise InputError(f"--start {start:g} and --end {end:g}: the end must be after the start.")
    if start > t1 or end < t0:
        raise InputError(f"the time window {start:g} to {end:g} s holds no poses: the run's poses span "
                         f"{t0:g} to {t1:g} s.")
    start, end = max(start, t0), min(end, t1)
    n = int(math.floor((end - start) * fps + 1e-6)) + 1
    if n > 100_000 and max_frames is None:
        raise InputError(f"--fps {fps:g} over {end - start:g} s gives {n} frames; lower --fps or set --max-frames "
                         "(at most 100000 frames).")
    if max_frames is not None:
        if isinstance(max_frames, bool) or not float(max_frames).is_integer() or int(max_frames) < 1:
            raise InputError(f"--max-frames must be a whole number of at least 1, not {max_frames!r}.")
        n = min(n, int(max_frames))
    return _frame_indices(t, start + np.arange(n) / fps)


def _check_out(out: Path) -> str:
    suffix = out.suffix.lower()
    if suffix not in _FORMATS:
        raise InputError(f"{out}: unknown animation format {out.suffix or '(no extension)'!r}; "
                         "use .gif or .mp4.")
    if out.is_dir():
        raise InputError(f"{out} is a folder; give a file name ending in .gif or .mp4.")
    return suffix


def _mp4_writer_module():
    try:
        import imageio.v2 as iio
        import imageio_ffmpeg
        imageio_ffmpeg.get_ffmpeg_exe()
    except Exception:  # missing package or bundled binary
        raise InputError(_MP4_MISSING) from None
    return iio


def _write_gif(frames: Iterator[np.ndarray], path: str, fps: float) -> int:
    from PIL import Image

    images, palette = [], None
    for f in frames:
        im = Image.fromarray(f, mode="RGB")
        if palette is None:  # one palette for all frames: no flicker, and fast
            palette = im.quantize(colors=128, method=Image.Quantize.MAXCOVERAGE, dither=Image.Dither.NONE)
            images.append(palette)
        else:
            images.append(im.quantize(palette=palette, dither=Image.Dither.NONE))
    if not images:
        raise InputError("no frames to write.")
    images[0].save(path, format="GIF", save_all=True, append_images=images[1:],
                   duration=max(20, int(round(1000.0 / fps))), loop=0)
    return len(images)


def _write_mp4(frames: Iterator[np.ndarray], path: str, fps: float, iio) -> int:
    n = 0
    writer = iio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=7,
                            macro_block_size=16, ffmpeg_log_level="error")
    try:
        for f in frames:
            writer.append_data(f)
            n += 1
    finally:
        writer.close()
    if n == 0:
        raise InputError("no frames to write.")
    return n


#: The animation's file name in its run folder when none is given.
DEFAULT_NAME = "animation.gif"


def animate(run_dir, out=None, exaggerate: float | str = "auto", fps: float = 25.0, start_s: float | None = None,
            end_s: float | None = None, max_frames: int | None = None, progress=None) -> Path:
    """Write an animation (``.gif`` or ``.mp4``) of a run folder's ``poses.npz``; returns the file written.

    ``out`` defaults to ``RUN_DIR/animation.gif``.  Frames are taken at ``fps`` over ``start_s`` to ``end_s``
    (default: the whole run), each showing the nearest pose, at most ``max_frames`` of them (the first ones).
    ``exaggerate`` scales the motion from the first pose: ``"auto"`` (the default) picks the factor that makes it
    visible (:func:`auto_exaggeration`: 1 when it is visible at true scale), a number sets it (1: true scale); the
    picture states it.  ``progress(done, total)`` is called after each frame.  The file is written whole or not at
    all.  Drawn into ``run_dir`` itself (a run folder of ehm's), it is listed in the folder's manifest, so that the
    next run may still replace the folder whole.
    """
    if progress is not None and not callable(progress):
        raise InputError(f"progress must be a function progress(done, total) or None, not {type(progress).__name__}.")
    if not isinstance(run_dir, (str, os.PathLike)) or not (out is None or isinstance(out, (str, os.PathLike))):
        raise InputError("animate: give the run folder (and the animation file, or None for RUN_DIR/animation.gif) "
                         f"as paths, not {type(run_dir).__name__} and {type(out).__name__}.")
    out = Path(run_dir) / DEFAULT_NAME if out is None else Path(out)
    suffix = _check_out(out)
    fps = _check_number("--fps", fps, 0.0, False)
    auto = isinstance(exaggerate, str) and exaggerate == "auto"
    if not auto:
        exaggerate = _check_number("--exaggerate", exaggerate, 0.0, True)
    iio = _mp4_writer_module() if suffix == ".mp4" else None
    poses = load_poses(run_dir)
    idx = _select(poses["time_s"], fps, start_s, end_s, max_frames)
    if auto:
        exaggerate = auto_exaggeration(poses, idx)
    frames = _counted(_iter_frames(poses, idx=idx, exaggerate=exaggerate, title=_run_title(run_dir)), len(idx),
                      progress)
    try:
        replace_atomically(out, lambda tmp: _write_gif(frames, tmp, fps) if suffix == ".gif"
                           else _write_mp4(frames, tmp, fps, iio), "the animation")
    finally:
        frames.close()
    if out.parent.resolve() == Path(run_dir).resolve():
        record_in_manifest(out, run_dir)
    return out


def pick_exaggeration(run_dir, fps: float = 25.0, start_s: float | None = None, end_s: float | None = None,
                      max_frames: int | None = None) -> tuple[float, str]:
    """The factor ``animate(..., exaggerate="auto")`` draws a run folder's frames with (:func:`auto_exaggeration`
    over the same frames), and why, in words (what ``ehm animate`` prints)."""
    fps = _check_number("--fps", fps, 0.0, False)
    poses = load_poses(run_dir)
    return _auto(poses, _select(poses["time_s"], fps, start_s, end_s, max_frames))


def _counted(frames: Iterator[np.ndarray], total: int, progress) -> Iterator[np.ndarray]:
    """The frames, calling ``progress(done, total)`` after each one is drawn."""
    try:
        for done, frame in enumerate(frames, 1):
            yield frame
            if progress is not None:
                progress(done, total)
    finally:
        frames.close()

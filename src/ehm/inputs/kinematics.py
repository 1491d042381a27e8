"""Seat rotation kinematics: the seat's attitude from its body-axis angular velocity, as z-y-x angles with their
rates and accelerations, and the rotation matrices of those angles.

``ehm.inputs.motion.seat_kinematics`` (and the other names here) are the same functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["SeatKinematics", "integrate_attitude", "seat_kinematics", "seat_rotation_matrices"]



@dataclass(frozen=True, eq=False)
class SeatKinematics:
    """Seat orientation as intrinsic z-y-x (yaw, pitch, roll) angles, with their rates and accelerations.

    All arrays have shape (n, 3) with columns yaw, pitch, roll, on the time grid ``time_s`` [s]; angles in
    rad, rates in rad/s, accelerations in rad/s^2.  The seat starts level (all angles 0) at ``time_s[0]``.
    """

    time_s: np.ndarray
    angles_rad: np.ndarray
    rates_radps: np.ndarray
    accs_radps2: np.ndarray

    def at(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angles, rates and accelerations linearly interpolated at times ``t_s`` (relative to the start)."""
        t0 = self.time_s - self.time_s[0]
        out = []
        for arr in (self.angles_rad, self.rates_radps, self.accs_radps2):
            out.append(np.column_stack([np.interp(t_s, t0, arr[:, j]) for j in range(3)]))
        return out[0], out[1], out[2]


def integrate_attitude(time_s: np.ndarray, angvel_radps: np.ndarray, initial_quat=None) -> np.ndarray:
    """Attitude quaternions (n, 4), scipy's scalar-last order, from body-axis angular velocity [rad/s].

    q(k+1) = q(k) * exp(w dt / 2) with w the mean of the two samples' rates (exact for rates constant over
    a step), starting from ``initial_quat`` (default: the identity), renormalised every 1024 steps.
    """
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(angvel_radps, dtype=float)
    # step rotations as quaternions (w, x, y, z) from rotation vectors, vectorised
    rv = 0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None]
    ang = np.linalg.norm(rv, axis=1)
    half = 0.5 * ang
    scale = np.where(ang > 1e-12, np.sin(half) / np.where(ang > 1e-12, ang, 1.0), 0.5)
    steps = np.column_stack([np.cos(half), rv * scale[:, None]])
    del rv, ang, half, scale
    # sequential Hamilton products in plain floats (a few microseconds per sample), a block of steps at a time
    # (plain floats take about 40 bytes each: a whole long drive of them would hold hundreds of MB)
    quats = np.empty((t.size, 4))
    if initial_quat is None:
        qw, qx, qy, qz = 1.0, 0.0, 0.0, 0.0
    else:
        qx, qy, qz, qw = (float(v) for v in initial_quat)
    quats[0] = (qw, qx, qy, qz)
    for b in range(0, steps.shape[0], 8192):
        for k, (sw, sx, sy, sz) in enumerate(steps[b:b + 8192].tolist(), start=b + 1):
            qw, qx, qy, qz = (qw * sw - qx * sx - qy * sy - qz * sz, qw * sx + qx * sw + qy * sz - qz * sy,
                              qw * sy - qx * sz + qy * sw + qz * sx, qw * sz + qx * sy - qy * sx + qz * sw)
            if k % 1024 == 0:  # keep unit length against round-off
                n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
                qw, qx, qy, qz = qw / n, qx / n, qy / n, qz / n
            quats[k] = (qw, qx, qy, qz)
    del steps
    return quats[:, [1, 2, 3, 0]]  # scipy's (x, y, z, w) order


def seat_kinematics(time_s: np.ndarray, angvel_radps: np.ndarray) -> SeatKinematics:
    """Integrate the seat's body-axis angular velocity (roll, pitch, yaw rates) into z-y-x Euler angles.

    The orientation is integrated as a quaternion, q(k+1) = q(k) * exp(w dt / 2) with w the mean of the two
    samples' rates (exact for rates constant over a step), then expressed as yaw, pitch, roll (yaw
    unwrapped).  The Euler-angle rates follow from the body rates w = (wx, wy, wz) and roll phi, pitch
    theta: roll' = wx + tan(theta) (wy sin(phi) + wz cos(phi)), pitch' = wy cos(phi) - wz sin(phi),
    yaw' = (wy sin(phi) + wz cos(phi)) / cos(theta); accelerations are their time derivatives.  Pitch must
    stay within +-80 deg.
    """
    from scipy.spatial.transform import Rotation

    t = np.asarray(time_s, dtype=float)
    w = np.asarray(angvel_radps, dtype=float)
    quats = integrate_attitude(t, w)
    yaw, pitch, roll = Rotation.from_quat(quats).as_euler("ZYX").T
    if np.abs(pitch).max() > np.radians(80):
        i = int(np.argmax(np.abs(pitch) > np.radians(80)))
        raise InputError(f"the seat pitch reaches {np.degrees(pitch[i]):.0f} deg at t = {t[i] - t[0]:.2f} s when its "
                         "angular velocities are integrated (it must stay within +-80 deg): check their unit "
                         "(--unit wx=deg/s ... if they are in deg/s), their axes (--mounting), and that they are the "
                         "seat's own rates, not rates in earth axes.")
    angles = np.column_stack([np.unwrap(yaw), pitch, roll])
    s, c = np.sin(roll), np.cos(roll)
    rates = np.column_stack([
        (w[:, 1] * s + w[:, 2] * c) / np.cos(pitch),             # yaw'
        w[:, 1] * c - w[:, 2] * s,                               # pitch'
        w[:, 0] + np.tan(pitch) * (w[:, 1] * s + w[:, 2] * c),   # roll'
    ])
    accs = np.gradient(rates, t, axis=0)
    return SeatKinematics(t, angles, rates, accs)


def seat_rotation_matrices(angles_rad: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of z-y-x angles (yaw, pitch, roll): seat axes -> world axes."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("ZYX", angles_rad).as_matrix()

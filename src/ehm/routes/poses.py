"""The segments' poses on the linear and hybrid routes, for pictures (``poses.npz``, ``ehm.outputs.animation``).

The linear model's state holds every joint's deviation from the settled posture, so the poses follow from it
through the model's kinematics (``ehm.engine.deviation_poses``), only at the pose rate: the modal state is
carried from pose to pose in one product per stretch (:meth:`PoseGrid.linear`), never per model step.  The
nonlinear windows record theirs as the nonlinear route does, on the same grid of steps (every ``every``-th step
of the drive from its first), so that the pieces join into one even series.
"""

from __future__ import annotations

import numpy as np

from .. import engine
from ..inputs.kinematics import seat_rotation_matrices
from .linear import advance, modal_form, scan, state_of


class PoseGrid:
    """Poses every ``every`` steps of the drive (from step 0) for one person and linear model.

    ``kin``: the drive's seat kinematics (``ehm.inputs.kinematics.seat_kinematics``) when it turns the seat, else None.
    """

    def __init__(self, human, ss, blk, dt: float, pose_rate_hz: float, kin=None):
        self.model, self.ss, self.blk, self.dt, self.kin = human.model, ss, blk, dt, kin
        self.static = human.static_model if human.model.seat is not None else None
        self.every = max(1, int(round(1.0 / (pose_rate_hz * dt))))
        self.geometry = {f"geometry_{k}": v for k, v in engine.drawing_geometry(human.model).items()}
        m = modal_form(ss)
        # the modal state one pose period on: z~ -> phi^every z~ + sum_i phi^(every-1-i) Bd u[i]
        P = blk.phi[None, :] ** np.arange(self.every - 1, -1, -1)[:, None]  # (every, m)
        G = (P[:, None, :] * blk.Bd.T[None, :, :]).reshape(-1, m.lam.size)  # (every nu, m)
        self.drive = np.ascontiguousarray(np.stack([G.real, G.imag], axis=2).reshape(G.shape[0], -1))  # real inputs
        self.phi_every = blk.phi ** self.every
        self.none = engine.deviation_poses(self.model, np.zeros((0, ss.A.shape[0])))  # no pose: (0, k, 3), (0, k, 4)

    def first(self, a: int) -> int:
        """Steps from sample ``a`` to the first pose at or after it."""
        return (-a) % self.every

    def linear(self, a: int, b: int, carry: np.ndarray, inputs: np.ndarray, offset: np.ndarray) -> dict:
        """Poses at the grid's steps in samples a ... b - 1 from the linear model's modal state ``carry`` at ``a``
        (not changed), its inputs there ``inputs`` (b - a, nu) and the constant state ``offset``."""
        steps = np.arange(a + self.first(a), b, self.every)
        if steps.size == 0:
            return self._poses(steps, *self.none)
        z = carry.copy()
        k0 = steps[0] - a
        if k0:
            advance(self.blk, inputs[:k0], z)
        n_u = inputs.shape[1]
        U = inputs[k0:k0 + (steps.size - 1) * self.every].reshape(steps.size - 1, self.every * n_u)
        Z = scan(self.phi_every, (U @ self.drive).view(complex), z)  # the modal states at the poses
        x = state_of(self.ss, self.blk, Z, inputs[steps - a]) + offset
        R = angles = None
        if self.static is not None:
            angles = self.kin.at(steps * self.dt)[0] if self.kin is not None else np.zeros((steps.size, 3))
            R = seat_rotation_matrices(angles)
        pos, quat = engine.deviation_poses(self.model, x, self.static, R, angles)
        return self._poses(steps, pos, quat)

    def of_raw(self, raw, a: int) -> dict:
        """The poses a nonlinear run from sample ``a`` recorded (``engine.run(..., pose_every=self.every,
        pose_first=self.first(a))``)."""
        return self._poses(a + raw.poses["step"], raw.poses["pos"], raw.poses["quat"])

    def _poses(self, steps: np.ndarray, pos: np.ndarray, quat: np.ndarray) -> dict:
        return {"time_s": steps * self.dt, "pos": pos, "quat": quat, **self.geometry}

"""Inverse kinematics of one arm by damped least squares on a site Jacobian, on a private ``MjData``.

Frames and units: targets are world-frame poses of a site (position m, quaternion [w, x, y, z]); joint angles in
rad. The solver never touches the live simulation: it owns an ``MjData`` of the same model and writes only the
arm's joints into it.

Iteration (Levenberg-Marquardt form of damped least squares), for the arm's joints q (n,):
    e  = [p_target - p_site ; L * log(R_target R_site^T)]        (6,), the rotation error as a world rotation vector
    J  = [J_pos ; L * J_rot]                                     (6, n), from ``mj_jacSite``
    dq = J^T (J J^T + lambda^2 I)^-1 e + N (k_home (q_home - q)),  N = I - J^T (J J^T)^-1 J (task nullspace)
    q  = clip(q + dq, joint range)
``L`` (:attr:`IKSettings.rotation_length`) makes metres and radians comparable. The nullspace pull keeps a
redundant arm (n > 6) near its home posture: its solve continues after the task converged until the pull is below
``posture_tolerance``. A 6-DOF arm has no task nullspace away from singularities (the term is skipped: with the
damped inverse it would only bias the solution by ~lambda^2), and its posture is kept by seeding from the current or
home configuration (the nearest IK branch).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from cosim.errors import InputError
from cosim.frames import vector_norm
from declared_settings.setting import check_settings, documented, setting

# Regularisation of J J^T in the nullspace projector (full-rank rows assumed; only guards exact singularity).
_NULLSPACE_REG = 1e-12


IK = "inverse kinematics"


@documented
@dataclass(frozen=True)
class IKSettings:
    """Solver settings."""

    position_tolerance: float = setting(1e-6, IK, "Converged when the site position error is below this.", "m", 0.0,
                                        0.01, lo_open=True)
    rotation_tolerance: float = setting(1e-6, IK, "And the rotation error below this.", "rad", 0.0, 0.1, lo_open=True)
    max_iterations: int = setting(100, IK, "Iterations before giving up.", "", 1, 10000)
    damping: float = setting(1e-4, IK, "lambda of the damped least squares, in units of the (weighted) error.", "m",
                             0.0, 1.0, lo_open=True)
    max_step: float = setting(0.4, IK, "Largest joint change per iteration.", "rad", 0.0, 3.15, lo_open=True)
    rotation_length: float = setting(0.2, IK, "Weight L of the rotation error against the position error.", "m", 0.0,
                                     10.0, lo_open=True)
    posture_gain: float = setting(0.5, IK, "Fraction of the home-posture error pulled in per iteration in the task "
                                  "nullspace (redundant arms, n > 6).", "", 0.0, 1.0)
    posture_tolerance: float = setting(1e-3, IK, "A redundant arm's solve ends when the nullspace pull toward home is "
                                       "below this (or at max_iterations with the task reached).", "rad", 0.0, 1.0,
                                       lo_open=True)
    stall_iterations: int = setting(8, IK, "Stop early when the error has not dropped by 1% in this many iterations.",
                                    "", 1, 10000)

    def __post_init__(self) -> None:
        check_settings(self, "ik")


@dataclass(frozen=True)
class IKResult:
    """Outcome of one solve: joint angles q (n,) rad, remaining errors, iterations, convergence."""

    q: np.ndarray
    position_error: float  # m
    rotation_error: float  # rad
    iterations: int
    converged: bool


def rotation_error(target_mat: np.ndarray, current_mat: np.ndarray) -> np.ndarray:
    """World-frame rotation vector (3,) rad that turns ``current_mat`` into ``target_mat`` (both 3x3)."""
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, (target_mat @ current_mat.T).ravel())
    if quat[0] < 0.0:
        quat = -quat
    vec = quat[1:]
    sin_half = float(vector_norm(vec))
    if sin_half < 1e-12:
        return 2.0 * vec
    return (2.0 * math.atan2(sin_half, quat[0]) / sin_half) * vec


class ArmIK:
    """Damped-least-squares IK for the site ``site`` moved by ``joints`` of ``model``.

    joints: names of the arm's hinge/slide joints (n), base to tip; the solution vector follows this order.
    home_q: (n,) rad, the posture the nullspace term pulls toward.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        joints: tuple[str, ...],
        site: str,
        home_q: np.ndarray,
        settings: IKSettings = IKSettings(),
    ) -> None:
        self.model = model
        self.settings = settings
        self.site_id = model.site(site).id
        ids = [model.joint(name).id for name in joints]
        self.qpos_adr = np.array([model.jnt_qposadr[i] for i in ids])
        self.dof_adr = np.array([model.jnt_dofadr[i] for i in ids])
        limited = np.array([bool(model.jnt_limited[i]) for i in ids])
        ranges = np.array([model.jnt_range[i] for i in ids])
        self.lower = np.where(limited, ranges[:, 0], -np.inf)
        self.upper = np.where(limited, ranges[:, 1], np.inf)
        self.home_q = np.asarray(home_q, dtype=float).copy()
        self._data = mujoco.MjData(model)  # private: never the live simulation's data
        self._jacp = np.zeros((3, model.nv))
        self._jacr = np.zeros((3, model.nv))
        n = len(ids)
        self._jac = np.empty((6, n))  # the weighted task Jacobian [J_pos ; L J_rot], filled each iteration
        self._err = np.empty(6)  # the weighted error [e_pos ; L e_rot]
        self._damping2 = settings.damping**2 * np.eye(6)
        self._redundant = n > 6 and settings.posture_gain > 0.0

    def solve(self, target_pos: np.ndarray, target_quat: np.ndarray, seed_q: np.ndarray) -> IKResult:
        """Solve for the site pose ``target_pos`` (3,) m, ``target_quat`` (4,) [w, x, y, z] from ``seed_q`` (n,) rad.

        Never raises for an unreachable target: see :attr:`IKResult.converged` and :meth:`solve_or_raise`.
        """
        s = self.settings
        model, data = self.model, self._data
        target_pos = np.asarray(target_pos, dtype=float)
        target_mat = np.empty(9)
        mujoco.mju_quat2Mat(target_mat, np.asarray(target_quat, dtype=float) / vector_norm(target_quat))
        target_mat = target_mat.reshape(3, 3)
        q = np.clip(np.asarray(seed_q, dtype=float).copy(), self.lower, self.upper)
        n = q.size
        damping2, redundant, jac, err = self._damping2, self._redundant, self._jac, self._err
        best_norm, best_iter = math.inf, 0
        err_p = err_r = math.inf
        task_ok = False
        iteration = 0
        for iteration in range(1, s.max_iterations + 1):
            data.qpos[self.qpos_adr] = q
            mujoco.mj_kinematics(model, data)
            e_pos = target_pos - data.site_xpos[self.site_id]
            e_rot = rotation_error(target_mat, data.site_xmat[self.site_id].reshape(3, 3))
            err_p, err_r = float(vector_norm(e_pos)), float(vector_norm(e_rot))
            task_ok = err_p <= s.position_tolerance and err_r <= s.rotation_tolerance
            if task_ok and not redundant:
                return IKResult(q, err_p, err_r, iteration, True)
            if not task_ok:
                norm = err_p + s.rotation_length * err_r
                if norm < 0.99 * best_norm:
                    best_norm, best_iter = norm, iteration
                elif iteration - best_iter >= s.stall_iterations:
                    break
            mujoco.mj_comPos(model, data)
            mujoco.mj_jacSite(model, data, self._jacp, self._jacr, self.site_id)
            # the arrays' own methods (what numpy's functions of the same names call, without their dispatch)
            self._jacp.take(self.dof_adr, axis=1, out=jac[:3])
            np.multiply(s.rotation_length, self._jacr.take(self.dof_adr, axis=1), out=jac[3:])
            err[:3] = e_pos
            np.multiply(s.rotation_length, e_rot, out=err[3:])
            dq = np.linalg.solve(jac @ jac.T + damping2, jac).T @ err  # J^T (J J^T + l^2 I)^-1 e
            if redundant:  # pull toward home in the exact task nullspace until that pull is negligible
                nullspace = np.eye(n) - jac.T @ np.linalg.solve(jac @ jac.T + _NULLSPACE_REG * np.eye(6), jac)
                pull = nullspace @ (self.home_q - q)
                if task_ok and float(np.max(np.abs(pull))) <= s.posture_tolerance:
                    return IKResult(q, err_p, err_r, iteration, True)
                dq += s.posture_gain * pull
            largest = float(np.abs(dq).max())
            if largest > s.max_step:
                dq *= s.max_step / largest
            q = (q + dq).clip(self.lower, self.upper)
        return IKResult(q, err_p, err_r, iteration, task_ok)

    def solve_or_raise(
        self, target_pos: np.ndarray, target_quat: np.ndarray, seed_q: np.ndarray, label: str
    ) -> np.ndarray:
        """Like :meth:`solve` but returns q (n,) rad, or raises ``InputError`` naming ``label`` and the distance left."""
        result = self.solve(target_pos, target_quat, seed_q)
        if not result.converged:
            x, y, z = np.asarray(target_pos, dtype=float)
            raise InputError(
                f"{label}: unreachable, the closest pose found is {result.position_error * 1000:.1f} mm and "
                f"{math.degrees(result.rotation_error):.2f} deg away (vessel frame target at x={x:.3f} y={y:.3f} "
                f"z={z:.3f} m)"
            )
        return result.q

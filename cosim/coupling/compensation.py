"""What an arm's controller feeds forward of the liquid it holds (two-way coupling), as a real arm would.

A UR controller compensates a payload: its mass ``m`` and centre of gravity ``c`` in the tool frame, entered in the
installation or set by ``set_payload`` in a program. It adds the joint torques that hold that payload's weight at the
current configuration, ``tau_ff = -J_c(q)^T m g`` (``J_c`` the positional Jacobian at ``c`` in the world, ``g`` the
gravity vector), and its servos feel the rest of what acts on the tool. :class:`Compensation` chooses the model:

* ``STATIC_PAYLOAD``: the liquid at the start, ``V0`` at rest in the upright vessel: ``m = rho V0``, ``c = (0, 0, V0 /
  (2 A))`` in the vessel frame (``A`` the inner floor area); the catcher starts empty. The servos feel the slosh, the
  liquid's inertia, its centre of mass moving as the pourer tilts, the mass leaving, and the catch.
* ``UPDATED_PAYLOAD``: the same model, re-set every control period to the volume each vessel holds.
* ``IDEAL_FORCE_TORQUE``: the measured liquid wrench itself, ``tau_ff = -J^T w``, with the wrench, Jacobian and step
  of ``xfrc_applied``: the two cancel exactly (a perfect, zero-delay wrist force-torque sensor) and the arms move as
  in a one-way run.
* ``NONE``: nothing; the servos carry the whole liquid.

The vessel's own mass is the model's (body gravity compensation through the actuators, :mod:`cosim.robots.scene`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cosim.coupling.settings import Compensation
from cosim.frames import Pose
from cosim.robots.scene import RobotScene, shift_wrench
from cosim.robots.scene_config import ArmRole
from cosim.vessel import VesselSpec


@dataclass(frozen=True)
class Payload:
    """A payload setting: mass (kg) and centre of gravity ``com_local`` (3,) m in the vessel frame."""

    mass: float
    com_local: np.ndarray


def liquid_payload(vessel: VesselSpec, volume: float, density: float) -> Payload:
    """``volume`` (m^3) of liquid of ``density`` (kg/m^3) at rest in the upright ``vessel``: a layer of height
    ``volume / A`` over the inner floor, its centre half as high."""
    return Payload(density * volume, np.array([0.0, 0.0, 0.5 * volume / vessel.inner_floor_area]))


def compensation_torque(
    scene: RobotScene,
    role: ArmRole,
    compensation: Compensation,
    force: np.ndarray,
    torque: np.ndarray,
    payload: Payload | None,
    frame: Pose,
) -> np.ndarray | None:
    """Feedforward joint torques (n,) N m of ``role``'s arm at its current configuration, or None (``NONE``).

    The scene's kinematics must be those of its current configuration (``mj_forward``, or ``mj_kinematics`` and
    ``mj_comPos`` since the positions last changed, as :func:`cosim.coupling.loop.coupled_step` keeps them): its
    Jacobians are read where they are. force (3,) N, torque (3,) N m: the liquid's measured wrench on the vessel
    about the vessel body's centre of mass, world frame (what goes into ``xfrc_applied``); used by
    ``IDEAL_FORCE_TORQUE``. payload: the arm's payload setting (the payload modes; None: no payload). frame: the
    vessel frame's world pose at this configuration (:func:`cosim.coupling.exchange.vessel_poses`)."""
    if compensation is Compensation.NONE:
        return None
    if compensation is Compensation.IDEAL_FORCE_TORQUE:
        return -scene.wrench_joint_torque(role, force, torque, kinematics_current=True)
    if payload is None or payload.mass == 0.0:
        return None
    centre = frame.transform(payload.com_local[None, :])[0]
    weight = payload.mass * scene.model.opt.gravity
    return -scene.wrench_joint_torque(role, weight, shift_wrench(weight, np.zeros(3), centre, scene.vessel_com(role)), kinematics_current=True)

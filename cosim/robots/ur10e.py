"""Published UR10e data: DH parameters, joint limits, joint speeds, payload; the analytic DH forward kinematics.

Sources (Universal Robots):
* "DH parameters for calculations of kinematics and dynamics" (universal-robots.com support article; UR10e rows):
  d1 = 0.1807, a2 = -0.6127, a3 = -0.57155, d4 = 0.17415, d5 = 0.11985, d6 = 0.11655 m,
  alpha = (pi/2, 0, 0, pi/2, -pi/2, 0), theta offsets 0.
* UR10e data sheet / user manual: payload 12.5 kg, reach 1300 mm, working range +-360 deg on all joints, maximum
  joint speed 120 deg/s (base, shoulder) and 180 deg/s (elbow, wrist 1-3).
* Universal Robots' ROS 2 description (UniversalRobots/Universal_Robots_ROS2_Description, ``urdf/ur_macro.xacro``):
  the joint names the ROS 2 driver and its controllers use, ``<tf_prefix>shoulder_pan_joint`` and so on.
* e-Series joint torques by joint size (Universal Robots' "max joint torques" support article): size 4 (UR10e base and
  shoulder) 330 N m, size 3 (elbow) 150 N m, size 2 (wrists) 56 N m; the model's actuator force ranges.

``models/ur10e/ur10e.xml`` is written from these numbers; ``tests/test_robot_kinematics.py`` checks that its forward
kinematics equals :func:`dh_forward_kinematics` (no MuJoCo here: numpy only).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

# UR joint names, base to flange, as used in models/ur10e/ur10e.xml (joints and actuators).
UR10E_JOINTS: tuple[str, ...] = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")
# The same joints as Universal Robots' ROS 2 driver names them (without its tf_prefix), base to flange.
UR10E_DRIVER_JOINTS: tuple[str, ...] = (
    "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint",
)

# Standard DH parameters (m, rad), UR10e rows of Universal Robots' DH table.
UR10E_DH_D: tuple[float, ...] = (0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655)
UR10E_DH_A: tuple[float, ...] = (0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0)
UR10E_DH_ALPHA: tuple[float, ...] = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)

# Data sheet: working range +-360 deg on every joint (rad).
UR10E_JOINT_RANGE: tuple[float, float] = (-2.0 * math.pi, 2.0 * math.pi)
# Data sheet: maximum joint speed, rad/s (120 deg/s base and shoulder, 180 deg/s elbow and wrists).
UR10E_MAX_JOINT_SPEED: tuple[float, ...] = tuple(math.radians(v) for v in (120.0, 120.0, 180.0, 180.0, 180.0, 180.0))
# Rated joint torque, N m (size 4, 4, 3, 2, 2, 2): the most each joint's drive may deliver.
UR10E_RATED_TORQUE: tuple[float, ...] = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)
# Data sheet: rated payload, kg.
UR10E_PAYLOAD_KG = 12.5


def dh_forward_kinematics(
    q: np.ndarray,
    dh_d: tuple[float, ...] = UR10E_DH_D,
    dh_a: tuple[float, ...] = UR10E_DH_A,
    dh_alpha: tuple[float, ...] = UR10E_DH_ALPHA,
) -> np.ndarray:
    """Flange pose (4x4 homogeneous transform, m) in the arm's base frame for joint angles ``q`` (6,), rad, of the
    arm with standard DH parameters ``dh_d``, ``dh_a`` (m) and ``dh_alpha`` (rad) (default: the UR10e's).

    Standard DH: ``T = prod_i Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; the result is DH frame 6 (tool flange, z out of
    the flange).
    """
    import numpy as np

    q = np.asarray(q, dtype=float)
    if q.shape != (6,):
        raise ValueError(f"q must have shape (6,), got {q.shape}")
    transform = np.eye(4)
    for theta, d, a, alpha in zip(q, dh_d, dh_a, dh_alpha):
        ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
        link = np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0.0, sa, ca, d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        transform = transform @ link
    return transform

"""A gate lifted off the dam-break column at a stated speed, as dam-break experiments release their liquid.

Experiments hold the column behind a gate (or diaphragm) and remove it over a finite time; a numerical release is
instantaneous. Lauber & Hager (1998, "Experiments to dambreak wave: Horizontal channel", J. Hydraulic Research
36(3)) take a removal as instantaneous when the gate clears the column within t_o = sqrt(2 H / g), the time a body
falls the column's height H: the slowest such gate rises at H / t_o = sqrt(g H / 2) (:func:`lauber_hager_speed`,
0.53 m/s for Martin & Moyce's a = 57 mm column).

The gate is a rigid vessel wall that the solver moves (:class:`cosim.fluid.solver.FluidSolver` moves every vessel to
the pose given for the end of each interval): a box vessel turned upside down (rotated by pi about +y), so that its
-x wall, whose inner face looks at -x, stands on the tank floor against the column's +x face, and its floor is a
ceiling above the liquid. Its walls are t thick, t the kernel-covering layers' thickness (``kernel_layers``'
:func:`cosim.fluid.wall_sampling.numerical_wall_thickness`, at least the tank walls' under either wall model), so
that they cover the kernel support whatever the wall model. Its interior spans the column and t beyond the tank's
closed wall, so that its other wall stands behind the tank's wall layers, out of every liquid particle's kernel
support; its ceiling is likewise t above the column. The gate rises at constant speed from t = 0 until its lower
edge is t above the column's top, clear of the liquid, and stays there. In 3-D its depth is the tank's plus t on
each side, so that its side walls stand behind the tank's; in 2-D it is the tank's depth (the liquid's mass per
depth is unchanged inside it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cosim.checks import check_positive
from cosim.frames import Pose, rotation_y
from cosim.vessel import VesselSpec

MAX_GATE_SPEED = 20.0  # m/s, far above any dam-break experiment's gate


def lauber_hager_speed(column_height: float, gravity: float) -> float:
    """m/s, the slowest gate speed Lauber & Hager (1998) accept as an instantaneous release of a ``column_height`` (m)
    column: the column's height over the time sqrt(2 H / g) a body takes to fall it, sqrt(g H / 2)."""
    return math.sqrt(gravity * column_height / 2.0)


@dataclass(frozen=True)
class LiftedGate:
    """The gate's vessel and its motion (world frame, m, s).

    spec: the upside-down box vessel whose -x wall is the gate. face_x: x of the gate's liquid-facing face.
    start: the vessel frame's origin at t = 0 (the ceiling's underside; the gate's lower edge at z = 0).
    speed: m/s upwards. travel: m, the lift at which the gate stops. top: m, the highest z its ceiling's wall layers
    reach (at full travel).
    """

    spec: VesselSpec
    face_x: float
    start: tuple[float, float, float]
    speed: float
    travel: float
    top: float

    def lift(self, t: float) -> float:
        """m, the gate's lower edge above the tank floor at time ``t`` (s)."""
        return min(self.speed * max(t, 0.0), self.travel)

    def pose(self, t: float) -> Pose:
        """The gate vessel's world pose at time ``t`` (s)."""
        x, y, z = self.start
        return Pose((x, y, z + self.lift(t)), rotation_y(math.pi))


def lifted_gate(wall_x: float, column_width: float, column_height: float, depth: float, dim: int, wall_thickness: float,
                speed: float) -> LiftedGate:
    """The gate against a column ``column_width`` x ``column_height`` (m) that stands on z = 0 against the tank's
    closed wall at x = ``wall_x`` (the tank ``depth`` m deep), lifted at ``speed`` (m/s); ``wall_thickness`` (m) is
    the gate's own wall thickness, at least the tank walls' numerical thickness so that its back wall clears them
    (module doc): a plate as thick as the kernel-covering layers is filled by them under either wall model."""
    check_positive("gate_speed", speed, "m/s", MAX_GATE_SPEED)
    t = wall_thickness
    inner_width = column_width + t  # from the gate's face back to behind the tank's wall layers
    inner_height = column_height + t  # the ceiling a support above the column
    spec = VesselSpec(name="gate", inner_width=inner_width, inner_depth=depth if dim == 2 else depth + 2.0 * t,
                      inner_height=inner_height, wall_thickness=t)
    face_x = wall_x + column_width
    # Turned by pi about +y, the frame's local x = +b (the +x wall's inner face) maps to world x = origin - b,
    # local x = -b (the -x wall's inner face, the gate) to origin + b, and local z to -z: the rim at origin_z - height.
    origin = (face_x - 0.5 * inner_width, 0.0, inner_height)
    travel = column_height + t
    return LiftedGate(spec, face_x, origin, speed, travel, inner_height + travel + t)

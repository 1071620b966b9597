"""The slosh plant of a vessel with no closed form (a mesh whose cavity is neither box- nor cylinder-like), identified
from the SPH liquid as ``cosim validate slosh-plant`` identifies it (:func:`cosim.validation.slosh_plant.identify`).

The vessel filled to the pour's fill is tilted by a small angle about pivots on its axis at fractions of a first
guess of the hinge (potential flow for the box of the vessel's equivalent sizes), the ring-downs are fitted, and the
fitted pendulum (omega1, hinge, damping) is the plant the pour controller is designed on.
"""

from __future__ import annotations

from controllers.errors import ControllerInputError
from controllers.slosh import SloshModel, potential_flow_model
from cosim.errors import InputError
from cosim.fluid.config import PressureSolver
from cosim.frames import Pose
from cosim.validation.common import case_fluid_config
from cosim.validation.scripted import tilt_about_axis_point
from cosim.validation.slosh_plant import MIN_HOLD_PERIODS, TILT_ANGLE, TILT_DURATION, domain_for, identify, pivot_heights
from cosim.vessel import VesselSpec


def identified_plant(spec: VesselSpec, fill: float, dim: int, spacing: float, solver: PressureSolver, device: str = "cpu") -> SloshModel:
    """The first-mode pendulum of ``spec`` filled to ``fill`` (m), identified from ``dim``-D SPH tilts at ``spacing``
    (m). Raises InputError naming ``vessels.pourer`` if a run fails or the fit gives no pendulum."""
    guess = potential_flow_model(spec.inner_width, fill)
    pivots = pivot_heights(guess.hinge_height)
    poses = [Pose()] + [tilt_about_axis_point(q, TILT_ANGLE, TILT_DURATION)(TILT_DURATION) for q in pivots]
    lo, hi = domain_for(spec, poses, 0.05 * spec.inner_width + 10 * spacing)
    cfg = case_fluid_config(dim, spacing, fill, spec.section_depth, lo, hi, solver)
    result = identify(spec, fill, cfg, pivots, 2.0 * MIN_HOLD_PERIODS * guess.period, device)
    failed = [f for f in result.failures if f]
    if result.fit is None or failed:
        raise InputError(f"vessels.pourer: the slosh plant of the mesh could not be identified ({failed[0] if failed else 'no fit'})")
    try:
        model = result.fit.slosh_model(cfg.gravity_magnitude)
    except ControllerInputError as exc:
        raise InputError(f"vessels.pourer: the identified slosh plant is no pendulum ({exc})") from None
    return model

"""The weir case: its channel and piston geometry, its inputs, and a coarse run's discharge coefficient."""

from __future__ import annotations

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.validation import weir

# The coarse run: 5 particles across the 40 mm head (dx = 8 mm), about 1000 particles. The resolution study in
# docs/outflow_validation.md gives C_d / Rehbock = 1.030 at this resolution, 1.037 at 7 and 1.035 at 10 across
# (the default) with DFSPH's default numerics. The coarse ratio is checked within half the change that halving dx
# made (|1.0348 - 1.0301| / 2): a change of the liquid's numerics that moves the coarse coefficient by that much
# moves it as much as a resolution step does, and is caught.
COARSE_SPACING = 0.008
COARSE_RATIO = 1.030
COARSE_TOLERANCE = 0.0024


def test_the_piston_supplies_rehbocks_discharge_at_the_nominal_head() -> None:
    p = weir.Params(head=0.04, crest_height=0.08)
    q = weir.piston_speed(p.head, p.crest_height) * (p.crest_height + p.head)
    assert q == pytest.approx((2 / 3) * (0.611 + 0.08 * 0.5) * np.sqrt(2 * 9.81) * 0.04**1.5, rel=1e-3)


def test_the_piston_plate_stands_on_the_floor_and_stays_behind_the_head_strip() -> None:
    p = weir.Params()
    dx, thickness = p.resolved_spacing, 0.012
    ch = weir.Channel(p, dx, 0.005, thickness)
    spec = ch.piston()
    half = 0.5 * spec.inner_width + thickness  # the floor slab the liquid sees: the numerical wall's thickness
    corners = np.array([[x, 0.0, z] for x in (-half, half) for z in (-thickness, 0.0)])
    for t in (0.0, p.duration):
        world = ch.piston_pose(t).transform(corners)
        assert world[:, 0].max() == pytest.approx(ch.piston_face + ch.speed * t)  # the face the liquid sees
        assert world[:, 2].min() == pytest.approx(0.0) and world[:, 2].max() == pytest.approx(ch.plate)
    assert ch.piston_face + ch.speed * p.duration < ch.station - 0.5 * ch.strip - 2 * p.head
    assert -ch.length < ch.piston_face - 6 * thickness  # the channel's back wall clear of the piston's trailing walls


# 8 across the head: the piston's own 20 mm cavity (four of its walls' thickness) holds the 3 rows its fit needs
REAL_WALLS_SPACING = 0.005
REAL_WALLS = (("wall_model", "real_thickness"), ("wall_pressure", "solved_rest_sum"))


def test_under_real_thickness_walls_the_weir_is_real_and_the_piston_covers_the_support() -> None:
    """The weir plate (the crest the nappe leaves) is the vessel's own 5 mm; the piston, a driver pushing with its
    floor's outer face, keeps the kernel-covering walls, so its thin-wall fit and rest offsets (made for liquid in
    its own cavity) never meet the liquid: the first 0.05 s run without the liquid at its foot being fired off."""
    result = weir.run(weir.Params(head=0.04, spacing=REAL_WALLS_SPACING, solver="dfsph", numerics=REAL_WALLS, duration=0.05, window=0.05))
    assert result.raw["crest_thickness"] == pytest.approx(0.005)
    assert result.raw["steps"] > 0 and result.raw["head"] == pytest.approx(0.04, rel=0.1)


@pytest.mark.parametrize("kwargs, field", [({"dim": 3}, "dim"), ({"window": 2.0}, "window"), ({"head": 0.5}, "head"),
                                           ({"spacing": 0.03}, "spacing")])
def test_bad_input_names_the_field(kwargs, field) -> None:
    with pytest.raises(InputError, match=rf"^{field}: "):
        weir.Params(**kwargs)


def test_a_coarse_run_measures_the_coefficient_of_the_resolution_study() -> None:
    result = weir.run(weir.Params(head=0.04, spacing=COARSE_SPACING, solver="dfsph"))
    ratio = result.raw["coefficient"] / result.raw["rehbock"]
    assert ratio == pytest.approx(COARSE_RATIO, abs=COARSE_TOLERANCE)
    assert result.raw["head"] == pytest.approx(0.04, rel=0.15)  # the flow settled near the head the piston supplies

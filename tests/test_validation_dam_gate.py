"""The dam-break gate: where its walls stand, how it moves, and that a closed gate holds the column."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig
from cosim.fluid.wall_sampling import sample_vessel_walls
from cosim.validation import dam_break
from cosim.validation.dam_gate import lauber_hager_speed, lifted_gate

DX = 0.005
SUPPORT = 3 * DX  # the default kernel's 2h = 3 dx
LAYERS = 3 * DX  # ceil(2h / dx) dummy layers


def test_lauber_hager_speed_clears_the_column_in_its_fall_time() -> None:
    speed = lauber_hager_speed(0.05715, GRAVITY)
    assert speed == pytest.approx(0.5294, abs=1e-4)
    assert 0.05715 / speed == pytest.approx(math.sqrt(2 * 0.05715 / GRAVITY))


def test_gate_rises_at_its_speed_then_stops_clear_of_the_column() -> None:
    gate = lifted_gate(-0.2, 0.05, 0.06, 0.1, 2, LAYERS, speed=1.5)
    assert gate.lift(-1.0) == 0.0
    for t in (0.0, 0.01, 0.03):
        pose = gate.pose(t)
        assert pose.position[2] - gate.start[2] == pytest.approx(1.5 * t)
        assert gate.lift(t) == pytest.approx(1.5 * t)
    assert gate.travel == pytest.approx(0.06 + LAYERS)  # its lower edge a layer thickness above the column's top
    assert gate.lift(1.0) == pytest.approx(gate.travel)


@pytest.mark.parametrize("dim", [2, 3])
def test_only_the_gate_wall_faces_the_column(dim: int) -> None:
    wall_x, a, height, depth = -0.2, 0.05, 0.06, 0.1
    gate = lifted_gate(wall_x, a, height, depth, dim, LAYERS, speed=1.0)
    local, _ = sample_vessel_walls(gate.spec, FluidConfig(dim=dim, spacing=DX))  # support 2h = 3 dx = SUPPORT
    for t in (0.0, 0.02):
        world = gate.pose(t).transform(local)
        lift = gate.lift(t)
        # The dummy particles within the kernel support of the column (x in [wall, wall + a], z in [0, height], |y| <= depth / 2).
        dx_out = np.maximum.reduce([wall_x - world[:, 0], world[:, 0] - (wall_x + a), np.zeros(len(world))])
        dz_out = np.maximum.reduce([-world[:, 2], world[:, 2] - height, np.zeros(len(world))])
        dy_out = np.maximum(np.abs(world[:, 1]) - 0.5 * depth, 0.0)
        near = np.sqrt(dx_out**2 + dy_out**2 + dz_out**2) < SUPPORT
        assert near.any()
        facing = world[near]
        assert facing[:, 0].min() == pytest.approx(gate.face_x + 0.5 * DX)  # the gate's first layer, half a spacing off its face
        assert facing[:, 0].max() < gate.face_x + LAYERS
        assert facing[:, 2].min() == pytest.approx(lift + 0.5 * DX, abs=0.5 * DX)  # its lower edge, lifted


def test_a_gate_that_stays_shut_holds_the_column_and_moves_as_specified() -> None:
    p = dam_break.Params(width=0.05, spacing=DX, t_max=1.2, gate_speed=0.001)  # 0.06 s: lifted 0.06 mm, far below a spacing
    held = dam_break.run(p)
    free = dam_break.run(dam_break.Params(width=0.05, spacing=DX, t_max=1.2))
    assert held.raw["gate_lift"] == pytest.approx([0.001 * t for t in held.raw["t"]])
    assert free.raw["gate_lift"] is None
    assert held.raw["Z"][-1] < 1.02  # the column stays behind its gate
    assert free.raw["Z"][-1] > 1.4  # released at once, it has run out

"""The liquid's energy account: what the numerics create, interval by interval (host side, O(vessels) work).

The energy of the liquid is E = K + U + P + R: kinetic K = sum m |v|^2 / 2, elastic U = sum m u(rho) (WCSPH's Tait
liquid stores energy when compressed or stretched; DFSPH's incompressible liquid none) and potential P =
-sum m g . x of the active particles (3-D equivalent masses; reduced on the device in every substep's diagnostics
row) and R, the kinetic and potential energy the particles that left the domain had as they left. The moving walls do the work
W = -sum over intervals of (F . v_com + tau . omega) dt on it, from the reaction wrench the solver reports (force F
and torque tau about the vessel's centre of mass, averaged over the interval's substeps, guard impulses included)
and the vessel's constant velocity within the interval. Viscosity, density diffusion and the wall guard only remove
energy, so E - W never rises above its start in exact arithmetic: :attr:`EnergyAccount.created`, E - E0 - W, is the
energy the numerics created (the definition ``cosim stress`` classifies by). It is measured from the start, not from
the account's lowest value: part of a dip is energy that comes back (the elastic part of an impulsive start is in
U, but the seeded liquid's first acoustic transient is not exact either), and measured from its minimum the account
flags configurations whose every other measure is clean. The price: energy dissipated earlier in a long run (a
pour's impacts) is margin for later creation. It is relative to M g L (liquid mass M,
L the tallest vessel's inner height, or the domain's height without vessels), the scale of
``FluidConfig.max_energy_creation``.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from cosim.fluid.config import FluidConfig
from cosim.frames import Pose, cross3, rotation_from_vector
from cosim.vessel import VesselSpec


class EnergyAccount:
    """E - E0 - W of the liquid (J), updated once per interval.

    Args:
      config: the solver's configuration.
      vessels: the vessels (their centres of mass are the wrenches' reference points).
      positions, velocities: (N, 3) initial particle state (m, m/s), world frame.
      internal_energy: J, the elastic energy the initial liquid stores (WCSPH's Tait liquid; 0 for DFSPH).
    """

    def __init__(
        self, config: FluidConfig, vessels: Sequence[VesselSpec], positions: np.ndarray, velocities: np.ndarray, internal_energy: float
    ):
        mass = config.rest_density * config.particle_volume  # kg per particle, 3-D equivalent
        gravity = np.asarray(config.gravity, dtype=np.float64)
        length = max((v.inner_height for v in vessels), default=config.domain_max[2] - config.domain_min[2])
        self.scale = mass * len(positions) * config.gravity_magnitude * length  # J, M g L
        self.energy = float(mass * (0.5 * np.einsum("ij,ij->i", velocities, velocities) - positions @ gravity).sum()) + internal_energy
        self.com_local = [np.asarray(v.com_local, dtype=np.float64) for v in vessels]
        self.wall_work = 0.0  # J, done by the walls on the liquid so far
        self.removed = 0.0  # J, carried out of the domain by deactivated particles
        self.initial = self.energy  # J, E0
        self.peak_created = 0.0  # largest :attr:`created` so far (M g L)

    def update(
        self,
        kinetic: float,
        potential: float,
        removed: float,
        wrenches: np.ndarray,
        before: Sequence[Pose],
        lin_vel: np.ndarray,
        ang_vel: np.ndarray,
        duration: float,
    ) -> None:
        """One interval: the active particles' kinetic (+ elastic) and potential energy at its end (J), the energy removed
        during it (J), the interval-averaged wrenches (V, 6) on the vessels, their start poses and their constant
        linear (V, 3, m/s) and angular (V, 3, rad/s) velocities over ``duration`` (s)."""
        for k, pose in enumerate(before):
            rotation_mid = rotation_from_vector(0.5 * duration * ang_vel[k]) @ pose.rotation
            v_com = lin_vel[k] + cross3(ang_vel[k], rotation_mid @ self.com_local[k])
            self.wall_work -= float(wrenches[k, :3] @ v_com + wrenches[k, 3:] @ ang_vel[k]) * duration
        self.removed += removed
        self.energy = kinetic + potential + self.removed
        self.peak_created = max(self.peak_created, self.created)

    @property
    def created(self) -> float:
        """Energy the numerics created, (E - E0 - W) / (M g L)."""
        return (self.energy - self.initial - self.wall_work) / self.scale


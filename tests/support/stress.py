"""A plausible clean stress measurement to derive crafted ones from."""

from cosim.stress.runner import Measurement

CLEAN = Measurement(
    particles=100, simulated_time=0.6, steps=4000, failure="", nonfinite=0, leaked=0, worst_inside=0, worst_through=0,
    worst_escaped=0, max_density_error=0.02, energy_excess=0.01, energy_change=0.1, work_in=0.12, dt_ratio_min=0.9,
    speed_ratio=0.3, guard_corrections=0, spilled_fraction=0.0, wall_time=1.0,
)

"""The rate the joint trajectories are sampled at, declared once for the recorder that takes it and the scene that
sets it (its own module, so that a scene reads the declaration without loading the recorder's NumPy and ruckig)."""

from declared_settings.setting import argument

DEFAULT_SAMPLE_RATE_HZ = 500.0  # Hz, the scene's trajectory.sample_rate_hz and the recorder's default
SAMPLE_RATE = argument("trajectory", "Rate of the exported joint trajectories.", "Hz", 0.0, 10_000.0, lo_open=True)

"""The rate the joint trajectories are sampled at: its default and its range, for the recorder and the scene (its own
module, so that a scene names them without loading the recorder's NumPy and ruckig)."""

DEFAULT_SAMPLE_RATE_HZ = 500.0  # Hz
MAX_SAMPLE_RATE_HZ = 10_000.0  # Hz; the rate is in (0, MAX_SAMPLE_RATE_HZ]

"""Input/output that observes the simulation: trajectory files, logs, summaries. Reads state, never changes it."""

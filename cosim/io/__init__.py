"""Input/output that observes a run and never changes it: the Rerun recording (``recording``), its geometry,
blueprint and read-back helpers (``rerun_*``) and the pour's time series (``pour_series``)."""

"""``cosim bench``: wall time against error for resolutions, numerics and scene skip options.

Modules: :mod:`~cosim.bench.config` (one configuration), :mod:`~cosim.bench.plan` (which ones, from axes),
:mod:`~cosim.bench.runners` (run one), :mod:`~cosim.bench.pour_compare` (pour against pour),
:mod:`~cosim.bench.cache` (results by configuration and code version), :mod:`~cosim.bench.run` (run a plan,
resumable), :mod:`~cosim.bench.pareto` (the front), :mod:`~cosim.bench.report` (CSV, Markdown, plots).
"""

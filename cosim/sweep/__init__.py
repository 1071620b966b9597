"""``cosim sweep``: many pours of one base scene over axes of scene keys, spread over a Ray cluster.

:mod:`~cosim.sweep.spec` reads the sweep file, :mod:`~cosim.sweep.expand` turns its axes into pours (one scene
each), :mod:`~cosim.sweep.store` keys each pour by its scene and the code version and keeps its run folder or its
recorded failure (what a rerun resumes from), :mod:`~cosim.sweep.resources` says what a pour asks Ray for,
:mod:`~cosim.sweep.runner` runs the pours as Ray tasks with a progress bar, :mod:`~cosim.sweep.report` writes
sweep.csv, the plots and the trajectory library. Importing this package imports neither Ray nor the simulation.
"""

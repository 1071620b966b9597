"""Numerical-stability matrix (``cosim stress``): the SPH liquid in the pouring vessel of
Camporredondo et al. (2019) under scripted motions (tilt about the lip, sideways shaking at the sloshing resonance,
sideways carrying), across fill, resolution, CFL number, dimension and pressure solver; each configuration is
classified ``clean``, ``instability`` (the solver's own :class:`~cosim.fluid.solver.FluidInstabilityError`),
``silent`` (garbage without an error) or ``error``.

Modules: ``matrix`` (the axes and the frozen configuration), ``runner`` (one configuration -> measurements),
``classify`` (measurements -> outcome), ``store`` (resumable CSV), ``report`` (Markdown table and plot).
"""

"""warp-lang SPH liquid with moving rigid vessels as boundaries: weakly compressible SPH (``wcsph``) or
divergence-free SPH (``dfsph``), chosen by :attr:`FluidConfig.pressure_solver`.

One code path for 2-D (the pour plane, world x-z at y = 0) and 3-D. No MuJoCo imports here: the coupling layer
sets vessel poses and reads back the liquid's wrench on each vessel.

Public API: :class:`FluidConfig`, :class:`KernelType`, :class:`PressureSolver` (``cosim.fluid.config``),
:class:`FluidSolver` (``cosim.fluid.solver``), the particle seeders in ``cosim.fluid.seeding``.
"""

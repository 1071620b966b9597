"""cosim: robot pours simulated with MuJoCo arms and a warp-lang SPH liquid.

Layers (dependency direction is fixed): ``controllers`` (pure numpy + python-control) and ``cosim.fluid``
(warp) know nothing of each other or of MuJoCo; ``cosim.robots`` is the MuJoCo side; ``cosim.coupling``
wires them; ``cosim.io`` observes. SI units everywhere, z-up world, quaternions [w, x, y, z].
"""

from cosim.reproducibility import pin_openblas_core

pin_openblas_core()  # before anything imports numpy: the same BLAS kernels, so the same bits, on every AVX2 machine

__version__ = "0.1.0"

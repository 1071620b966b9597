"""cosim: robot pours simulated with MuJoCo arms and a warp-lang SPH liquid.

Layers (dependency direction is fixed): ``controllers`` (pure numpy + python-control) and ``cosim.fluid``
(warp) know nothing of each other or of MuJoCo; ``cosim.robots`` is the MuJoCo side; ``cosim.coupling``
wires them; ``cosim.io`` observes. SI units everywhere, z-up world, quaternions [w, x, y, z].

Importing the package changes nothing outside it: the ``cosim`` command pins numpy's BLAS kernels
(:func:`cosim.reproducibility.pin_openblas_core`) and configures warp (:func:`cosim.fluid.runtime.init_warp`)
itself, when it runs.
"""

__version__ = "0.1.0"

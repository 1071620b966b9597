"""Imported by pytest before any test module: pins numpy's OpenBLAS kernels before numpy is loaded
(cosim.reproducibility), as the cosim command does."""

from cosim.reproducibility import pin_openblas_core

pin_openblas_core()

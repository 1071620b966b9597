"""Imported by pytest before any test module: cosim first, so that it pins numpy's OpenBLAS kernels before numpy is
loaded (cosim.reproducibility), as the cosim command does."""

import cosim  # noqa: F401

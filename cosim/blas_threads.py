"""numpy's OpenBLAS on one thread, set before numpy loads.

OpenBLAS starts a worker thread per core beside the caller's. It hands the LU back-substitution of
``numpy.linalg.solve`` (``getrs``) to its workers even for a 6 x 6 system, so every solve of the IK wakes a worker,
waits for it, and leaves the workers spinning for their next call on the cores the liquid's solver lanes run on
(``cosim.fluid.lanes``). The pour's matrices are a few rows by a few columns: no call in it gains from a second
thread. The workers split the right-hand sides among them, and each one's back-substitution is the same arithmetic
on one thread (docs/performance.md).

Like the kernels' pin (:mod:`cosim.reproducibility`) this only works before numpy is first imported (OpenBLAS reads
the variable once, when it loads), so the ``cosim`` command and the test suite's ``conftest.py`` call
:func:`limit_openblas_threads` first. A user's own ``OPENBLAS_NUM_THREADS`` is left alone.
"""

from __future__ import annotations

import os
import sys

VARIABLE = "OPENBLAS_NUM_THREADS"


def limit_openblas_threads() -> bool:
    """Set ``OPENBLAS_NUM_THREADS`` to 1 unless it is set already or numpy is loaded (too late then); returns whether
    it was set."""
    if VARIABLE in os.environ or "numpy" in sys.modules:
        return False
    os.environ[VARIABLE] = "1"
    return True

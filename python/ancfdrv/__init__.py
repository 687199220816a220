"""ancfdrv: flexible multibody dynamics with the Absolute Nodal Coordinate Formulation.

Scenes (Fortran namelists) are read by :mod:`ancfdrv.scene`, turned into models over the
Fortran kernel by :mod:`ancfdrv.model`, solved by :mod:`ancfdrv.static`, and stored in
HDF5 by :mod:`ancfdrv.results`; :mod:`ancfdrv.runner` ties these together and
:mod:`ancfdrv.cli` is the ``ancf`` command.
"""
import os as _os

# The kernel's OpenMP element loops (large-deformation beam, plate) run on one thread unless the
# user sets OMP_NUM_THREADS: sweeps already fill the cores with processes. OpenBLAS stays
# single-threaded unless OPENBLAS_NUM_THREADS says otherwise: its threaded banded Cholesky
# was measured 10x slower than the single-threaded one on the beam's narrow band.
_os.environ.setdefault("OMP_NUM_THREADS", "1")
_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# Idle OpenMP threads sleep instead of spinning between the element loops: spinning
# threads took the cores from the serial solve and made the 2-thread plate pendulum 2x
# slower than 1 thread (measured 6.1 s vs 2.8 s, 2.4 s with the passive policy).
_os.environ.setdefault("OMP_WAIT_POLICY", "passive")

__version__ = "0.1.0"

"""ancfdrv: flexible multibody dynamics with the Absolute Nodal Coordinate Formulation.

Compose a system in Python (``from ancfdrv import System``, :mod:`ancfdrv.system`) or in a
namelist scene (read and checked by :mod:`ancfdrv.io`; template and general scenes are
built by :mod:`ancfdrv.builders` over the same API), solve it (:mod:`ancfdrv.solvers`) and
store the results in HDF5 (:mod:`ancfdrv.results`); :mod:`ancfdrv.runner` ties these
together and :mod:`ancfdrv.cli` is the ``ancf`` command. From Python, ``System.static()``
and ``System.simulate()`` run the same path (:mod:`ancfdrv.analyses`) and return
:class:`~ancfdrv.results.Results`; ``ancfdrv.open(path)`` reads any result file.
``ancfdrv.simulate(scene, overrides)`` runs a scene file as ``ancf run`` does and keeps the
results in memory (:class:`~ancfdrv.simulation.Simulation`, no file unless ``save(path)``).
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

from ._version import __version__  # noqa: E402,F401

from .system import (Beam, Box, Cable, Circle, Constant, Cycle, General, Leaf, Luffing,  # noqa: E402
                     Material, Model, Plate, Ramp, Rectangle, RigidBody, Sine, SpinUp, Standard,
                     System, Table, Tube)

from .results import Results, open_results  # noqa: E402
from . import analyses as _analyses  # noqa: E402,F401  (gives System its analyses)

#: ``ancfdrv.open(path)``: any result file as :class:`~ancfdrv.results.Results`
open = open_results  # noqa: A001 - the package's own name, as SPEC section 10 spells it



def __getattr__(name: str):
    """``ancfdrv.simulate`` and ``ancfdrv.Simulation`` (:mod:`ancfdrv.simulation`: a scene
    run with its results kept in memory), imported on first use."""
    if name in ("simulate", "Simulation"):
        from . import simulation
        return getattr(simulation, name)
    raise AttributeError(f"module 'ancfdrv' has no attribute {name!r}")


__all__ = ["simulate", "Simulation", "open", "open_results", "Results", "System", "Model", "Material", "Beam", "Cable",
           "Plate", "Leaf", "RigidBody", "Rectangle", "Box", "Tube", "Circle", "General",
           "Standard", "Constant", "Luffing", "SpinUp", "Cycle", "Sine", "Table", "Ramp"]

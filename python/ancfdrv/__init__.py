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

import importlib as _importlib  # noqa: E402

from . import _lazy  # noqa: E402

# System's analyses (System.static, simulate, modes, buckling) live in ancfdrv.analyses,
# above the system layer: it is named here, at the top, and imported on the first analysis
_lazy.provide("analyses", "ancfdrv.analyses")
# the general scenes' builder (ancfdrv.builders.general), which io.scene.load_scene needs to
# check a general scene's effects: loaded by the reader on the first general scene
_lazy.provide("general_builder", "ancfdrv.builders.general")

#: the public names, each imported from its module on first use (``ancf run --help`` and
#: ``ancf info`` import neither the system nor the solvers)
_EXPORTS = {
    **{name: ".system" for name in (
        "Beam", "Box", "Cable", "Circle", "Constant", "Cycle", "General", "Leaf", "Luffing",
        "Material", "Model", "Plate", "Ramp", "Rectangle", "RigidBody", "Sine", "SpinUp",
        "Standard", "System", "Table", "Tube")},
    "Results": ".results", "open_results": ".results",
    #: ``ancfdrv.open(path)``: any result file as :class:`~ancfdrv.results.Results`
    "open": ".results",
    "simulate": ".simulation", "Simulation": ".simulation",
}


def __getattr__(name: str):
    """The public names of :data:`_EXPORTS`, imported on first use: the system API, the
    result reader and ``ancfdrv.simulate`` / ``ancfdrv.Simulation``
    (:mod:`ancfdrv.simulation`: a scene run with its results kept in memory)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'ancfdrv' has no attribute {name!r}")
    value = getattr(_importlib.import_module(module, __name__),
                    "open_results" if name == "open" else name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


__all__ = ["simulate", "Simulation", "open", "open_results", "Results", "System", "Model", "Material", "Beam", "Cable",
           "Plate", "Leaf", "RigidBody", "Rectangle", "Box", "Tube", "Circle", "General",
           "Standard", "Constant", "Luffing", "SpinUp", "Cycle", "Sine", "Table", "Ramp"]

"""ancfdrv: flexible multibody dynamics with the Absolute Nodal Coordinate Formulation.

Scenes (Fortran namelists) are read by :mod:`ancfdrv.scene`, turned into models over the
Fortran kernel by :mod:`ancfdrv.model`, solved by :mod:`ancfdrv.static`, and stored in
HDF5 by :mod:`ancfdrv.results`; :mod:`ancfdrv.runner` ties these together and
:mod:`ancfdrv.cli` is the ``ancf`` command.
"""
__version__ = "0.1.0"

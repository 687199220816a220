"""Errors that carry their message from the kernel (system_api.f90 returns info and a text,
kernel_errors.f90 holds the shared texts): a stale handle and a size mismatch are named as
what they are, never as a solver failure ("Newton did not converge", "non-finite")."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import _kernel, kernel
from ancfdrv.errors import SolverError
from ancfdrv.solvers.dynamic import DynamicSettings


def test_stale_handle_is_named():
    """A destroyed system's handle: every routine refuses it with the handle's number."""
    ks = kernel.KernelSystem(6, 6)
    handle = ks.handle
    ks.close()
    stale = kernel.KernelSystem.__new__(kernel.KernelSystem)
    stale.handle, stale.ndof, stale.nfull, stale.npoint, stale.nnz_pattern = handle, 6, 6, 0, 0
    with pytest.raises(SolverError, match=f"handle {handle} is not a live system.*stale handle"):
        stale.stepper_setup(DynamicSettings(dt=1e-3, t_end=1.0))
    with pytest.raises(SolverError, match="force evaluation, kernel code 1: .*stale handle") as err:
        stale.evaluate(0.0, np.zeros(6), np.zeros(6), np.zeros((2, 1)), np.zeros(6, np.int32))
    assert "Newton" not in str(err.value) and "non-finite" not in str(err.value)
    with pytest.raises(SolverError, match="full force evaluation, kernel code 1: .*stale handle"):
        stale.full_forces(0.0, np.zeros(6), np.zeros(6), np.zeros((2, 1)))
    stale.handle = 0
    info, message = _kernel.system_destroy(handle)
    assert info == 1 and b"stale handle" in message


def test_size_mismatch_is_named():
    """Coordinates of the wrong size and an element dof outside the system: the routine
    names itself and what is inconsistent."""
    with kernel.KernelSystem(6, 6) as ks:
        ks.ndof = 9   # the caller's bug: a state of another system's size
        with pytest.raises(SolverError, match="system_evaluate: sizes inconsistent with the "
                                              "system"):
            ks.evaluate(0.0, np.zeros(9), np.zeros(9), np.zeros((2, 1)), np.zeros(6, np.int32))
        dofs = np.arange(12).reshape(12, 1) + 3    # up to 15 > nfull = 6
        scatter = np.zeros((12, 12, 1), dtype=np.int32)
        with pytest.raises(SolverError, match="cable set.*an element dof outside 1..nfull"):
            ks.add_cable_set(dofs, scatter, [1.0], 1.0, 1.0)

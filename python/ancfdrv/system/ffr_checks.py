"""The check of an 'ffr' beam against its assumptions that the system alone decides: a
frame turning near or above the beam's first bending frequency (run at assembly: the
warning is in ``model.warnings`` from the start)."""
from __future__ import annotations

import numpy as np

from ..codes import DRIVE_LUFFING, DRIVE_SPINUP
from .kinds import Beam


def first_bending_frequency(beam: Beam) -> float:
    """Clamped-free first bending frequency (rad/s) in the weak direction,
    (beta_1 L)^2 sqrt(EI / (rho A L^4))."""
    section = beam.section.data
    inertia = min(section.inertia_y, section.inertia_z)
    return 1.875104068711961**2 * np.sqrt(beam.material.youngs_modulus * inertia / (
        beam.material.density * section.area * beam.length**4))


def ffr_speed_warnings(system) -> list[str]:
    """A warning for each 'ffr' beam whose frame turns at a speed near or above its first
    bending frequency (FFR has no geometric, centrifugal, stiffening)."""
    out = []
    for beam in system.bodies.values():
        if not beam.floating or beam.frame_drive is None:
            continue
        drive = beam.frame_drive
        params = drive.params()
        rate = {DRIVE_LUFFING: abs(params[0]), DRIVE_SPINUP: abs(params[0])}.get(drive.kind, 0.0)
        omega1 = first_bending_frequency(beam)
        if rate > 0.3 * omega1 and beam.geometric_stiffness:
            out.append(
                f"formulation 'ffr' outside its assumptions: the frame of beam {beam.name!r} "
                f"turns at {rate:.3g} rad/s, {rate / omega1:.2f} of its first bending frequency "
                f"{omega1:.3g} rad/s; its centrifugal stiffening comes from the P-delta option "
                "(geometric_stiffness), linear in the frame - compare with formulation = "
                "'nonlinear'")
        elif rate > 0.3 * omega1:
            out.append(
                f"formulation 'ffr' outside its assumptions: the frame of beam {beam.name!r} "
                f"turns at {rate:.3g} rad/s, {rate / omega1:.2f} of its first bending frequency "
                f"{omega1:.3g} rad/s; FFR has no geometric (centrifugal) stiffening and becomes "
                "unstable near and above it - use formulation = 'nonlinear'")
    return out

"""An 'ffr' beam's floating frame is fixed or turned by its own drive about a fixed pivot;
the kernel cannot make it follow another moving body. Such a beam is refused with a message
that names it (issue 12), not approximated silently."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import Rectangle, System
from ancfdrv.errors import InputError
from ancfdrv.solvers.dynamic import DynamicSettings, integrate
from ancfdrv.solvers.static import solve_newton


def beam_system(formulation: str = "ffr", *, frame_drive: str | None = None) -> System:
    s = System("frames")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.drive("turn", "spinup", omega=1.0, period=1.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=4,
           section=Rectangle(0.05, 0.05), height_axis=(0, 1, 0), formulation=formulation,
           bending="cubic", frame_drive=frame_drive)
    s.rigid_body("hub", mass=5.0, inertia=(0.1, 0.1, 0.1, 0, 0, 0), position=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -9.81, 0))
    return s


def test_ffr_beam_joined_only_to_a_free_body_is_refused():
    s = beam_system()
    s.joint("mount", "weld", "hub", "arm", point=(0, 0, 0))
    with pytest.raises(InputError, match=r"beam 'arm': formulation 'ffr' needs its floating "
                                         r"frame held.*'hub'.*formulation = 'nonlinear'"):
        s.assemble()


def test_ffr_frame_drive_that_moves_nothing_is_refused():
    s = beam_system(frame_drive="turn")
    s.joint("pin", "revolute", "ground", "arm", point=(0, 0, 0), axis=(0, 0, 1))
    with pytest.raises(InputError, match=r"beam 'arm': its floating frame turns with drive "
                                         r"'turn', but no joint moves"):
        s.assemble()


@pytest.mark.parametrize("held", ["hub on the beam", "hub on a welded body"])
def test_ffr_frame_moved_by_its_drive_is_accepted(held):
    """The same beam turned by a 'hub' with the frame's drive, on the beam itself or on a
    rigid body welded to it (the boom's arm), assembles and runs."""
    s = beam_system(frame_drive="turn")
    if held == "hub on the beam":
        s.joint("drive", "hub", "ground", "arm", point=(0, 0, 0), pivot=(0, 0, 0),
                axis=(0, 0, 1), drive="turn")
    else:
        s.joint("drive", "hub", "ground", "hub", point=(0, 0, 0), pivot=(0, 0, 0),
                axis=(0, 0, 1), drive="turn")
        s.joint("mount", "weld", "hub", "arm", point=(0, 0, 0))
    model = s.assemble()
    try:
        result = integrate(model, DynamicSettings(dt=1e-3, t_end=0.01), model.e0,
                           progress=False)
        assert result.steps == 10
    finally:
        model.close()


def test_unchecked_model_is_refused_by_the_solvers():
    """check_frames=False assembles the refused beam for checks of joint equations; the
    static and dynamic solvers then refuse to run it, with the same message."""
    s = beam_system()
    s.joint("mount", "weld", "hub", "arm", point=(0, 0, 0))
    model = s.assemble(check_frames=False)
    try:
        assert model.frame_problems and "beam 'arm'" in model.frame_problems[0]
        with pytest.raises(InputError, match="beam 'arm'"):
            solve_newton(model)
        with pytest.raises(InputError, match="beam 'arm'"):
            integrate(model, DynamicSettings(dt=1e-3, t_end=0.01), model.e0, progress=False)
    finally:
        model.close()


def test_nonlinear_beam_on_a_free_body_is_not_refused():
    s = beam_system("nonlinear")
    s.joint("mount", "weld", "hub", "arm", point=(0, 0, 0))
    model = s.assemble()
    try:
        assert model.frame_problems == []
        assert np.isfinite(model.e0).all()
    finally:
        model.close()

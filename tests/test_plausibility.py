"""Issue 35, items 5 and 6 and the "no physical bounds" cases: the default static method
that can solve the scene, the plausibility warning of a result strained beyond an elastic
metal or deflected beyond the structure's size, and the physical bounds of force elements,
eigen settings, sizes and output, with a result that is not finite or absurdly large
never ending with status ok."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main

# a box of 2 kg hanging on a spring (800 N/m, free length 0.9 m, preload 5 N) from the
# origin, held to slide along z: tension m g = 5 + 800 (L - 0.9) at the spring length L
SPRING = """
&scene title = 'spring', analysis = 'static' /
&rigid_body name = 'box', mass = 2.0, inertia = 0.1, 0.1, 0.1, 0, 0, 0, position = 0, 0, -1.0 /
&force_element name = 'spring', type = 'spring_damper', body1 = 'ground', body2 = 'box',
  point1 = 0, 0, 0, point2 = 0, 0, -1.0, stiffness = 800.0, free_length = 0.9, preload = 5.0 /
&joint name = 'hold_r_x', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_x' /
&joint name = 'hold_r_y', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_y' /
&joint name = 'hold_r_z', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r_z' /
&joint name = 'gx', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r', axis = 1, 0, 0 /
&joint name = 'gy', type = 'fix', body2 = 'box', point = 0, 0, -1.0, vector = 'r', axis = 0, 1, 0 /
&load name = 'g', type = 'gravity', vector = 0, 0, -9.81 /
&probe name = 'c', body = 'box', point = 0, 0, -1.0 /
"""
SPRING_LENGTH = 0.9 + (2.0 * 9.81 - 5.0) / 800.0

BOOM = """
&scene title = 'boom', analysis = 'static', formulation = 'ffr',
       effects = 'gravity', 'tip_mass', 'bending_moment' /
&beam length = 7.791, width = 0.1, height = 0.1, nodes = 4, segments = 1.791, 3.0, 3.0 /
&material youngs_modulus = 2.1e11, density = 7850.0 /
&boom angle_deg = 15 /
&loads tip_mass = 50.0, moment = 1000.0 /
"""


# -- item 6: the default static method is one that can solve the scene --------------------
def test_spring_damper_scene_solves_with_the_default_method(write_scene, tmp_path):
    out = tmp_path / "spring.h5"
    assert main(["run", str(write_scene(SPRING)), "-o", str(out)]) == 0
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "ok"
        static = h5["static"]
        assert static.attrs["method"] == "newton"
        assert static.attrs["method_setting"] == "auto"
        # the equilibrium of the closed form, to the solver's relative tolerance
        assert static["probes/c"][2] == pytest.approx(-SPRING_LENGTH, rel=1e-9)


def test_explicit_split_on_a_spring_damper_is_refused(write_scene, tmp_path, capsys):
    out = tmp_path / "split.h5"
    code = main(["run", str(write_scene(SPRING)), "-o", str(out),
                 "--set", "solver.static_method=split"])
    assert code == 2
    err = capsys.readouterr().err
    assert "&solver static_method" in err and "'split' cannot solve this scene" in err
    assert "force elements" in err and "'newton'" in err
    assert not out.exists()  # refused before anything is written


def test_boom_default_is_the_split_iteration_unchanged(write_scene, tmp_path):
    """The boom of seed 000 keeps the split iteration under 'auto': the same computation
    as an explicit 'split', so the same state bit for bit on one machine."""
    scene = write_scene(BOOM)
    auto, split = tmp_path / "auto.h5", tmp_path / "split.h5"
    assert main(["run", str(scene), "-o", str(auto)]) == 0
    assert main(["run", str(scene), "-o", str(split), "--set", "solver.static_method=split"]) == 0
    with h5py.File(auto) as a, h5py.File(split) as b:
        assert a["static"].attrs["method"] == "split"
        assert a["static"].attrs["method_setting"] == "auto"
        assert b["static"].attrs["method_setting"] == "split"
        assert np.array_equal(a["static/q"][()], b["static/q"][()])

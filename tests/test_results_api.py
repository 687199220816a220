"""From a System to results in one call (issue 22 item 1, SPEC section 10 "Python"):
``System.static()`` / ``System.simulate()`` run the path of ``ancf run`` with the CLI's
defaults and return :class:`ancfdrv.results.Results`; ``.save()`` writes the file the CLI
writes; ``ancfdrv.open()`` reads any result file back into the same object.

References: the Euler-Bernoulli cantilever (tip load and own weight, closed form) for the
static numbers; the namelist twin of the same system run by ``ancf run`` for the claim that
the Python door uses the CLI's defaults (the histories agree to round-off, the file's layout
and solver attributes are the same)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

import ancfdrv
from ancfdrv import Rectangle, System
from ancfdrv.cli import main
from ancfdrv.errors import InputError

E, RHO, L, W, H, MASS, G = 2.1e11, 7850.0, 2.0, 0.05, 0.1, 10.0, 9.81

TWIN = f"""
&scene  title = 'cantilever', analysis = 'dynamic', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = {E}, density = {RHO} /
&beam  name = 'arm', material = 'steel', start = 0.0, 0.0, 0.0, end = {L}, 0.0, 0.0,
       nodes = 5, section = 'rectangle', width = {W}, height = {H},
       height_axis = 0.0, 1.0, 0.0, formulation = 'nonlinear', bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0.0, 0.0, 0.0 /
&load  name = 'g', type = 'gravity', vector = 0.0, -{G}, 0.0 /
&load  name = 'payload', type = 'point_mass', body = 'arm', point = {L}, 0.0, 0.0, mass = {MASS} /
&probe  name = 'end', body = 'arm', point = {L}, 0.0, 0.0 /
&solver  t_end = 0.02 /
"""


def cantilever() -> System:
    s = System("cantilever")
    steel = s.material("steel", youngs_modulus=E, density=RHO)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(L, 0, 0), nodes=5,
           section=Rectangle(W, H), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.load("payload", "point_mass", body="arm", point=(L, 0, 0), mass=MASS)
    s.probe("end", "arm", (L, 0, 0))
    return s


def test_static_in_one_call_against_the_cantilever_formula():
    res = cantilever().static()
    ei = E * W * H**3 / 12.0
    q = RHO * W * H * G
    sag = MASS * G * L**3 / (3 * ei) + q * L**4 / (8 * ei)    # Euler-Bernoulli
    assert res.status == "ok"
    assert res.deflection["end"][1] == pytest.approx(-sag, rel=2e-3)
    np.testing.assert_allclose(res.probes["end"], [L, 0, 0] + res.deflection["end"],
                               atol=1e-12)
    assert res.counters["gravity"] == 1 and res.counters["contact"] == 0
    assert res.static.attrs["method"] == "newton"     # 'split' cannot run a nonlinear beam
    assert res.dynamic is None and res.time is None


def test_simulate_uses_the_cli_defaults_and_save_writes_the_cli_file(tmp_path):
    scene = tmp_path / "twin.nml"
    scene.write_text(TWIN)
    cli_file = tmp_path / "cli.h5"
    assert main(["run", str(scene), "-o", str(cli_file)]) == 0

    res = cantilever().simulate(t_end=0.02)
    with h5py.File(cli_file) as h5:
        cli_end = h5["dynamic/probes/end"][()]
        cli_attrs = dict(h5["dynamic"].attrs)
        cli_layout = set()
        h5.visit(cli_layout.add)
    np.testing.assert_allclose(res.probes["end"], cli_end, rtol=0, atol=1e-13)
    assert res.probes["end"].shape == (21, 3) and res.time[-1] == pytest.approx(0.02)
    for key in ("integrator", "dt", "beta", "gamma", "jacobian_policy", "steps",
                "factorizations", "newton_iterations"):
        assert res.dynamic.attrs[key] == (cli_attrs[key].decode() if isinstance(
            cli_attrs[key], bytes) else cli_attrs[key]), key
    assert res.dynamic.attrs["jacobian_policy"] == "reuse"

    saved = res.save(tmp_path / "py" / "run.h5")
    assert saved.with_suffix(".png").stat().st_size > 1000
    assert saved.with_suffix(".xdmf").exists()
    assert 'run.h5:' in saved.with_suffix(".xdmf").read_text()   # names the saved file
    with h5py.File(saved) as h5:
        layout = set()
        h5.visit(layout.add)
        assert h5.attrs["status"] == "ok"
    assert layout == cli_layout
    again = ancfdrv.open(saved)
    assert set(again.probes) == {"end"}
    np.testing.assert_array_equal(again.probes["end"], res.probes["end"])
    np.testing.assert_array_equal(again.energy["total"], res.energy["total"])
    assert again.counters == res.counters
    cli = ancfdrv.open(cli_file)            # a file of `ancf run` reads the same way
    np.testing.assert_array_equal(cli.time, res.time)


def test_options_are_the_scene_keys_and_bad_ones_are_named(tmp_path):
    s = cantilever()
    with pytest.raises(InputError, match="unknown option 'nodes'"):
        s.static(nodes=3)
    with pytest.raises(InputError, match="jacobian"):
        s.simulate(t_end=0.01, jacobian="sometimes")
    with pytest.raises(InputError, match="t_end"):
        s.simulate(t_end=-1.0)
    out = tmp_path / "direct.h5"
    res = s.simulate(0.004, 2e-3, integrator="generalized_alpha", rho_inf=0.8,
                     from_static=True, output=out, xdmf=False)
    assert res.path == out and res.static is not None and len(res.time) == 3
    assert res.dynamic.attrs["integrator"] == "generalized_alpha"
    text = tmp_path / "notes.txt"
    text.write_text("not a result")
    with pytest.raises(InputError, match="not an HDF5"):
        ancfdrv.open(text)

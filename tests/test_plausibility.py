"""Issue 35, items 5 and 6 and the "no physical bounds" cases: the default static method
that can solve the scene, the plausibility warning of a result strained beyond an elastic
metal or deflected beyond the structure's size, and the physical bounds of force elements,
eigen settings, sizes and output, with a result that is not finite or absurdly large
never ending with status ok."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main
from ancfdrv.errors import InputError, UnstableError
from ancfdrv.io import validate

from conftest import INPUTS

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


# -- item 5: a result strained beyond an elastic metal warns -------------------------------
def run_cantilever(tmp_path, name: str, *sets: str) -> tuple[int, Path]:
    """The shipped cantilever (2 m, 50 x 50 mm, 100 N at the tip), nonlinear so that a
    soft material deflects without leaving the formulation, 4 nodes."""
    out = tmp_path / f"{name}.h5"
    code = main(["run", str(INPUTS / "cantilever.nml"), "-o", str(out),
                 "--set", "scene.formulation=nonlinear", "--set", "beam.nodes=4",
                 "--set", "solver.load_steps=10", *(x for s in sets for x in ("--set", s))])
    return code, out


def largest_strain(out: Path) -> float:
    """The beam's largest von Mises stress in the file over the modulus the run used."""
    with h5py.File(out) as h5:
        stress = float(h5["static/stress/beam"].attrs["max"])
        modulus = float(h5.attrs["scene"].split("youngs_modulus = ")[1].split()[0]
                        .replace("d", "e"))
    return stress / modulus


def test_youngs_modulus_in_mpa_warns_in_file_and_on_stderr(tmp_path, capsys):
    """The state of the 4-node beam hanging under a load 1e6 times too large (stretched by
    15 %) is also an unstable equilibrium of the model (a torsion direction of negative
    stiffness, tests/test_static_stability.py): refused with exit 3, status 'unstable',
    the refusal naming the implausibility (the likely cause: the units)."""
    code, out = run_cantilever(tmp_path, "mpa", "material.youngs_modulus=2.1e5")
    assert code == 3
    err = capsys.readouterr().err
    strain = largest_strain(out)
    assert strain > 0.005   # the file's own stresses: beyond the elastic limit
    with h5py.File(out) as h5:
        warnings = h5.attrs["warnings"]
        assert h5.attrs["status"] == "unstable"
        length = 2.0   # the undeformed beam's bounding box
        moved = np.abs(h5["static/deflection/tip"][()]).max()
    assert moved > length
    for text in (warnings, err):
        assert "beam 'beam' is strained by" in text
        assert f"{strain:.3g}" in text    # the strain named is the file's
        assert "probe 'tip' on beam 'beam' is displaced by" in text
        assert "check the units" in text and "Young's modulus in Pa" in text
        assert "scene.bounds = 'off' silences" in text
    assert "static state found is unstable" in err and "static result implausible" in err


def test_youngs_modulus_in_pa_does_not_warn(tmp_path, capsys):
    code, out = run_cantilever(tmp_path, "pa")
    assert code == 0
    assert "implausible" not in capsys.readouterr().err
    assert largest_strain(out) < 0.005
    with h5py.File(out) as h5:
        assert "implausible" not in h5.attrs["warnings"]


def test_bounds_off_silences_the_warning(tmp_path, capsys):
    code, out = run_cantilever(tmp_path, "off", "material.youngs_modulus=2.1e5",
                               "scene.bounds=off")
    assert code == 3   # still an unstable state (the test above)
    err = capsys.readouterr().err
    assert "implausible" not in err and "static state found is unstable" in err
    assert largest_strain(out) > 0.005   # the same result, unwarned
    with h5py.File(out) as h5:
        assert "implausible" not in h5.attrs["warnings"]
        assert h5.attrs["status"] == "unstable"


# -- physical bounds and results that are no results ----------------------------------------
def test_a_spring_of_1e_300_is_refused_and_its_result_never_ok(write_scene, tmp_path, capsys):
    scene = write_scene(SPRING.replace("stiffness = 800.0", "stiffness = 1e-300"))
    out = tmp_path / "soft.h5"
    assert main(["run", str(scene), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "&force_element[spring] stiffness" in err
    assert "below the smallest physical stiffness" in err and "scene.bounds = 'off'" in err
    assert not out.exists()
    # bounds lifted: the box falls without end, a result no run vouches for (exit 3)
    assert main(["run", str(scene), "-o", str(out), "--set", "scene.bounds=off"]) == 3
    assert "the static result is not physical" in capsys.readouterr().err
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "failed"
        assert "not physical" in h5.attrs["message"]
        assert "static/q" in h5   # the rows computed are kept


def test_a_stiffness_beyond_the_bound_is_refused(write_scene, tmp_path, capsys):
    scene = write_scene(SPRING.replace("stiffness = 800.0", "stiffness = 1e15"))
    assert main(["run", str(scene), "-o", str(tmp_path / "stiff.h5")]) == 2
    err = capsys.readouterr().err
    assert "&force_element[spring] stiffness" in err and "beyond the physical bound" in err


def test_spin_rate_beyond_the_bound_is_refused(tmp_path, capsys):
    code = main(["run", str(INPUTS / "crane_boom_modes.nml"), "-o", str(tmp_path / "m.h5"),
                 "--set", "modal.spin_rate=1e9"])
    assert code == 2
    err = capsys.readouterr().err
    assert "&modal spin_rate" in err and "beyond the physical bound for angular rate" in err


def test_a_1_nm_beam_is_refused_in_both_kinds_of_scene(write_scene, tmp_path, capsys):
    code = main(["run", str(INPUTS / "cantilever.nml"), "-o", str(tmp_path / "a.h5"),
                 "--set", "beam.length=1e-9"])
    assert code == 2
    err = capsys.readouterr().err
    assert "&beam length" in err and "below the smallest physical length" in err
    general = (INPUTS / "general" / "cantilever.nml").read_text().replace("2.0, 0.0, 0.0",
                                                                          "1e-9, 0.0, 0.0")
    code = main(["run", str(write_scene(general)), "-o", str(tmp_path / "b.h5")])
    assert code == 2
    err = capsys.readouterr().err
    assert "&beam[arm]" in err and "below the smallest physical length" in err


def test_output_stations_beyond_memory_is_refused_before_allocating(tmp_path, capsys):
    code = main(["run", str(INPUTS / "cantilever.nml"), "-o", str(tmp_path / "s.h5"),
                 "--set", "output.stations=100000000"])
    assert code == 2
    err = capsys.readouterr().err
    assert "&output stations" in err and "of memory for the section forces" in err
    assert "use fewer stations" in err
    assert not (tmp_path / "s.h5").exists()


def test_output_memory_estimate_counts_elements_and_stations():
    """The estimate is BYTES_PER_STATION per element and station (a 10-node beam: 9
    elements), refused above half the memory available, named output.stations."""
    estimate = validate.Estimate([validate.Part("beam", "nodes", "beam", 10, 12, sections=True)])
    output = {"stations": 1000}
    assert validate.output_bytes(estimate, output, None, "static") == 4096 * 9 * 1000
    room = 2 * (estimate.memory_bytes + 4096 * 9 * 1000)   # exactly the limit: accepted
    validate.check_output_memory(estimate, output, "f.nml", None, "static", available=room)
    with pytest.raises(InputError, match=r"&output stations: 1,000 stations per beam element"):
        validate.check_output_memory(estimate, output, "f.nml", None, "static",
                                     available=room - 4)


def api_cantilever(modulus: float, bounds: str = "check"):
    """The cantilever of run_cantilever built in Python."""
    from ancfdrv import Rectangle, System
    s = System("cantilever", bounds=bounds)
    s.material("m", youngs_modulus=modulus, density=7850.0)
    s.beam("b", material="m", start=(0, 0, 0), end=(2, 0, 0), nodes=4, formulation="nonlinear",
           section=Rectangle(0.05, 0.05), height_axis=(0, 1, 0))
    for vector in ("r", "r_y", "r_z"):
        s.joint(f"clamp {vector}", "fix", "ground", "b", point=(0, 0, 0), vector=vector)
    s.load("f", "force", body="b", point=(2, 0, 0), vector=(0, -100, 0))
    s.probe("tip", "b", (2, 0, 0))
    return s


def test_python_runs_warn_alike_and_bounds_off_silences(recwarn):
    """As the command line: the unstable state refused, the implausibility named unless
    bounds are off; a stable implausible state (E = 2.1e6 Pa: the beam swings down 1.7 m,
    strained beyond 0.5 %) is 'ok' with the warning."""
    with pytest.raises(UnstableError, match="static result implausible: beam 'b' is strained"):
        api_cantilever(2.1e5).static(load_steps=10)
    with pytest.raises(UnstableError) as refused:
        api_cantilever(2.1e5, bounds="off").static(load_steps=10)
    assert "implausible" not in str(refused.value)
    recwarn.clear()
    with pytest.warns(UserWarning, match="static result implausible: beam 'b' is strained"):
        assert api_cantilever(2.1e6).static(load_steps=10).status == "ok"
    recwarn.clear()
    result = api_cantilever(2.1e6, bounds="off").static(load_steps=10)
    assert result.status == "ok"
    assert not [w for w in recwarn if "implausible" in str(w.message)]


def test_dynamic_result_strained_beyond_the_limit_warns_with_its_time(tmp_path, capsys):
    """The dynamic run's stress envelope (/dynamic/stress) is what the warning reads."""
    code, out = run_cantilever(tmp_path, "dyn", "material.youngs_modulus=2.1e5",
                               "scene.analysis=dynamic", "solver.t_end=0.1", "solver.dt=1e-2",
                               "output.xdmf=false")
    assert code == 0
    err = capsys.readouterr().err
    with h5py.File(out) as h5:
        envelope = h5["dynamic/stress/beam"].attrs
        strain, when = float(envelope["max"]) / 2.1e5, float(envelope["t_max"])
        warnings = h5.attrs["warnings"]
    assert strain > 0.005
    for text in (warnings, err):
        assert f"dynamic result implausible: beam 'beam' is strained by {strain:.3g}" in text
        assert f"at t = {when:.6g} s" in text


def test_a_swinging_double_pendulum_is_not_flagged(tmp_path, capsys):
    """Issue 39: the hard double pendulum (two hinged 1 m beams, 'nonlinear', no drive)
    swings its tip 3.7 m in 1 s, farther than the model's size (2 m) as any pendulum may:
    its beams' frames are constant, so the deflection is the whole motion, not the elastic
    part the check reads (plausibility.moving_frame); no warning."""
    out = tmp_path / "double.h5"
    code = main(["run", str(INPUTS / "hard" / "double_pendulum.nml"), "-o", str(out),
                 "--set", "solver.t_end=1.0", "--set", "solver.dt=1e-3"])
    assert code == 0
    assert "implausible" not in capsys.readouterr().err
    with h5py.File(out) as h5:
        moved = np.abs(h5["dynamic/deflection/tip"][()]).max()
        assert "implausible" not in h5.attrs["warnings"]
    assert moved > 2.0 * 1.5      # beyond the 2 m model: the check would have fired


def test_moving_frame_is_a_driven_beam_frame():
    """The boom's beam turns with its luffing drive (checked); the double pendulum's
    beams keep their frames (not checked)."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    from ancfdrv.results.plausibility import moving_frame
    boom = build_model(load_scene(INPUTS / "boom_luffing.nml"))
    assert all(moving_frame(boom, p.frame) for p in boom.probes.values())
    double = build_model(load_scene(INPUTS / "hard" / "double_pendulum.nml"))
    assert not any(moving_frame(double, p.frame) for p in double.probes.values())

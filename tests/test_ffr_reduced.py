"""Modal reduction of an FFR model in a prescribed frame (ancfdrv.solvers.ffr_reduced;
issue 23, item 2). References: the full model's constrained modes (ancfdrv.solvers.modal,
an independent eigen-solution on the whole null space) and the kernel's full FFR run of the
same scene (Newmark, the same step)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

from ancfdrv.builders import build_model
from ancfdrv.errors import SolverError
from ancfdrv.io.scene import load_scene
from ancfdrv.runner import run_scene
from ancfdrv.solvers.ffr_reduced import reduce_ffr, simulate
from ancfdrv.solvers.modal import modal_analysis
from ancfdrv.solvers.static import solve_newton

from conftest import INPUTS
from reference.reduced_ffr_newmark import newmark_python  # (tests/reference: never used by a run)

BOOM = INPUTS / "boom_luffing.nml"
BASE = ["beam.nodes=10", "solver.t_end=3.0", "solver.static_method=newton",
        "output.xdmf=false"]


def model_and_static(*extra: str):
    model = build_model(load_scene(BOOM, [*BASE, *extra]))
    return model, solve_newton(model, tol=1e-12, max_iter=50)


def full_history(tmp_path, *extra: str) -> tuple[np.ndarray, np.ndarray]:
    out = tmp_path / "full.h5"
    run_scene(BOOM, [*BASE, *extra], out, progress=False)
    with h5py.File(out) as h5:
        return h5["dynamic/time"][()], h5["dynamic/deflection/tip"][()][:, 1]


def test_kept_modes_are_exact():
    model, static = model_and_static()
    full = modal_analysis(model, 6, static=static)
    for modes in (2, 5):
        reduced = reduce_ffr(model, static, modes)
        ritz = np.sort(reduced.omega_squared)[:modes]
        frequency = np.sqrt(ritz) / (2.0 * np.pi)
        # measured: 1e-9 relative (the eigen-solutions' round-off)
        assert frequency == pytest.approx(full.frequency[:modes], rel=1e-7)
        # the Ritz values above the kept modes bound the full model's from above
        assert np.sort(reduced.omega_squared)[modes] >= reduced.kept_omega_squared[-1]


@pytest.mark.parametrize("extra", [(), ("beam.geometric_stiffness=true",)])
def test_reduced_history_converges_to_the_full_ffr_run(tmp_path, extra):
    # m = 50 kg, 10 nodes, 3 s (start and luffing): error of the reduced tip sag against the
    # kernel's full FFR run, in % of its sag range; measured without P-delta 0.0124% (1 mode),
    # 2e-4% (4 modes) on the 28-node 10 s run; here 2.7e-4 and 3.8e-6 of the range without
    # P-delta, 1.6e-3 and 7.1e-5 with it (its axial-force patterns among the corrections)
    t, full = full_history(tmp_path, *extra)
    model, static = model_and_static(*extra)
    errors = []
    for modes in (1, 4):
        out = simulate(reduce_ffr(model, static, modes), 3.0, 1e-3)
        assert np.allclose(out["time"], t)
        errors.append(np.max(np.abs(out["tip"][:, 1] - full)) / np.ptp(full))
    print("\nerrors (fraction of the sag range), modes 1 and 4:", errors)
    assert errors[1] < errors[0]
    assert errors[1] < 2e-4


def test_refuses_a_frame_that_does_not_turn():
    model = build_model(load_scene(INPUTS / "cantilever.nml", []))
    with pytest.raises(SolverError, match="one frame, turned by a drive"):
        reduce_ffr(model, solve_newton(model), 2)


@pytest.mark.parametrize("extra", [(), ("beam.geometric_stiffness=true",)])
def test_kernel_stepper_matches_the_python_steps(extra):
    # the Fortran loop (one LU while the frame's rate and acceleration stay, simplified Newton
    # for P-delta) against the plain numpy steps (full Newton); measured 2e-16 m (linear) and
    # 8e-14 m (P-delta, converged to 1e-12)
    model, static = model_and_static(*extra)
    reduced = reduce_ffr(model, static, 3)
    fast = simulate(reduced, 3.0, 1e-3, tol=1e-12)
    slow = newmark_python(reduced, 3.0, 1e-3, tol=1e-12)
    assert np.max(np.abs(fast["tip"] - slow["tip"])) < 1e-11


# -- the scene path: &beam modes = N (runner, System.simulate; issue 23 items 2 and 5) ------
def scene_run(tmp_path, name: str, *extra: str) -> h5py.File:
    out = tmp_path / f"{name}.h5"
    run_scene(BOOM, [*BASE, *extra], out, progress=False)
    return h5py.File(out)


def test_scene_path_equals_the_prototype(tmp_path):
    # the file of `ancf run --set beam.modes=3` against ffr_reduced.simulate of the same
    # model and static state (the runner's static solve, repeated): the expansion to the
    # full coordinates and the kernel's output row give back the reduced deflection
    from ancfdrv.solvers.static import solve_static
    scene = load_scene(BOOM, [*BASE, "beam.modes=3"])
    model = build_model(scene)
    solver = scene["solver"]
    static = solve_static(model, solver["static_method"], tol=solver["tol"],
                          max_iter=solver["max_iter"], p=solver["split_p"],
                          load_steps=solver["load_steps"])
    ref = simulate(reduce_ffr(model, static, 3), 3.0, 1e-3, tol=solver["newton_tol"])
    with scene_run(tmp_path, "reduced", "beam.modes=3") as h5:
        dyn = h5["dynamic"]
        assert dyn.attrs["reduction"] == "modal" and dyn.attrs["modes"] == 3
        assert "lambda" in dyn.attrs["not_provided"]
        assert np.all(np.isnan(dyn["lambda"][()]))
        assert np.allclose(dyn["time"][()], ref["time"])
        assert np.max(np.abs(dyn["deflection/tip"][()] - ref["tip"])) < 1e-12
        # the expanded state keeps the constraints to the linearization's order (m)
        assert np.max(dyn["constraint_violation"][()]) < 1e-6
        # kinetic energy starts at 0 (at rest) and is positive while luffing
        kinetic = dyn["energy/kinetic"][()]
        assert kinetic[0] == pytest.approx(0.0, abs=1e-12) and kinetic.max() > 0
        assert h5.attrs["status"] == "ok"
        assert h5["counters"].attrs["reduced_coordinates"] == dyn.attrs["reduced_coordinates"]


def test_scene_path_converges_to_the_full_ffr_run(tmp_path):
    # m = 50 kg, 10 nodes, 3 s: error of the reduced run's tip sag (from the file) against the
    # full FFR run's, as a fraction of its sag range; falls with the modes (the morning's
    # prototype: 2.7e-4 at 1 mode, 3.8e-6 at 4 modes on this case)
    with scene_run(tmp_path, "full") as h5:
        full = h5["dynamic/deflection/tip"][()][:, 1]
    errors = []
    for modes in (1, 2, 4):
        with scene_run(tmp_path, f"m{modes}", f"beam.modes={modes}") as h5:
            sag = h5["dynamic/deflection/tip"][()][:, 1]
        errors.append(np.max(np.abs(sag - full)) / np.ptp(full))
    print("\nerrors (fraction of the sag range), modes 1, 2, 4:", errors)
    assert errors[0] > errors[1] > errors[2]
    assert errors[0] < 1e-3 and errors[2] < 1e-5


def test_refused_models_name_the_beam(tmp_path):
    from ancfdrv.errors import InputError
    with pytest.raises(InputError, match="beam 'boom': modes = 2: reduce_ffr: every element "
                       "set must be 'ffr'"):
        run_scene(BOOM, [*BASE, "beam.modes=2", "scene.formulation=nonlinear"],
                  tmp_path / "a.h5", progress=False)
    with pytest.raises(InputError, match="beam 'boom': modes = 2: .*static\\+dynamic"):
        run_scene(BOOM, [*BASE, "beam.modes=2", "scene.analysis=dynamic"],
                  tmp_path / "b.h5", progress=False)
    with pytest.raises(InputError, match="beam 'boom': modes = 2: .*Newmark"):
        run_scene(BOOM, [*BASE, "beam.modes=2", "solver.integrator=generalized_alpha"],
                  tmp_path / "c.h5", progress=False)
    assert not (tmp_path / "a.h5").exists()


def test_modes_zero_is_the_full_run_bitwise(tmp_path):
    # modes = 0 (the default) must leave the full run untouched
    with scene_run(tmp_path, "default") as a, scene_run(tmp_path, "zero", "beam.modes=0") as b:
        assert np.array_equal(a["dynamic/deflection/tip"][()], b["dynamic/deflection/tip"][()])
        assert "reduction" not in b["dynamic"].attrs


def test_system_simulate_runs_the_reduced_model():
    # System.simulate takes the same path: the tip history equals the scene run's prototype
    # (simulate of the same model and static state) to 1e-12 m
    from ancfdrv.builders import build_system
    scene = load_scene(BOOM, ["beam.nodes=10", "beam.modes=3"])
    system = build_system(scene).system
    res = system.simulate(1.0, 1e-3, from_static=True, static_method="newton", xdmf=False)
    assert res.status == "ok" and res.dynamic.attrs["reduction"] == "modal"
    model = build_model(load_scene(BOOM, ["beam.nodes=10", "solver.static_method=newton"]))
    static = solve_newton(model, tol=scene["solver"]["tol"],
                          max_iter=scene["solver"]["max_iter"])
    ref = simulate(reduce_ffr(model, static, 3), 1.0, 1e-3,
                   tol=scene["solver"]["newton_tol"])
    assert np.max(np.abs(res.deflection["tip"] - ref["tip"])) < 1e-12


def test_general_scene_refusal_names_the_beam(tmp_path):
    # the general twin has the rigid arm besides the beam: outside the reduction's scope
    from ancfdrv.errors import InputError
    with pytest.raises(InputError, match=r"&beam\[boom\] modes: beam 'boom': modes = 2: .*"
                       "only body.*arm"):
        run_scene(INPUTS / "general" / "boom_luffing.nml",
                  ["beam[boom].modes=2", "solver.t_end=0.1"], tmp_path / "g.h5",
                  progress=False)


def test_sweep_over_modes_with_a_reference(tmp_path):
    # ancf sweep --vary beam.modes=0,1,4 --reference FULL.h5: modes = 0 (the full model) is
    # the finest case; err vs reference recomputed here from the files
    from ancfdrv.sweep import run_sweep
    base = ["beam.nodes=7", "solver.t_end=0.5", "solver.static_method=newton",
            "output.xdmf=false"]
    reference = tmp_path / "full.h5"
    run_scene(BOOM, base, reference, progress=False)
    rows = run_sweep(str(BOOM), ["beam.modes=0,1,4"], tmp_path / "sweep", base=base,
                     workers=1, progress=False, reference=reference)
    with h5py.File(reference) as h5:
        y_ref = h5["dynamic/deflection/tip"][()][:, 1]
    by_modes = {r["beam.modes"]: r for r in rows}
    assert all(r["status"] == "ok" for r in rows)
    assert all(r["err_reference"] == by_modes["0"]["case"] for r in rows)
    assert by_modes["0"]["err_vs_reference"] == 0.0   # the same run, bitwise
    for modes in ("1", "4"):
        with h5py.File(by_modes[modes]["file"]) as h5:
            y = h5["dynamic/deflection/tip"][()][:, 1]
        assert by_modes[modes]["err_vs_reference"] == pytest.approx(
            np.max(np.abs(y - y_ref)) / np.ptp(y_ref), rel=1e-9)
    assert by_modes["4"]["err_vs_reference"] < by_modes["1"]["err_vs_reference"]
    assert "err vs reference" in (tmp_path / "sweep" / "summary.md").read_text()
    assert (tmp_path / "sweep" / "error_vs_time.png").exists()


def test_general_spinup_with_pdelta_reduced_matches_the_full_run(tmp_path):
    # the general spin-up beam (one 'ffr' beam on a driven hub, P-delta: the centrifugal
    # stiffening is the P-delta remainder of the reduced model), 2 s: the reduced run writes
    # /dynamic/deflection_support like the full one, and its tip sag matches the full run's
    # (measured: 4.4e-6 of the sag range at 4 modes)
    base = ["scene.formulation=ffr", "scene.analysis=static+dynamic",
            "solver.integrator=newmark", "solver.t_end=2.0", "output.xdmf=false",
            "solver.static_method=newton", "beam[beam].geometric_stiffness=true"]
    sags = []
    for name, extra in (("full", []), ("reduced", ["beam[beam].modes=4"])):
        out = tmp_path / f"{name}.h5"
        run_scene(INPUTS / "general" / "spinup.nml", base + extra, out, progress=False)
        with h5py.File(out) as h5:
            sags.append(h5["dynamic/deflection_support/tip"][()][:, 1])
    full, reduced = sags
    error = np.max(np.abs(reduced - full)) / np.ptp(full)
    print("\nspin-up, 4 modes: error / sag range", error)
    assert error < 2e-5

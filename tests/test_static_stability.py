"""Right or refused (issue 39): a load-controlled static solve converges onto any
equilibrium, stable or not; the run counts the stability index of the state it found
(solvers/path.stability_index: negative eigenvalues of the tangent on the constraints'
null space, zero-stiffness directions not counted) and refuses an unstable one with exit
3, status 'unstable', the state kept in /static. References: Euler's loads of the columns
(pi^2 E I / (K L)^2, K = 1 pinned-pinned, 2 fixed-free; the square section buckles in two
planes at the same load, the next mode at 4 (K = 1) or 9 (K = 2) times it, above 1.5
times) and Prandtl's lateral-torsional load of the strip of tests/test_buckling.py."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv import System
from ancfdrv.cli import main
from ancfdrv.errors import SolverError, UnstableError
from ancfdrv.system.sections import Rectangle
from test_buckling import E, K_FACTOR, _strip, _strip_critical, column

ROOT = Path(__file__).resolve().parents[1]
#: the words of the refusal (solvers/path.unstable_static_message)
WORDS = ("static state found is unstable", "negative eigenvalue",
         "bifurcation or limit point", "static_method = 'arc_length'", "imperfection",
         "analysis = 'buckling'", "kept in /static")


def _euler(case: str, length: float = 2.0, side: float = 0.02) -> float:
    return np.pi**2 * E * side**4 / 12 / (K_FACTOR[case] * length) ** 2


def _static(system: System, out: Path, **options):
    """System.static into ``out``: the error raised (None: ok) and the file's status,
    /static stability_index and whether the state q is there."""
    try:
        system.static(output=out, **options)
        error = None
    except SolverError as exc:
        error = exc
    with h5py.File(out) as h5:
        return (error, h5.attrs["status"], h5["static"].attrs.get("stability_index"),
                "static/q" in h5)


@pytest.mark.parametrize("case", ["pinned-pinned", "fixed-free"])
def test_perfect_column_beyond_its_euler_load_is_refused(case, tmp_path):
    """At 1.5 P_cr with no imperfection Newton converges onto the straight state (an
    equilibrium, unstable): refused, exit 3 'unstable', both bending planes counted, the
    straight state kept (its tip moved along the axis only)."""
    out = tmp_path / "column.h5"
    error, status, index, kept = _static(column(case, load=1.5 * _euler(case)), out)
    assert isinstance(error, UnstableError) and error.exit_code == 3
    for word in WORDS:
        assert word in str(error)
    assert status == "unstable" and index == 2 and kept
    with h5py.File(out) as h5:
        assert "unstable" in h5.attrs["message"]


@pytest.mark.parametrize("nodes", [5, 33])
def test_the_index_counts_the_euler_loads_below_the_load(nodes):
    """At 4.5 P_cr the pinned-pinned column's Euler loads n^2 P_cr below the load are
    n = 1 and 2, each in two planes: index 4 (5 nodes: the dense test; 33 nodes: the
    banded one), as the arc-length path's own count (buckling.negative_eigenvalues)."""
    from ancfdrv.solvers.buckling import negative_eigenvalues
    from ancfdrv.solvers.path import solve_static_path
    model = column("pinned-pinned", load=4.5 * _euler("pinned-pinned"), nodes=nodes).assemble()
    try:
        static = solve_static_path(model, "newton", tol=1e-10, max_iter=50)
        assert static.extra["stability_index"] == 4
        assert negative_eigenvalues(model, static.e, static.lam, 1.0) == 4
    finally:
        model.close()


@pytest.mark.parametrize("case", ["pinned-pinned", "fixed-free"])
def test_column_below_its_euler_load_is_ok_and_stable(case, tmp_path):
    error, status, index, _ = _static(column(case, load=0.5 * _euler(case)),
                                      tmp_path / "column.h5")
    assert error is None and status == "ok" and index == 0


def _hinged_rod(pull: float) -> System:
    """A rod on a revolute joint about its own axis (x) at the root, a dead axial force
    ``pull`` (N, + tension) at its tip: the rotation about x is free (zero stiffness: the
    force does no work in it); the rest a cantilever, P_cr = pi^2 E I_min / (4 L^2) = 864 N
    in compression."""
    s = System("hinged rod")
    s.material("steel", youngs_modulus=E, density=7850.0)
    s.beam("rod", material="steel", start=(0, 0, 0), end=(1.0, 0, 0), nodes=3,
           section=Rectangle(0.02, 0.01), height_axis=(0, 1, 0), formulation="nonlinear",
           bending="cubic")
    s.joint("hinge", "revolute", "ground", "rod", point=(0, 0, 0), axis=(1, 0, 0))
    s.load("P", "force", body="rod", point=(1.0, 0, 0), vector=(pull, 0, 0))
    return s


def test_a_mechanisms_free_rotation_is_not_instability(tmp_path):
    """The free rotation's zero stiffness (a round-off eigenvalue, of either sign) is not
    counted: in tension the rod is ok with index 0; in compression above its Euler load
    (1000 N against 864 N) the one bending direction softer than the load is counted."""
    from ancfdrv.solvers.modal import linearize, null_space
    from ancfdrv.solvers.path import solve_static_path
    model = _hinged_rod(1000.0).assemble()
    try:   # the free rotation is there: a zero eigenvalue of the reduced tangent
        static = solve_static_path(model, "newton", tol=1e-10, max_iter=50)
        lin = linearize(model, static.e, static.lam, load_factor=1.0)
        basis = null_space(lin.constraints, model.ndof)
        w = np.linalg.eigvalsh(basis.T @ (lin.stiffness @ basis))
        assert abs(w[0]) < 1e-12 * w[-1] and w[1] > 1e-9 * w[-1]
        assert static.extra["stability_index"] == 0
    finally:
        model.close()
    error, status, index, _ = _static(_hinged_rod(1000.0), tmp_path / "tension.h5")
    assert error is None and status == "ok" and index == 0
    error, status, index, _ = _static(_hinged_rod(-1000.0), tmp_path / "compression.h5")
    assert isinstance(error, UnstableError) and status == "unstable" and index == 1


def test_strip_past_lateral_torsional_buckling_in_one_step_is_refused(tmp_path):
    """The strip at 1.1 Prandtl's P_cr with a lateral imperfection of 1e-4, in one load
    step: Newton lands on the nearly plane branch (the lateral tip displacement stays
    below L / 1000, against L / 100 on the stable branch, tests/test_buckling.py), whose
    one lateral-torsional direction is unstable: refused."""
    critical = _strip_critical()
    out = tmp_path / "strip.h5"
    error, status, index, kept = _static(
        _strip("cubic", 9, (0.0, -1.1 * critical, 1.1e-4 * critical)), out)
    with h5py.File(out) as h5:
        lateral = abs(h5["static/deflection/tip"][2])
    assert lateral < 2.0 / 1000
    assert isinstance(error, UnstableError) and status == "unstable" and index == 1 and kept


def test_cli_refuses_an_unstable_column_with_exit_3(tmp_path, capsys):
    """`ancf run` of the general cantilever made a nonlinear column under an axial tip force
    of 1.5 its Euler load (fixed-free, 2 m, 50 mm square): exit 3, the words on stderr, no
    traceback, the file 'unstable' with the state."""
    text = (ROOT / "inputs/general/cantilever.nml").read_text()
    force = 1.5 * np.pi**2 * E * 0.05**4 / 12 / (2 * 2.0) ** 2
    text = text.replace("formulation = 'ffr'", "formulation = 'nonlinear'").replace(
        "vector = 0.0, -100.0, 0.0", f"vector = {-force!r}, 0.0, 0.0")
    scene = tmp_path / "column.nml"
    scene.write_text(text)
    out = tmp_path / "column.h5"
    assert main(["run", str(scene), "-o", str(out)]) == 3
    stderr = capsys.readouterr().err
    assert "Traceback" not in stderr
    for word in WORDS:
        assert word in " ".join(stderr.split())
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "unstable"
        assert h5["static"].attrs["stability_index"] == 2 and "static/q" in h5


def test_static_start_of_a_dynamic_run_is_checked_alike(tmp_path):
    """analysis 'static+dynamic' (System.simulate(from_static=True)) solves the same static
    state first: the perfect column at 1.5 P_cr is refused before any step, the static
    state kept and no dynamic row written; at 0.5 P_cr the run is 'ok'."""
    out = tmp_path / "unstable.h5"
    with pytest.raises(UnstableError):
        column("pinned-pinned", load=1.5 * _euler("pinned-pinned")).simulate(
            0.002, 1e-3, from_static=True, output=out)
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "unstable" and "static/q" in h5
        assert h5["static"].attrs["stability_index"] == 2
        assert "dynamic/time" not in h5 or len(h5["dynamic/time"]) == 0
    stable = column("pinned-pinned", load=0.5 * _euler("pinned-pinned")).simulate(
        0.002, 1e-3, from_static=True, output=tmp_path / "stable.h5")
    assert stable.status == "ok"
